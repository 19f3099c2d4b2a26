"""Seed 002 for real: the seed's slam.py, run by Debian's /usr/bin/python3 with its real
rospy and actionlib, patrols its own six places with roverlab's simulator, map_server, amcl
and move_base (one ``roverlab launch``) under Debian's real rosmaster, and reaches them.

The seed's places (x from -5.5 to 4.6 m, y from -6.1 to 0.0 m) fit none of the bundled
worlds, so the test draws a map_server map of a room they fit (with a few boxes for amcl to
see) and gives it to the simulator as its world and to map_server as its map. Slow (about a
minute on a loaded 2-core machine): ``pytest -m slow tests/core/ros1/test_seed002_ros1.py``.
"""

from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.core.transport.ros1.xmlrpc import call
from tests.core.ros1.conftest import DATA, SCRIPTS, ros_env, run_ros, stop

REPO = Path(__file__).resolve().parents[3]
SLAM = REPO / "examples" / "seed002" / "slam.py"
LINE = re.compile(r"^\[INFO\] \[\d+\.\d+, \d+\.\d+\]: (.*)$")  # wall, sim time
# slam.py's locations (x, y)
PLACES = {
    "1": (4.589, -0.376),
    "2": (4.231, -6.050),
    "3": (-0.674, -5.244),
    "4": (-5.543, -4.779),
    "5": (-4.701, -0.590),
    "6": (2.924, 0.018),
}


def draw_room(folder: Path) -> Path:
    """A 13.5 x 9.3 m walled room holding the seed's six places, four boxes inside; a
    map_server YAML + PGM (0.05 m cells, origin at its lower-left corner)."""
    res, x0, y0, x1, y1 = 0.05, -7.0, -7.5, 6.5, 1.8
    w, h = round((x1 - x0) / res), round((y1 - y0) / res)
    grid = np.full((h, w), 254, np.uint8)

    def box(cx: float, cy: float, sx: float, sy: float) -> None:
        c0, c1 = int((cx - sx / 2 - x0) / res), int((cx + sx / 2 - x0) / res)
        r0, r1 = int((cy - sy / 2 - y0) / res), int((cy + sy / 2 - y0) / res)
        grid[h - r1 : h - r0, c0:c1] = 0  # image rows run top down

    t = 0.15
    box((x0 + x1) / 2, y0 + t / 2, x1 - x0, t)
    box((x0 + x1) / 2, y1 - t / 2, x1 - x0, t)
    box(x0 + t / 2, (y0 + y1) / 2, t, y1 - y0)
    box(x1 - t / 2, (y0 + y1) / 2, t, y1 - y0)
    for b in ((-2.5, -2.5, 0.8, 0.8), (1.5, -3.0, 1.0, 0.6), (-6.0, 1.0, 1.2, 0.6)):
        box(*b)
    box(5.5, -3.0, 0.6, 1.5)
    Image.fromarray(grid).save(folder / "room.pgm")
    yaml = folder / "room.yaml"
    yaml.write_text(
        f"image: room.pgm\nresolution: {res}\norigin: [{x0}, {y0}, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return yaml


@pytest.mark.slow
def test_real_rospy_slam_py_patrols_roverlab_navigation(real_master: str, tmp_path: Path) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    room = draw_room(tmp_path)
    launch = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "roverlab.cli",
            "launch",
            str(DATA / "seed002_nav.launch"),
            *("--rate", "3", f"map:={room}"),
        ],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=(tmp_path / "launch.log").open("w"),
    )
    # slam.py starts once the launch has set /use_sim_time, so that it follows /clock
    deadline = time.monotonic() + 60
    while not call(real_master, "hasParam", "/test", "/use_sim_time"):
        assert time.monotonic() < deadline and launch.poll() is None
        time.sleep(0.2)
    slam = subprocess.Popen(
        ["/usr/bin/python3", str(SLAM), "_rest_time:=30"],
        env={**ros_env(real_master), "PYTHONUNBUFFERED": "1"},  # its log lines as they come
        stdout=subprocess.PIPE,
        stderr=(tmp_path / "slam.err").open("w"),
        text=True,
    )
    messages: list[str] = []
    try:
        assert slam.stdout is not None
        deadline = time.monotonic() + 240
        while messages.count("Goal succeeded!") < 2:
            assert time.monotonic() < deadline and slam.poll() is None, (
                messages,
                (tmp_path / "launch.log").read_text()[-3000:],
            )
            m = LINE.match(slam.stdout.readline())
            if m:
                messages.append(m.group(1))
        # where the robot is during its rest at the second place: odom -> base_footprint,
        # read by the real tf2_ros (odom starts where the map's origin is, as amcl's
        # initial pose says, and drifts little over two legs)
        where = run_ros(
            real_master, "/usr/bin/python3", str(SCRIPTS / "tf_lookup.py"), "odom", "base_footprint"
        )
        # Ctrl-C; the seed's shutdown hook sleeps in sim time, which real rospy may no
        # longer follow once it is shutting down: it gets a moment, then is killed
        slam.send_signal(signal.SIGINT)
        try:
            out, _ = slam.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            slam.kill()
            out, _ = slam.communicate()
        messages += [m.group(1) for m in map(LINE.match, out.splitlines()) if m]
    finally:
        stop(slam)
        stop(launch)
        run_ros(real_master, "/usr/bin/rosparam", "delete", "/use_sim_time")
    assert messages[:3] == [
        "Waiting for move_base action server...",
        "Connected to move base server",
        "Starting navigation test",
    ], messages
    goals = [x.removeprefix("Going to: ") for x in messages if x.startswith("Going to: ")]
    assert "Success so far: 2/2 = 100%" in messages, messages
    assert "State:3" in messages and "Stopping the robot..." in messages, messages
    # the robot stands at the place of the second goal it reached
    assert where.returncode == 0, where.stderr[-2000:]
    x, y = (float(v) for v in where.stdout.split(":")[1].split()[:2])
    px, py = PLACES[goals[1]]
    assert math.hypot(x - px, y - py) < 0.6, (where.stdout, goals)
