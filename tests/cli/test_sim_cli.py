"""``roverlab sim`` end to end: recording, rates at real time with a second terminal, errors."""

from __future__ import annotations

import math
import subprocess
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from rosbags.highlevel import AnyReader

from tests.helpers.procs import Proc


def _read(path: Path) -> tuple[Counter[str], dict[str, list[Any]]]:
    counts: Counter[str] = Counter()
    msgs: dict[str, list[Any]] = {}
    with AnyReader([path]) as reader:
        for con, _t, raw in reader.messages():
            counts[con.topic] += 1
            if con.topic in ("/odom", "/cmd_vel", "/ground_truth/state"):
                msgs.setdefault(con.topic, []).append(reader.deserialize(raw, con.msgtype))
    return counts, msgs


def test_rate_max_duration_and_record(tmp_path: Path) -> None:
    out = tmp_path / "run.mcap"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "sim", "--world", "maze", "--robot", "mybot",
         "--rate", "max", "--duration", "10", "--record", str(out), "--no-expose"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert out.is_file() and not (tmp_path / "run.mcap.part").exists()
    counts, msgs = _read(out)
    rates = {"/scan": 7, "/odom": 30, "/imu": 100, "/image_raw": 30, "/clock": 100}
    for topic, hz in rates.items():
        assert abs(counts[topic] / 10.0 - hz) <= 0.02 * hz, (topic, counts[topic])
    assert counts["/tf_static"] >= 1 and counts["/camera_info"] == counts["/image_raw"]
    # the robot stood still: odometry (world source) stays at the spawn
    last = msgs["/odom"][-1].pose.pose.position
    assert math.hypot(last.x, last.y) < 1e-9


@pytest.mark.zenoh
def test_real_time_with_topic_pub_from_a_second_terminal(daemon: str, tmp_path: Path) -> None:
    out = tmp_path / "live.mcap"
    sim = Proc(
        [sys.executable, "-m", "roverlab.cli", "sim", "--world", "maze", "--robot", "mybot",
         "--rate", "1", "--duration", "12", "--record", str(out)]
    )  # fmt: skip
    pub = Proc(
        [sys.executable, "-m", "roverlab.cli", "topic", "pub", "-r", "10", "/cmd_vel",
         "geometry_msgs/Twist", "{linear: {x: 0.0}, angular: {z: 0.4}}"]
    )  # fmt: skip
    try:
        assert sim.popen.wait(timeout=120) == 0, sim.stop()
    finally:
        pub.stop()
        sim.stop()
    counts, msgs = _read(out)
    rates = {"/scan": 7, "/odom": 30, "/imu": 100, "/image_raw": 30, "/clock": 100}
    for topic, hz in rates.items():
        assert abs(counts[topic] / 12.0 - hz) <= 0.02 * hz, (topic, counts[topic])
    assert counts["/cmd_vel"] > 50  # the second terminal's commands were recorded
    # and they turned the robot in place
    q = msgs["/odom"][-1].pose.pose.orientation
    assert abs(q.z) > 0.1


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--rate", "fast"], "--rate must be a positive number or 'max'"),
        (["--world", "atlantis"], "unknown world 'atlantis'"),
        (["--robot", "rover9"], "unknown robot 'rover9'"),
        (["--duration", "-1"], "--duration must be a positive"),
        (["--arg", "novalue"], "--arg expects name:=value"),
    ],
)
def test_bad_input_is_one_line_exit_2(args: list[str], needle: str, tmp_path: Path) -> None:
    out = tmp_path / "x.mcap"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "sim", "--no-expose", "--record", str(out), *args],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], r.stderr
    assert not out.exists() and not (tmp_path / "x.mcap.part").exists()


@pytest.mark.zenoh
def test_rate_max_runs_privately_by_default(daemon: str, tmp_path: Path) -> None:
    """A batch run neither feeds nor hears another system on the machine."""
    import threading
    import time

    from roverlab.core import Context
    from roverlab.core.transport.daemon import connect_context
    from roverlab.msgs import Twist

    outsider = Context(clock="wall")
    node = outsider.create_node("outsider")
    clocks: list[Any] = []
    node.create_subscription("rosgraph_msgs/Clock", "/clock", clocks.append, 100)
    cmd = node.create_publisher("geometry_msgs/Twist", "/cmd_vel", 10)
    connect_context(outsider)
    outsider.spin_in_thread()
    stop = threading.Event()

    def drive() -> None:  # an operator's teleop running on the same machine
        while not stop.is_set():
            cmd.publish(Twist(linear_x=0.5))
            time.sleep(0.05)

    driver = threading.Thread(target=drive, daemon=True)
    driver.start()
    out = tmp_path / "batch.mcap"
    try:
        r = subprocess.run(
            [sys.executable, "-m", "roverlab.cli", "sim", "--rate", "max", "--duration", "20",
             "--record", str(out)],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
    finally:
        stop.set()
        driver.join()
        outsider.shutdown()
    assert r.returncode == 0, r.stderr
    assert "--rate max runs privately" in r.stderr
    assert clocks == []  # its /clock never reached the outsider
    counts, msgs = _read(out)
    assert counts["/cmd_vel"] == 0  # and the outsider's commands never reached it
    last = msgs["/odom"][-1].pose.pose.position
    assert math.hypot(last.x, last.y) < 1e-9
