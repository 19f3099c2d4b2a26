"""The other way round: ``roverlab dashboard`` with ROS_MASTER_URI naming a real ROS 1
system (a real rospy node publishing a latched /map, /scan and /tf and setting the
/robot_description parameter, and Debian's C++ robot_state_publisher publishing the
robot's fixed joints on /tf_static) shows its map, scan and robot model with mbot's own
gmapping.rviz, every display green, in Debian's chromium. The screenshot goes to the
test's tmp dir."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from tests.core.ros1.conftest import SCRIPTS, start_ros, stop
from tests.helpers.browser import CHROMIUM, chromium
from tests.helpers.net import free_port
from tests.viz.test_bringup_pages import _wait_http
from tests.viz.test_other_process_pages import _displays

pytestmark = pytest.mark.skipif(not CHROMIUM.exists(), reason="/usr/bin/chromium is absent")
RVIZ = (
    Path(__file__).resolve().parents[3] / "src/roverlab/packages/mbot_navigation/rviz/gmapping.rviz"
)


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    yield from chromium()


def test_dashboard_shows_a_real_ros1_robot(real_master: str, browser: Any, tmp_path: Path) -> None:
    world = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "robot_world.py"))
    procs: list[subprocess.Popen[str]] = [world]
    try:
        assert world.stdout is not None and world.stdout.readline().strip() == "READY"
        procs.append(start_ros(real_master, "/usr/lib/robot_state_publisher/robot_state_publisher"))
        port = free_port()
        env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
        procs.append(
            subprocess.Popen(
                [
                    sys.executable,
                    "-m",
                    "roverlab.cli",
                    "dashboard",
                    "-d",
                    str(RVIZ),
                    "--port",
                    str(port),
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
                text=True,
            )
        )
        _wait_http(f"http://127.0.0.1:{port}/config", timeout_s=60.0)
        page = browser.new_page(viewport={"width": 1200, "height": 800})
        page.goto(f"http://127.0.0.1:{port}/")
        want = {"Grid", "RobotModel", "Map", "LaserScan"}
        displays: dict[str, tuple[str, str]] = {}
        deadline = time.monotonic() + 40
        while time.monotonic() < deadline:
            displays = _displays(page)
            if all(displays.get(n, ("",))[0] == "ok" for n in want):
                break
            time.sleep(0.5)
        time.sleep(1.0)  # a frame drawn with everything
        shot = tmp_path / "ros1_dashboard.png"
        page.screenshot(path=str(shot))
        page.close()
    finally:
        for p in reversed(procs):
            stop(p)
    for name in want:
        assert displays[name][0] == "ok", f"{name}: {displays[name]}"
    assert displays["RobotModel"][1] == "URDF:2 visuals"  # the parameter's URDF, both links
    assert "Transform OK" in displays["Map"][1] and "Transform OK" in displays["LaserScan"][1]
    # the 3D view: the map's grey floor, its black walls, the red scan and the blue robot
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    assert ((r > 200) & (g < 60) & (b < 60)).sum() > 200, "no red scan points"
    assert ((b > 150) & (r < 80) & (g < 120)).sum() > 20, "no blue robot"
    assert ((abs(r - 160) < 20) & (abs(g - 160) < 20) & (abs(b - 160) < 20)).sum() > 5000
