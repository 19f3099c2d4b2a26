"""Issue 26's "Seed 002 for real", the rviz half: Debian's real rviz 1.14, under Xvfb, shows
roverlab's simulator (mycar, seed 001's robot) with the seed's own ``test.rviz``, under a
real rosmaster. rviz subscribes to roverlab's /odom and /tf over TCPROS and draws the
Odometry display's red arrows on the grid; the screenshot goes to the test's tmp dir.

Slow (rviz alone takes about 10 s to start on software Mesa):
``pytest -m slow tests/core/ros1/test_rviz_ros1.py``."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.core.transport.ros1.xmlrpc import call
from tests.core.ros1.conftest import ros_env, stop

RVIZ_FILE = Path(__file__).resolve().parents[3] / "src/roverlab/packages/mycar/config/test.rviz"
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        not (Path("/usr/bin/rviz").exists() and shutil.which("Xvfb") and shutil.which("import")),
        reason="Debian's rviz, Xvfb or ImageMagick's import is not installed",
    ),
]


def _free_display() -> int:
    for n in range(140, 200):
        if not Path(f"/tmp/.X11-unix/X{n}").exists() and not Path(f"/tmp/.X{n}-lock").exists():
            return n
    raise RuntimeError("no free X display between :140 and :199")


def _rviz_connections(master: str) -> dict[str, bool]:
    """Topic -> connected, of rviz's inbound TCPROS links (its slave's getBusInfo)."""
    state = call(master, "getSystemState", "/test")
    nodes = {n for _topic, subs in state[1] for n in subs if n.startswith("/rviz")}
    if not nodes:
        return {}
    uri = call(master, "lookupNode", "/test", sorted(nodes)[0])
    bus = call(uri, "getBusInfo", "/test")
    # roscpp: [id, destination, direction, transport, topic, connected, ...]
    return {str(c[4]): bool(c[5]) for c in bus if c[2] == "i"}


def test_real_rviz_shows_roverlab_sim_with_the_seeds_rviz_file(
    real_master: str, tmp_path: Path
) -> None:
    display = _free_display()
    xvfb = subprocess.Popen(
        ["Xvfb", f":{display}", "-screen", "0", "1280x800x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    procs: list[subprocess.Popen[bytes]] = [xvfb]
    try:
        env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
        procs.append(
            subprocess.Popen(
                [sys.executable, "-m", "roverlab.cli", "sim", "--robot", "mycar", "-w", "empty"],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        renv = {**ros_env(real_master), "DISPLAY": f":{display}", "LIBGL_ALWAYS_SOFTWARE": "1"}
        renv["HOME"] = str(tmp_path)  # rviz writes ~/.rviz
        procs.append(
            subprocess.Popen(
                ["/usr/bin/rviz", "-d", str(RVIZ_FILE)],
                env=renv,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        links: dict[str, bool] = {}
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline:
            links = _rviz_connections(real_master)
            if links.get("/odom") and links.get("/tf"):
                break
            time.sleep(1.0)
        time.sleep(5.0)  # a few frames drawn with the odometry arrows
        shot = tmp_path / "rviz.png"
        subprocess.run(
            ["import", "-window", "root", str(shot)],
            env={**os.environ, "DISPLAY": f":{display}"},
            check=True,
            timeout=30,
        )
    finally:
        for p in reversed(procs):
            stop(p)
    assert links.get("/odom") and links.get("/tf"), f"rviz's inbound links: {links}"
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    # the Odometry display's arrows (255, 25, 0) in the 3D view (right of the 430 px
    # Displays panel); the rest of the view is the odometry's covariance shapes and the grid
    # (lit and blended: about (150, 56, 23) here)
    red = ((r - g) > 60) & ((r - b) > 60)
    assert red[:, 430:].sum() > 150, f"no odometry arrow in {shot}"
