"""The CLI from a second terminal against running processes, and its bad-input errors."""

from __future__ import annotations

import subprocess
import sys
from typing import Any

import pytest
import yaml

from roverlab.description import load_robot
from roverlab.sim.app import resolve_robot
from tests.helpers.imports import loaded_after
from tests.helpers.nodes import run_main
from tests.helpers.procs import Proc, twist_pub_args

pytestmark = pytest.mark.zenoh


def test_echo_once_prints_yaml_from_running_process(node_proc: Any, cli: Any) -> None:
    node_proc("talker")
    r = cli("topic", "echo", "/chatter", "--once")
    assert r.returncode == 0, r.stderr
    body, sep, rest = r.stdout.partition("---")
    assert sep and rest.strip() == ""
    assert yaml.safe_load(body)["data"].startswith("hello world ")


def test_seed_habit_pub_rate_and_echo_once_find_each_other(cli: Any) -> None:
    """Two CLI processes with nothing else running (the daemon links them)."""
    pub = Proc(
        [
            sys.executable,
            "-m",
            "roverlab.cli",
            *twist_pub_args(0.2, 0.5),
        ]
    )
    try:
        r = cli("topic", "echo", "/cmd_vel", "--once", timeout=30)
        assert r.returncode == 0, r.stderr
        data = yaml.safe_load(r.stdout.split("---")[0])
        assert data["linear"] == {"x": 0.2, "y": 0.0, "z": 0.0}
        assert data["angular"] == {"x": 0.0, "y": 0.0, "z": 0.5}
    finally:
        pub.stop()


def test_pub_once_reaches_subscriber_and_seed_no_space_form(node_proc: Any, cli: Any) -> None:
    listener = node_proc("listener")
    r = cli(
        "topic",
        "pub",
        "-1",
        "/cmd_vel",
        "geometry_msgs/Twist",
        "{linear:{x:0.2,y:0,z:0},angular:{x:0,y:0,z:0.5}}",
    )
    assert r.returncode == 0, r.stderr
    assert listener.wait_line(lambda s: s.startswith("cmd_vel")) == "cmd_vel 0.200 0.500"


def test_list_info_node_and_hz(node_proc: Any, cli: Any) -> None:
    node_proc("talker")
    r = cli("topic", "list", "-t")
    assert r.returncode == 0, r.stderr
    assert "/chatter [std_msgs/msg/String]" in r.stdout.splitlines()
    r = cli("topic", "info", "/chatter", "-v")
    assert "Type: std_msgs/msg/String" in r.stdout
    assert "Publisher count: 1" in r.stdout and "/proc_talker" in r.stdout
    r = cli("node", "list")
    assert "/proc_talker" in r.stdout.splitlines()
    r = cli("topic", "hz", "/chatter", "--duration", "3.5")
    assert r.returncode == 0, r.stderr
    rates = [float(line.split(":")[1]) for line in r.stdout.splitlines() if "average rate" in line]
    assert rates and 40.0 <= rates[-1] <= 60.0  # published at 50 Hz


def test_param_get_set_dump(node_proc: Any, cli: Any, capfd: pytest.CaptureFixture[str]) -> None:
    node_proc("pong")
    assert cli("param", "get", "/proc_pong", "gain").stdout.strip() == "1.5"
    # the other commands in this process (output captured at the file descriptors): the
    # node is still in its own process, each command its own Zenoh session
    capfd.readouterr()
    assert run_main(["param", "set", "/proc_pong", "gain", "2.5"]) == 0
    assert "successful" in capfd.readouterr().out
    assert run_main(["param", "dump", "proc_pong"]) == 0
    dumped = yaml.safe_load(capfd.readouterr().out)
    assert dumped["/proc_pong"]["ros__parameters"]["gain"] == 2.5
    assert run_main(["param", "set", "/proc_pong", "gain", "fast"]) == 2
    err = capfd.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "type double" in err, err
    assert run_main(["param", "get", "/proc_pong", "gian"]) == 2
    assert "did you mean 'gain'" in capfd.readouterr().err


def test_a_topic_command_does_not_import_the_stack() -> None:
    """The root command loads a subcommand's module when it runs: ``roverlab topic``
    must not pay for the simulator, move_base, the launch registry or FastAPI."""
    code = (
        "from typer.testing import CliRunner\n"
        "from roverlab.cli.main import app\n"
        "r = CliRunner().invoke(app, ['topic', 'pub', '--help'])\n"
        "assert r.exit_code == 0 and 'Usage: roverlab topic pub' in r.output, r.output\n"
    )
    heavy = ("roverlab.sim.app", "roverlab.navigation.move_base.node",
             "roverlab.launch.registry", "fastapi", "roverlab.cli.demo")  # fmt: skip
    assert loaded_after(code, heavy) == []


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["/cmd_vel", "geometry_msgs/Twist", "{linear: {x: 0.2"], "YAML"),
        (["/cmd_vel", "geometry_msgs/Twst", "{}"], "unknown message type"),
        (["/cmd_vel", "geometry_msgs/Twist", "{linear: {w: 1}}"], "linear.w"),
        (["/cmd_vel", "geometry_msgs/Twist", "{linear: {x: fast}}"], "linear.x"),
        (["/bad topic", "geometry_msgs/Twist", "{}"], "invalid topic name"),
    ],
)
def test_pub_bad_input_is_one_line_exit_2(
    args: list[str], needle: str, capfd: pytest.CaptureFixture[str]
) -> None:
    # in this process, stderr captured at the file descriptor (a process per case costs an
    # import; test_info_unknown_topic_exit_2 runs a real one)
    assert run_main(["topic", "pub", "-1", *args]) == 2
    err = capfd.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert needle in lines[0]


def test_info_unknown_topic_exit_2(cli: Any) -> None:
    r = cli("topic", "info", "/nothing_here")
    assert r.returncode == 2 and "unknown topic '/nothing_here'" in r.stderr


def test_tf_echo_and_frames_against_the_simulator(daemon: str, cli: Any) -> None:
    sim = Proc([sys.executable, "-m", "roverlab.cli", "sim", "--duration", "60"])
    try:
        r = cli("tf", "echo", "odom", "base_laser_link", "--count", "1", "--timeout", "15")
        assert r.returncode == 0, r.stderr
        assert "- Translation: [" in r.stdout and "- Rotation: in Quaternion" in r.stdout
        # the lidar's height on mybot, from its URDF
        links = load_robot(resolve_robot("mybot")).link_transforms()
        z = (~links["base_footprint"] * links["base_laser_link"]).translation[2]
        translation = r.stdout.split("- Translation: [")[1].split("]")[0]
        assert abs(float(translation.split(",")[2]) - z) < 1e-3
        r = cli("tf", "frames", "--wait", "5")  # view_frames listens 5 s; 2 s flaked under load
        assert r.returncode == 0, r.stderr
        for frame in ("odom", "base_footprint", "base_link", "base_laser_link"):
            assert frame in r.stdout
    finally:
        sim.stop()


def test_help_is_complete() -> None:
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "topic", "pub", "--help"],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert r.returncode == 0
    assert "Usage: roverlab topic pub" in r.stdout
    for opt in ("--rate", "--once", "--times", "topic", "msg_type", "values"):
        assert opt in r.stdout
