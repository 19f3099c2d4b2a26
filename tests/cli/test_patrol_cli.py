"""``roverlab patrol`` (seed 002's slam.py) against seed 003's navigation in another
process, on that process's sim clock."""

from __future__ import annotations

import re
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.nodes import run_main
from tests.helpers.procs import Proc

pytestmark = pytest.mark.zenoh

HELPER = Path(__file__).resolve().parents[1] / "helpers" / "nav_stack.py"
LINE = re.compile(r"^\[INFO\] \[\d+\.\d{6}\]: (.*)$")


@pytest.fixture
def nav_stack(daemon: str) -> Iterator[Proc]:
    p = Proc([sys.executable, str(HELPER), "25"])
    assert p.wait_line(lambda line: line.startswith("READY"), timeout=60) == "READY"
    yield p
    p.stop()


def test_patrol_three_goals_prints_the_seed_s_statistics(nav_stack: Proc, cli: Any) -> None:
    r = cli("patrol", "--goals", "3", "--rest-time", "0.5", "--seed", "1", timeout=240)
    assert r.returncode == 0, r.stderr
    msgs = [m.group(1) for m in map(LINE.match, r.stdout.splitlines()) if m]
    assert msgs[:3] == [
        "Waiting for move_base action server...",
        "Connected to move base server",
        "Starting navigation test",
    ]
    goals = [m for m in msgs if m.startswith("Going to: ")]
    assert len(goals) == 3 and goals[0] != goals[1] != goals[2]
    assert msgs.count("Goal succeeded!") == 3
    assert "Success so far: 3/3 = 100%" in msgs
    assert re.fullmatch(r"Running time: \d+\.\d min Distance: \d+\.\d m", msgs[-1])
    assert "patrol: 3/3 goals succeeded" in r.stderr


def test_ctrl_c_stops_the_robot(nav_stack: Proc, daemon: str) -> None:
    p = Proc([sys.executable, "-m", "roverlab.cli", "patrol", "--rest-time", "0.5"])
    try:
        p.wait_line(lambda line: "Going to:" in line, timeout=60)
        p.popen.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
    finally:
        if p.popen.poll() is None:
            p.popen.kill()
    assert "Stopping the robot..." in out
    # 0 if every goal sent so far had succeeded, else 1 (the interrupted one counts)
    assert p.popen.returncode in (0, 1) and re.search(r"patrol: \d+/\d+ goals succeeded", err)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--goals", "-1"], "--goals must be >= 0"),
        (["--rest-time", "nan"], "--rest-time must be a number >= 0"),
        (["--locations", "/nonexistent/places.yaml"], "cannot read"),
        (["--clock", "fast"], "unknown --clock"),
    ],
)
def test_bad_input_is_one_line_exit_2(
    daemon: str, args: list[str], needle: str, capfd: pytest.CaptureFixture[str]
) -> None:
    # in this process, stderr captured at the file descriptor (a process per case costs an
    # import; the tests above run the command in its own process)
    assert run_main(["patrol", *args]) == 2
    err = capfd.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], err
