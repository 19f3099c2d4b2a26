"""The newcomer check: the README's commands, typed into terminals (tmux) in its order, as a
new user follows them; the run fails on a traceback, a warning said more than a few times a
minute, or a start that warns of timeouts and dropped data.

Every command is taken from the page it follows (the test checks that the page still has
it, word for word). The default run has the short form, seed 003's two terminals (the
simulator, then ``navigation_stack.launch`` following its clock); ``-m slow`` runs every
flow of the README: the live system and its second-terminal commands, seed 000's mapping,
seed 003 with the dashboard and the patrol, seed 004's car.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.net import free_port
from tests.helpers.newcomer import TMUX, Terminals, problems

README = Path(__file__).resolve().parents[2] / "README.md"
# What a start before the first /clock used to print. (A costmap's "transform timeout" is
# not among them here: across processes it also says that the machine is too busy to
# deliver TF in time, as in ROS; tests/launch/test_quiet_start.py holds the 20 s start to
# none on a clock it controls.)
NAV_START_WORDS = ("No laser scan", "dropped 100", "timed out", "waiting for the transform")


@dataclass(frozen=True)
class Step:
    """``open`` a terminal running ``command``, ``type`` it into an open one, press
    ``keys`` there (``command`` holds them), or ``wait``."""

    kind: str
    terminal: str = ""
    command: str = ""
    seconds: float = 0.0


def _open(terminal: str, command: str) -> Step:
    return Step("open", terminal, command)


def _type(terminal: str, command: str) -> Step:
    return Step("type", terminal, command)


def _keys(terminal: str, keys: str) -> Step:
    return Step("keys", terminal, keys)


def _wait(seconds: float) -> Step:
    return Step("wait", seconds=seconds)


SEED003 = [
    _open("sim", "roverlab launch bingda_tutorials simulation_robot.launch"),
    _wait(5.0),
    _open("nav", "roverlab launch robot_navigation navigation_stack.launch simulation:=true"),
    _wait(15.0),
]
FLOWS: dict[str, list[Step]] = {
    "live": [
        _open("sim", "roverlab sim"),
        _wait(8.0),
        _open("cli", "roverlab topic list -t"),
        _type("cli", "roverlab topic echo /odom --once"),
        _type("cli", "roverlab node list"),
        _type("cli", "roverlab param get /gazebo physics_rate"),
        _type("cli", "roverlab service list -t"),
        _type("cli", "roverlab action list -t"),
        _wait(30.0),
    ],
    "seed000": [
        _open("slam", "roverlab launch mbot_navigation gmapping_demo.launch"),
        _wait(10.0),
        _open("teleop", "roverlab teleop"),
        _keys("teleop", "iiiijjjiii"),
        _wait(15.0),
        _open("save", "roverlab map save -f maze"),
        _wait(10.0),
        _type("save", "roverlab slam mapeval maze.yaml --world maze"),
        _wait(15.0),
    ],
    "seed003": [
        *SEED003[:-1],
        _open("rviz", "roverlab launch robot_navigation slam_rviz.launch"),
        _wait(10.0),
        _open("patrol", "roverlab patrol --goals 20"),
        _wait(60.0),
    ],
    "seed004": [
        _open("car", "roverlab launch urdlee car_ee.launch"),
        _wait(10.0),
        _open(
            "drive",
            'roverlab topic pub -r 10 /cmd_vel geometry_msgs/Twist "{linear: {x: 0.2}, '
            'angular: {z: 0.5}}"',
        ),
        _wait(20.0),
    ],
}


def _run(steps: list[Step], tmp_path: Path) -> tuple[dict[str, str], float]:
    """Follow ``steps`` in fresh terminals (in ``tmp_path``, with ``BASE_TYPE`` exported
    as seed 003's page says, the dashboard on a free port); the transcripts and minutes."""
    readme = README.read_text()
    for step in steps:
        if step.kind in ("open", "type"):
            assert step.command in readme, f"README lost: {step.command}"
    terms = Terminals(
        tmp_path / "logs",
        env={"BASE_TYPE": "NanoRobot", "ROVERLAB_DASHBOARD_PORT": str(free_port())},
    )
    started = time.monotonic()
    try:
        for step in steps:
            if step.kind == "wait":
                time.sleep(step.seconds)
            elif step.kind == "open":
                terms.open(step.terminal, f"cd {tmp_path} && {step.command}")
            elif step.kind == "keys":
                terms.keys(step.terminal, step.command)
            else:
                terms.type(step.terminal, step.command)
        return terms.close(), (time.monotonic() - started) / 60.0
    finally:
        terms.kill()


needs_tmux = pytest.mark.skipif(
    TMUX is None, reason="tmux is absent (scripts/install-system-deps.sh)"
)


@needs_tmux
def test_seed003_terminals_start_quietly(tmp_path: Path) -> None:
    """The short form: seed 003's simulator, then navigation_stack.launch in a second
    terminal: no traceback, no warning said over and over, and no timeout or dropped-data
    warning while it starts."""
    out, minutes = _run(SEED003, tmp_path)
    assert "started 2 nodes" in out["sim"], out["sim"]
    assert "started 3 nodes: /map_server, /amcl, /move_base" in out["nav"], out["nav"]
    assert not problems(out, minutes), problems(out, minutes)
    noisy = [line for line in out["nav"].splitlines() if any(w in line for w in NAV_START_WORDS)]
    assert not noisy, out["nav"]


# what shows that a flow's commands ran (terminal -> a piece of its transcript)
RAN = {
    "live": {"sim": "simulating mybot", "cli": "/scan [sensor_msgs/msg/LaserScan]"},
    "seed000": {"slam": "started", "save": "maze.yaml"},
    "seed003": {"nav": "started 3 nodes", "patrol": "Going to:"},
    "seed004": {"car": "started"},
}


@needs_tmux
@pytest.mark.slow
@pytest.mark.parametrize("flow", sorted(FLOWS))
def test_readme_flow_runs_cleanly(flow: str, tmp_path: Path) -> None:
    out, minutes = _run(FLOWS[flow], tmp_path)
    for terminal, shown in RAN[flow].items():
        assert shown in out[terminal], (terminal, out[terminal])
    assert not problems(out, minutes), problems(out, minutes)
