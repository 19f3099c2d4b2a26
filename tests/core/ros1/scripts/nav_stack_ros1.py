"""Seed 003's robot and navigation in one roverlab process, as a ROS 1 participant of the
graph ROS_MASTER_URI names: ``python nav_stack_ros1.py RATE`` runs bingda_tutorials'
simulation_robot.launch and robot_navigation's navigation_stack.launch (BASE_TYPE
NanoRobot) paced at RATE x real time. Prints READY once it is registered."""

from __future__ import annotations

import os
import sys

from roverlab.core import Context
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.description import find_package
from roverlab.launch import build_launch


def main(rate: float) -> None:
    os.environ.setdefault("BASE_TYPE", "NanoRobot")
    ctx = Context(clock="paced", rate=rate)
    build_launch(
        find_package("bingda_tutorials") / "launch" / "simulation_robot.launch", context=ctx
    )
    build_launch(
        find_package("robot_navigation") / "launch" / "navigation_stack.launch",
        {"simulation": "true"},
        context=ctx,
    )
    transport = Ros1Transport(os.environ["ROS_MASTER_URI"])
    ctx.add_transport(transport)
    print("READY", flush=True)
    try:
        ctx.spin()
    except KeyboardInterrupt:
        pass
    finally:
        ctx.shutdown()
        transport.close()


if __name__ == "__main__":
    main(float(sys.argv[1]))
