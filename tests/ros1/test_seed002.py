"""Seed 002's scripts run unchanged by ``roverlab run``: slam.py against a move_base
stand-in that succeeds, aborts or never answers; keyboard.py through a pty."""

from __future__ import annotations

import itertools
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from roverlab.core.transport.zenoh import (
    ZenohOptions,
    daemon_endpoint,
    open_session,
    query_graph,
)
from tests.helpers.procs import Proc

pytestmark = pytest.mark.zenoh

REPO = Path(__file__).resolve().parents[2]
SEED = REPO / "examples" / "seed002"
HELPER = REPO / "tests" / "helpers" / "fake_move_base.py"
LINE = re.compile(r"^\[INFO\] \[\d+\.\d{6}, \d+\.\d{6}\]: (.*)$")


@pytest.fixture
def move_base(daemon: str) -> Iterator[Callable[[str, float], Proc]]:
    procs: list[Proc] = []

    def start(behaviour: str, rate: float) -> Proc:
        p = Proc([sys.executable, str(HELPER), behaviour, str(rate)])
        procs.append(p)
        assert p.wait_line(lambda line: line.startswith("READY")) == "READY"
        _wait_for_clock_publisher()
        return p

    yield start
    for p in procs:
        p.stop()


def _wait_for_clock_publisher() -> None:
    """Until the router lists the stand-in's /clock, so `roverlab run`'s --clock auto sees it."""
    session, temps = open_session(ZenohOptions(connect=(daemon_endpoint(),)))
    try:
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            ents = query_graph(session, 0, 0.5)
            if any(e.kind == "publisher" and e.topic == "/clock" for e in ents):
                return
            time.sleep(0.05)
        raise AssertionError("the move_base stand-in's /clock never appeared")
    finally:
        session.close()
        for t in temps:
            os.unlink(t)


def _slam(until: Callable[[list[str]], bool], timeout: float = 60.0) -> tuple[list[str], str, int]:
    """Run slam.py until ``until(messages)``, then Ctrl-C it; its log messages, stderr
    and exit status."""
    proc = Proc(
        [sys.executable, "-m", "roverlab.cli", "run", str(SEED / "slam.py"), "_rest_time:=1"]
    )
    messages: list[str] = []
    try:
        deadline = time.monotonic() + timeout
        while not until(messages):
            assert time.monotonic() < deadline, f"slam.py said only: {messages}"
            line = proc.wait_line(timeout=max(0.1, deadline - time.monotonic()))
            m = LINE.match(line)
            assert m, f"not a rospy log line: {line!r}"
            messages.append(m.group(1))
        proc.popen.send_signal(signal.SIGINT)
        try:
            out, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.popen.send_signal(signal.SIGABRT)  # faulthandler prints every thread
            out, err = proc.communicate(timeout=10)
            raise AssertionError(f"slam.py did not stop on Ctrl-C: {err[-4000:]}") from None
    finally:
        if proc.popen.poll() is None:
            proc.popen.kill()
    messages += [LINE.match(x).group(1) for x in out.splitlines() if LINE.match(x)]  # type: ignore[union-attr]
    return messages, err, proc.popen.returncode


def test_slam_py_patrols_and_reports(move_base: Any) -> None:
    server = move_base("succeed", 20.0)
    messages, err, code = _slam(lambda m: sum(x.startswith("Running time") for x in m) >= 3)
    assert code == 0, err
    assert messages[:3] == [
        "Waiting for move_base action server...",
        "Connected to move base server",
        "Starting navigation test",
    ]
    goals = [x for x in messages if x.startswith("Going to: ")]
    assert len(goals) >= 3 and all(x[-1] in "123456" for x in goals), messages
    # random order without repeating the previous place
    assert all(a != b for a, b in itertools.pairwise(goals))
    for n in (1, 2, 3):
        assert f"Success so far: {n}/{n} = 100%" in messages
    assert messages.count("Goal succeeded!") >= 3 and "State:3" in messages
    runs = [x for x in messages if x.startswith("Running time: ")]
    assert all(re.fullmatch(r"Running time: \d+\.\d min Distance: \d+\.\d m", x) for x in runs)
    # Ctrl-C: the shutdown hook cancels the goal and stops the robot, as in ROS
    assert "Stopping the robot..." in messages
    assert messages[-1] == "Exploring SLAM finished."
    server.stop()
    out = server.rest().splitlines()
    # the goals reached the server in the map frame at the seed's coordinates, and the
    # shutdown hook's zero Twist reached /cmd_vel
    seed_places = {
        "4.589 -0.376",
        "4.231 -6.050",
        "-0.674 -5.244",
        "-5.543 -4.779",
        "-4.701 -0.590",
        "2.924 0.018",
    }
    goal_lines = [x for x in out if x.startswith("goal ")]
    assert goal_lines and all(
        x.startswith("goal map ") and x[len("goal map ") :] in seed_places for x in goal_lines
    )
    assert "cmd_vel 0.000 0.000" in out


def test_slam_py_reports_aborted_goals(move_base: Any) -> None:
    move_base("abort", 20.0)
    messages, err, code = _slam(lambda m: sum(x.startswith("Running time") for x in m) >= 2)
    assert code == 0, err
    assert "Goal failed with error code: ABORTED" in messages
    assert "Success so far: 0/1 = 0%" in messages and "Success so far: 0/2 = 0%" in messages
    assert "Running time: 0.0 min Distance: 0.0 m" in messages


def test_slam_py_times_out_a_goal_after_300_s(move_base: Any) -> None:
    server = move_base("hang", 200.0)  # 300 s of sim time pass in 1.5 s
    messages, err, code = _slam(lambda m: "Success so far: 0/1 = 0%" in m)
    assert code == 0, err
    assert "Timed out achieving goal" in messages
    server.stop()
    out = server.rest()
    assert "preempt" in out.splitlines()  # slam.py canceled the goal it gave up on


def test_keyboard_py_through_a_pty(daemon: str) -> None:
    from tests.teleop.test_pty import Receiver

    receiver = Receiver()
    master, slave = os.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "run", str(SEED / "keyboard.py"), "_speed:=0.4"],
        stdin=slave,
        stdout=slave,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
        start_new_session=True,
    )
    os.close(slave)
    try:
        screen = b""
        deadline = time.monotonic() + 30
        while b"currently:" not in screen and time.monotonic() < deadline:
            screen += os.read(master, 4096)
        assert b"Reading from the keyboard  and Publishing to Twist!" in screen
        time.sleep(1.0)  # the publisher finds the receiver
        os.write(master, b"i")
        assert receiver.wait_for(lambda msgs: (0.4, 0.0, 0.0, 0.0) in msgs)
        os.write(master, b"j")
        assert receiver.wait_for(lambda msgs: (0.0, 0.0, 0.0, 0.5) in msgs)
        os.write(master, b"\x03")  # raw mode: Ctrl-C is a key; the script stops the robot
        assert proc.wait(timeout=20) == 0, proc.stderr.read() if proc.stderr else ""
        assert receiver.wait_for(lambda msgs: msgs[-1] == (0.0, 0.0, 0.0, 0.0))
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(master)
        receiver.close()
