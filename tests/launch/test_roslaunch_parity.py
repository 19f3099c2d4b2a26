"""Where roverlab meets roslaunch's behaviour for ``<param command>`` (no shell), ``cwd``
on roverlab's own nodes, and command-line args the file does not declare."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.core import Context
from roverlab.launch import LaunchError, build_launch, load_launch


def _launch(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "x.launch"
    path.write_text(f"<launch>\n{body}\n</launch>\n")
    return path


def test_a_command_runs_split_as_roslaunch_splits_it_without_a_shell(tmp_path: Path) -> None:
    path = _launch(tmp_path, """<param name="p" command="echo '$HOME' ; echo x | cat"/>""")
    assert load_launch(path).params["/p"] == "$HOME ; echo x | cat\n"


@pytest.mark.parametrize(
    ("command", "message"),
    [
        ("false --now", r"x\.launch: <param name=\"p\">: command 'false --now' exited 1"),
        ("no-such-tool a", r"x\.launch: <param name=\"p\">: command 'no-such-tool a': "
         r"no-such-tool: no such command"),
        ("echo 'open", r"x\.launch: <param name=\"p\">: cannot parse command \"echo 'open\""),
    ],
)  # fmt: skip
def test_a_failing_command_is_one_line_naming_the_file_and_command(
    tmp_path: Path, command: str, message: str
) -> None:
    path = _launch(tmp_path, f'<param name="p" command="{command}"/>')
    with pytest.raises(LaunchError, match=message) as err:
        load_launch(path)
    assert "\n" not in str(err.value)


def test_cwd_on_an_in_process_node_is_named(tmp_path: Path) -> None:
    tf = '<node pkg="tf" type="static_transform_publisher" name="{}" args="0 0 0 0 0 0 a b 100"{}/>'
    path = _launch(tmp_path, tf.format("a", ' cwd="node"') + tf.format("b", ""))
    ctx = Context()
    try:
        launch = build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    (warning,) = launch.warnings
    assert 'x.launch: <node name="a">' in warning
    assert "cwd='node' not applied: roverlab's tf/static_transform_publisher runs in" in warning


def test_an_undeclared_command_line_arg_is_named(tmp_path: Path) -> None:
    path = _launch(tmp_path, '<arg name="world" default="maze"/>')
    spec = load_launch(path, {"world": "house", "wrold": "x"})
    assert spec.warnings == [
        f'{path}: wrold:= on the command line, but the file declares no <arg name="wrold">'
    ]
