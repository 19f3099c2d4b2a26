"""rospy-era modules through `roverlab run`: tf (listener, broadcaster, transformations),
cv_bridge, visualization_msgs; a Python 2 script is one line naming file, line and fix."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.core.transport.zenoh import endpoint_reachable
from roverlab.ros1 import run_script
from roverlab.ros1.runner import python2_problem
from tests.helpers.net import free_port

SCRIPTS = (
    Path(__file__).resolve().parents[1] / "ros1_packages" / "book_robot_description" / "scripts"
)


def test_tf_listener_broadcaster_and_marker(capfd: pytest.CaptureFixture[str]) -> None:
    ctx = Context(clock="wall", publish_clock=False)
    got: list[object] = []
    ctx.create_node("watch").create_subscription(
        "visualization_msgs/msg/Marker", "/visualization_marker", got.append, 10
    )
    try:
        assert run_script(SCRIPTS / "tf_follow.py", [], ctx) == 0
        ctx.spin_for(0.2)
    finally:
        ctx.shutdown()
    assert "carrot at 1.00 2.00 yaw 1.57" in capfd.readouterr().out
    assert got and got[-1].pose.position.y == pytest.approx(2.0)  # type: ignore[attr-defined]


def test_cv_bridge_round_trip(capfd: pytest.CaptureFixture[str]) -> None:
    ctx = Context(clock="wall", publish_clock=False)
    try:
        assert run_script(SCRIPTS / "image_flip.py", [], ctx) == 0
    finally:
        ctx.shutdown()
    # red (200) first in rgb8; mono8 = 0.299 * 200 = 60; no bgr8 -> 32FC1 conversion
    assert capfd.readouterr().out.strip() == "bgr8 200 0 60 True"


def test_cv_bridge_mono16_and_passthrough() -> None:
    from roverlab.ros1.cv_bridge import CvBridge

    b = CvBridge()
    depth = np.arange(12, dtype=np.uint16).reshape(3, 4) * 1000
    msg = b.cv2_to_imgmsg(depth, "16UC1")
    assert msg.encoding == "16UC1"
    assert np.array_equal(b.imgmsg_to_cv2(msg), depth)
    f = b.cv2_to_imgmsg(depth.astype(np.float32) / 1000.0)
    assert f.encoding == "32FC1" and b.imgmsg_to_cv2(f, "32FC1")[2, 3] == pytest.approx(11.0)


def test_python2_script_is_one_line_with_the_fix() -> None:
    line = python2_problem(SCRIPTS / "py2_teleop.py")
    assert line == (
        f"{SCRIPTS / 'py2_teleop.py'}:6: Python 2 code, a print statement: write print(...) "
        "(roverlab runs Python 3, as ROS noetic)"
    )
    endpoint = f"tcp/127.0.0.1:{free_port()}"  # a daemon of its own, if it started one
    done = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "run", str(SCRIPTS / "py2_teleop.py")],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "ROVERLAB_DAEMON": endpoint},
    )
    assert done.returncode == 1
    assert done.stderr.strip() == f"error: {line}"
    # refused before joining the network: no daemon was started for it
    assert not endpoint_reachable(endpoint)


@pytest.mark.parametrize(
    ("source", "fix"),
    [
        ("try:\n    pass\nexcept ValueError, e:\n    pass\n", "write 'except E as e:'"),
        ("x = 0777\n", "write 0o777"),
        ("if 1 <> 2:\n    pass\n", "write '!='"),
        ("raise ValueError, 'no'\n", "write 'raise E(msg)'"),
    ],
)
def test_other_python2_forms(tmp_path: Path, source: str, fix: str) -> None:
    p = tmp_path / "old.py"
    p.write_text(source)
    line = python2_problem(p)
    assert line is not None and line.startswith(f"{p}:") and fix in line
