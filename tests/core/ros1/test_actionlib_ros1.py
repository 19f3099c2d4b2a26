"""The crown acceptance point of issue 26: a ROS 1 package's own kind of navigation script
(rbx1-style: goals through actionlib.SimpleActionClient, Debian's rospy) drives roverlab's
move_base (seed 003's robot and robot_navigation's navigation_stack.launch) under a real
rosmaster, and reaches every goal. Slow (about a minute and a half on a loaded 2-core
machine): ``pytest -m slow tests/core/ros1/test_actionlib_ros1.py``."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from tests.core.ros1.conftest import SCRIPTS, run_ros, stop


@pytest.mark.slow
def test_real_actionlib_client_drives_roverlab_move_base(real_master: str) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    stack = subprocess.Popen(
        [sys.executable, str(SCRIPTS / "nav_stack_ros1.py"), "5"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert stack.stdout is not None and stack.stdout.readline().strip() == "READY"
        t0 = time.monotonic()
        run = run_ros(
            real_master,
            "/usr/bin/python3",
            str(SCRIPTS / "nav_goals.py"),
            "2.0,0.0,0.0",
            "-0.5,-0.5,0.78",
            timeout_s=400,
        )
        assert run.returncode == 0, run.stdout + run.stderr[-2000:]
        assert run.stdout.splitlines() == [
            "connected to move_base",
            "goal 2.0,0.0,0.0: SUCCEEDED",
            "goal -0.5,-0.5,0.78: SUCCEEDED",
        ]
        assert time.monotonic() - t0 < 400
    finally:
        stop(stack)
        run_ros(real_master, "/usr/bin/rosparam", "delete", "/use_sim_time")
