"""Command-line handling of ``roverlab teleop`` that needs no terminal or network."""

from __future__ import annotations

import pytest

from roverlab.cli.teleop import main, parse_ros_args
from roverlab.errors import RoverlabError
from roverlab.teleop.node import MbotTeleopNode


def test_ros_style_parameters_and_remaps() -> None:
    args = parse_ros_args(["_speed:=3e-1", "_turn:=1", "_repeat_rate:=10", "cmd_vel:=/r1/cmd_vel"])
    assert args.parameters == {"speed": 0.3, "turn": 1.0, "repeat_rate": 10.0}
    assert isinstance(args.parameters["turn"], float)
    assert args.remappings == {"cmd_vel": "/r1/cmd_vel"}
    assert args.node_name is None and args.namespace == "/"


def test_absolute_remap_name_node_name_and_namespace() -> None:
    args = parse_ros_args(["/robot/cmd_vel:=/robot/base/cmd_vel", "__ns:=/robot", "__name:=kb"])
    assert args.remappings == {"/robot/cmd_vel": "/robot/base/cmd_vel"}
    assert (args.node_name, args.namespace) == ("kb", "/robot")


def test_smooth_takes_the_launch_file_parameter_names() -> None:
    args = parse_ros_args(["_scale_linear:=0.1", "_scale_angular:=0.4"], node_class=MbotTeleopNode)
    assert args.parameters == {"scale_linear": 0.1, "scale_angular": 0.4}


@pytest.mark.parametrize(
    ("arg", "match"),
    [
        ("_speed:=abc", "_speed:=abc: not a number"),
        ("_speed:=", "not a number"),
        ("_speed:=true", "not a number"),
        ("_speed:=.nan", "finite"),
        ("_turn:=1e400", "finite"),
        ("_speed:=-0.1", ">= 0"),
        ("_speed:=nan", "finite"),
        ("_foo:=1", "unknown parameter '_foo'"),
        ("_scale_linear:=0.1", "unknown parameter '_scale_linear'"),
        ("speed", "expected NAME:=VALUE"),
        (":=1", "expected NAME:=VALUE"),
        ("__master:=http://x:11311", "unsupported"),
        ("scan:=/other", "cannot remap 'scan'"),
        ("cmd_vel:=/bad name", "invalid topic name"),
        ("__name:=1bad", "invalid node name"),
    ],
)
def test_bad_arguments_are_one_clear_error(arg: str, match: str) -> None:
    with pytest.raises(RoverlabError, match=match):
        parse_ros_args([arg])


def test_same_parameter_twice_is_an_error() -> None:
    with pytest.raises(RoverlabError, match="twice"):
        parse_ros_args(["_speed:=0.1", "_speed:=0.2"])


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--speed", "nan"], "--speed must be a finite number"),
        (["--turn", "inf"], "--turn must be a finite number"),
        (["--speed", "-1"], "--speed must be a finite number >= 0"),
        (["--speed", "0.3", "_speed:=0.3"], "both given"),
        (["_foo:=1"], "unknown parameter"),
    ],
)
def test_main_turns_errors_into_one_line_and_exit_2(
    argv: list[str], match: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and match in err
    assert len(err.strip().splitlines()) == 1


def test_main_without_a_terminal(capsys: pytest.CaptureFixture[str]) -> None:
    # under pytest stdin is not a TTY: refused before any network is touched
    with pytest.raises(SystemExit) as info:
        main(["--speed", "0.3"])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        "error: stdin is not a terminal: teleop reads single key presses from a TTY "
        "(run it in a terminal, not with input from a pipe or file)"
    ]
