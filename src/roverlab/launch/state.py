"""What the nodes of one launch share while it is built, and the node factory type."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roverlab.core import Context, Node
from roverlab.launch.xml import NodeSpec

__all__ = ["LaunchState", "NodeFactory", "node_kwargs"]


@dataclass
class LaunchState:
    """What the nodes of one launch share: the context, global parameters, and the
    simulation being assembled (gzserver gives the world, spawn_model the robot)."""

    context: Context
    params: dict[str, Any]
    world: Any = None
    world_source: str = ""
    spawns: list[tuple[Any, tuple[float, float, float], str]] = field(default_factory=list)
    spawn_urdf: str = ""
    warnings: list[str] = field(default_factory=list)


NodeFactory = Callable[[LaunchState, NodeSpec], Node | None]


def node_kwargs(spec: NodeSpec) -> dict[str, Any]:
    """The :class:`~roverlab.core.Node` keywords of a ``<node>``: namespace, private
    parameters, remappings."""
    return {
        "namespace": spec.namespace,
        "parameter_overrides": spec.params,
        "remappings": spec.remaps,
    }
