"""``roverlab urdf check`` / ``xacro`` through typer's CliRunner."""

from __future__ import annotations

from pathlib import Path

import pytest
from typer.testing import CliRunner

from roverlab.cli.description import app, parse_mappings
from roverlab.description import DescriptionError
from tests.description.conftest import MYBOT_URDF, MYBOT_XACRO, robot

runner = CliRunner()


def test_check_prints_check_urdf_report() -> None:
    result = runner.invoke(app, ["check", str(MYBOT_URDF)])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("robot name is: mybot\n---------- Successfully Parsed XML")
    assert "root Link: base_footprint has 1 child(ren)" in result.stdout


def test_check_with_xacro_args() -> None:
    result = runner.invoke(app, ["check", str(MYBOT_XACRO), "--arg", "laser_visual:=true"])
    assert result.exit_code == 0, result.output
    assert "rplidar_sensor (ray)" in result.stdout
    positional = runner.invoke(app, ["check", str(MYBOT_XACRO), "camera_visual:=true"])
    assert positional.exit_code == 0


def test_check_bad_file_exits_2_with_one_error_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.urdf"
    bad.write_text(robot('<link name="a"/><link name="b"/>'))
    result = runner.invoke(app, ["check", str(bad)])
    assert result.exit_code == 2
    assert result.stdout == ""
    lines = result.stderr.splitlines()
    assert lines == [
        f"error: {bad}: two root links found: 'a' and 'b'; every link but one needs a parent joint"
    ]


def test_check_bad_xacro_and_bad_arg_syntax(tmp_path: Path) -> None:
    bad = tmp_path / "bad.xacro"
    bad.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:nope/></robot>'
    )
    result = runner.invoke(app, ["check", str(bad)])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {bad}: unknown macro name: xacro:nope")
    assert len(result.stderr.splitlines()) == 1
    result = runner.invoke(app, ["check", str(MYBOT_XACRO), "--arg", "laser_visual=true"])
    assert result.exit_code == 2
    assert "is not of the form name:=value" in result.stderr


def test_xacro_prints_expanded_urdf(tmp_path: Path) -> None:
    result = runner.invoke(app, ["xacro", str(MYBOT_XACRO), "laser_visual:=true"])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith('<?xml version="1.0" ?>')
    assert "<visualize>true</visualize>" in result.stdout
    assert "xacro:" not in result.stdout.split("-->")[-1]
    out = tmp_path / "mybot.urdf"
    result = runner.invoke(app, ["xacro", str(MYBOT_XACRO), "-o", str(out)])
    assert result.exit_code == 0
    assert "<robot" in out.read_text()


def test_package_path_option(tmp_path: Path) -> None:
    pkg = tmp_path / "ws" / "cli_pkg"
    pkg.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>cli_pkg</name></package>")
    (pkg / "r.xacro").write_text(robot('<link name="only"/>'))
    top = tmp_path / "top.xacro"
    top.write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find cli_pkg)/r.xacro"/></robot>'
    )
    assert runner.invoke(app, ["check", str(top)]).exit_code == 2
    result = runner.invoke(app, ["check", str(top), "-p", str(tmp_path / "ws")])
    assert result.exit_code == 0, result.output
    assert "root Link: only has 0 child(ren)" in result.stdout


def test_parse_mappings() -> None:
    assert parse_mappings(["a:=1", "b:=x:=y", "c:="]) == {"a": "1", "b": "x:=y", "c": ""}
    with pytest.raises(DescriptionError):
        parse_mappings([":=1"])
