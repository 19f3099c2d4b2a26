"""``roverlab teleop``, ``action send_goal`` and ``patrol`` on a ROS 1 graph (real rosmaster):
teleop's Twists reach a real rospy subscriber; goals go through actionlib topics to a real
actionlib.SimpleActionServer (Debian's rospy), standing in for move_base."""

from __future__ import annotations

import os
import queue
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from roverlab.teleop import CTRL_C
from tests.core.ros1.conftest import SCRIPTS, start_ros, stop
from tests.teleop.test_pty import PtyTeleop


class Lines:
    """A process's stdout lines, read in a thread."""

    def __init__(self, proc: subprocess.Popen[str]) -> None:
        self.proc = proc
        self.q: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.q.put(line.strip())

    def next(self, timeout_s: float = 30.0) -> str:
        return self.q.get(timeout=timeout_s)

    def drain(self) -> list[str]:
        out = []
        while not self.q.empty():
            out.append(self.q.get())
        return out


@pytest.fixture(scope="module")
def move_base_stub(real_master: str) -> Iterator[Lines]:
    proc = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "move_base_stub.py"))
    lines = Lines(proc)
    try:
        assert lines.next() == "ready"
        yield lines
    finally:
        stop(proc)


def _env(master: str) -> dict[str, str]:
    return {**os.environ, "ROS_MASTER_URI": master, "ROS_HOSTNAME": "127.0.0.1"}


def test_teleop_twists_reach_a_rospy_subscriber(
    real_master: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    listener = start_ros(
        real_master, "/usr/bin/python3", str(SCRIPTS / "twist_listener.py"), "/cmd_vel"
    )
    heard = Lines(listener)
    monkeypatch.setenv("ROS_MASTER_URI", real_master)
    monkeypatch.setenv("ROS_HOSTNAME", "127.0.0.1")
    teleop = PtyTeleop("_speed:=0.4", "_turn:=0.8")
    try:
        assert heard.next() == "ready"
        teleop.wait_output("CTRL-C to quit")
        got = ""
        for _ in range(100):  # until the TCPROS link is up: stop keys give zero Twists
            teleop.type("k")
            try:
                got = heard.next(0.2)
                break
            except queue.Empty:
                continue
        assert got == "0.00 0.00", got
        teleop.type("ij")
        rest = []
        while rest[-2:] != ["0.40 0.00", "0.00 0.80"]:
            rest.append(heard.next(10))
        teleop.type(CTRL_C)
        assert teleop.wait_exit() == 0, teleop.stderr()
        assert heard.next(10) == "0.00 0.00"  # teleop's last Twist stops the robot
    finally:
        teleop.close()
        stop(listener)


def test_action_send_goal_through_rospy_actionlib(real_master: str, move_base_stub: Lines) -> None:
    cmd = [sys.executable, "-m", "roverlab.cli", "action", "send_goal", "/move_base"]
    goal = "{target_pose: {header: {frame_id: map}, pose: {position: {x: %s, y: 1.5}}}}"
    ok = subprocess.run(
        [*cmd, "move_base_msgs/MoveBaseAction", goal % "2.0", "--feedback", "--timeout", "30"],
        env=_env(real_master),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert ok.returncode == 0, ok.stdout + ok.stderr
    assert "Goal finished with status: SUCCEEDED" in ok.stdout
    assert "Feedback:" in ok.stdout and "frame_id: map" in ok.stdout
    assert move_base_stub.next() == "goal map 2.00 1.50"
    bad = subprocess.run(
        [*cmd, "move_base_msgs/MoveBase", goal % "-1.0", "--timeout", "30"],
        env=_env(real_master),
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 1, bad.stdout + bad.stderr
    assert "Goal finished with status: ABORTED (negative x)" in bad.stdout
    assert move_base_stub.next() == "goal map -1.00 1.50"


def test_patrol_goals_through_rospy_actionlib(
    real_master: str, move_base_stub: Lines, tmp_path: Path
) -> None:
    places = tmp_path / "places.yaml"
    places.write_text(
        "frame_id: map\nlocations:\n  a: {x: 1.0, y: 0.0, yaw: 0.0}\n"
        "  b: {x: 2.0, y: 1.0, yaw: 1.57}\n  c: {x: 3.0, y: 2.0, yaw: 3.14}\n"
    )
    move_base_stub.drain()
    run = subprocess.run(
        [
            *[sys.executable, "-m", "roverlab.cli", "patrol"],
            *["--locations", str(places), "--goals", "3", "--rest-time", "0", "--clock", "wall"],
        ],
        env=_env(real_master),
        capture_output=True,
        text=True,
        timeout=90,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "Connected to move base server" in run.stdout
    assert "Success so far: 3/3 = 100%" in run.stdout
    served = [move_base_stub.next() for _ in range(3)]
    wanted = {"goal map 1.00 0.00", "goal map 2.00 1.00", "goal map 3.00 2.00"}
    assert set(served) <= wanted and len(served) == 3
