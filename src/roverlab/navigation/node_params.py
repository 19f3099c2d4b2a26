"""Parameters of a host node under a plugin's name (node side: reads the node's overrides).

ROS 1 plugins of move_base read their parameters from the host node's private namespace
under their own name (``~NavfnROS/allow_unknown``, ``~global_costmap/robot_radius``); a
launch file gives them as ``NavfnROS/allow_unknown`` (``<rosparam>`` nesting) or, from ROS 2
YAML, ``NavfnROS.allow_unknown``.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from roverlab.core import Node

__all__ = ["parameters_under"]


def parameters_under(node: Node, name: str, *, searched: Iterable[str] = ()) -> dict[str, Any]:
    """Every override of ``node`` under ``name/`` (or ``name.``), declared now so none is
    reported as unused, plus the host-level ``searched`` names not set under ``name``
    (ROS's ``searchParam``: a costmap finds ``footprint`` one level up)."""
    values: dict[str, Any] = {}
    for key in node.unused_parameter_overrides():
        for prefix in (name + "/", name + "."):
            if key.startswith(prefix):
                values[key[len(prefix) :]] = node.declare_parameter(key, None).value
    for prefix in (name + "/", name + "."):
        for key, param in node.parameters.items():
            if key.startswith(prefix) and key[len(prefix) :] not in values:
                values[key[len(prefix) :]] = param.value
    for key in searched:
        if key in values:
            continue
        if node.has_parameter(key):
            v = node.get_parameter(key).value
        elif key in node.unused_parameter_overrides():
            v = node.declare_parameter(key, None).value
        else:
            continue
        if v is not None:
            values[key] = v
    return values
