"""Seed 003's robot and navigation in one process for CLI tests: ``python nav_stack.py RATE
[PLANNER]`` runs bingda_tutorials' simulation_robot.launch and robot_navigation's
navigation_stack.launch (BASE_TYPE NanoRobot) paced at RATE x real time, joined to the
network. Prints READY once move_base serves."""

from __future__ import annotations

import os
import sys

from child_main import serve_ready

from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import build_launch


def main(rate: float, planner: str) -> None:
    os.environ.setdefault("BASE_TYPE", "NanoRobot")
    ctx = Context(clock="paced", rate=rate)
    build_launch(
        find_package("bingda_tutorials") / "launch" / "simulation_robot.launch", context=ctx
    )
    build_launch(
        find_package("robot_navigation") / "launch" / "navigation_stack.launch",
        {"simulation": "true", "planner": planner},
        context=ctx,
    )
    serve_ready(ctx)


if __name__ == "__main__":
    main(float(sys.argv[1]), sys.argv[2] if len(sys.argv) > 2 else "dwa")
