"""A roverlab node on the ROS 1 graph ROS_MASTER_URI names, with declared parameters
(``speed`` 0.5, ``mode`` "slow", ``limits.max_range`` 12.0; ``frame`` and ``unset``
without a default, ``frame`` overridden with "odom") and a set-parameters callback
that refuses a negative speed and prints every change it accepts (``SET name value``).
Prints ``READY speed mode max_range frame`` (the values it started with) once the node is
registered. The node's name is the first argument (default param_node)."""

from __future__ import annotations

import os
import sys
from typing import Any

from roverlab.core import Context, SetParametersResult
from roverlab.core.transport.ros1.transport import Ros1Transport


def on_set(params: list[Any]) -> SetParametersResult:
    for p in params:
        if p.name == "speed" and p.value < 0:
            return SetParametersResult(False, "speed must be >= 0")
        print(f"SET {p.name} {p.value}", flush=True)
    return SetParametersResult(True)


ctx = Context(clock="wall")
transport = Ros1Transport(os.environ["ROS_MASTER_URI"])
ctx.add_transport(transport)
name = sys.argv[1] if len(sys.argv) > 1 else "param_node"
node = ctx.create_node(name, parameter_overrides={"frame": "odom"})
node.declare_parameter("speed", 0.5)
node.declare_parameter("mode", "slow")
node.declare_parameter("limits.max_range", 12.0)
node.declare_parameter("frame", None)  # no default: the override's value
node.declare_parameter("unset", None)  # no default, no override: not on the master
node.add_on_set_parameters_callback(on_set)
values = [node.get_parameter_value(n) for n in ("speed", "mode", "limits.max_range", "frame")]
print("READY", *values, flush=True)
try:
    ctx.spin()
except KeyboardInterrupt:
    pass
finally:
    ctx.shutdown()
    transport.close()
