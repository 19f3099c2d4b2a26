"""What the nodes of one launch share while it is built, and the node factory type."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roverlab.core import Context, Node
from roverlab.errors import RoverlabError
from roverlab.launch.xml import LaunchError, NodeSpec

__all__ = ["LaunchState", "NodeFactory", "build_node", "node_factory", "node_kwargs"]


@dataclass
class LaunchState:
    """What the nodes of one launch share: the context, global parameters, and the
    simulation being assembled (gzserver gives the world, spawn_model the robot)."""

    context: Context
    params: dict[str, Any]
    param_sources: dict[str, str] = field(default_factory=dict)  # LaunchSpec's
    world: Any = None
    world_source: str = ""
    spawns: list[tuple[Any, tuple[float, float, float], str]] = field(default_factory=list)
    spawn_urdf: str = ""
    warnings: list[str] = field(default_factory=list)
    #: (namespace, name) of each controller controller_manager's spawner started
    controllers: list[tuple[str, str]] = field(default_factory=list)


NodeFactory = Callable[[LaunchState, NodeSpec], Node | None]


def node_kwargs(spec: NodeSpec) -> dict[str, Any]:
    """The :class:`~roverlab.core.Node` keywords of a ``<node>``: namespace, private
    parameters, remappings."""
    return {
        "namespace": spec.namespace,
        "parameter_overrides": spec.params,
        "remappings": spec.remaps,
    }


def build_node(
    state: LaunchState,
    spec: NodeSpec,
    make: Callable[..., Node],
    parameter_overrides: dict[str, Any] | None = None,
) -> Node:
    """``make(context, node_name=..., **node_kwargs(spec))`` (with ``parameter_overrides``
    in place of the ``<node>``'s own when given); a bad configuration is a LaunchError
    naming the file and the node."""
    kwargs = node_kwargs(spec)
    if parameter_overrides is not None:
        kwargs["parameter_overrides"] = parameter_overrides
    try:
        return make(state.context, node_name=spec.name, **kwargs)
    except (RoverlabError, ValueError) as err:
        raise LaunchError(f"{spec.source}: {spec.pkg}/{spec.type}: {err}") from err


def node_factory(path: str) -> NodeFactory:
    """The factory of a plain node: the class at ``"module:Class"`` built from its
    ``<node>`` (private parameters, remaps); a bad configuration is a LaunchError naming
    the file. The module is imported when a launch first starts such a node, so a launch
    pays only for the nodes it runs."""
    module, _, name = path.partition(":")

    def factory(state: LaunchState, spec: NodeSpec) -> Node:
        return build_node(state, spec, getattr(importlib.import_module(module), name))

    return factory
