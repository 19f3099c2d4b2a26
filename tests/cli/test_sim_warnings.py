"""`roverlab sim` prints a world's warnings grouped; --strict makes them errors."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

PKGS = Path(__file__).resolve().parents[1] / "ros1_packages"
WORLD = PKGS / "book_worlds" / "worlds" / "mesh_obstacles.world"
ROBOT = PKGS / "book_robot_description" / "urdf" / "robot_with_laser.urdf.xacro"


def test_missing_models_printed_grouped_and_strict_fails(cli: Any) -> None:
    os.environ["ROS_PACKAGE_PATH"] = str(PKGS)
    try:
        args = ("sim", "--world", str(WORLD), "--robot", str(ROBOT), "--rate", "max")
        done = cli(*args, "--duration", "0.2", timeout=120)
        assert done.returncode == 0, done.stderr
        assert "warning: world mesh_obstacles: 1 problem:" in done.stderr
        assert "2 models skipped: hydrant_0, hydrant_1 — model://fire_hydrant not found" in (
            done.stderr
        )
        strict = cli(*args, "--duration", "0.2", "--strict", timeout=120)
        assert strict.returncode == 2
        assert "error: world mesh_obstacles: 1 problem:" in strict.stderr
        assert "--strict" in strict.stderr and "simulated" not in strict.stderr
    finally:
        os.environ.pop("ROS_PACKAGE_PATH", None)
