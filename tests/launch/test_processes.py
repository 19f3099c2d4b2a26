"""roslaunch's process attributes: output, respawn, respawn_delay, required — and a node
that dies (fails to start, or ends) while the others go on."""

from __future__ import annotations

import logging
import time
from pathlib import Path

import numpy as np
import pytest

from roverlab.core import Context, configure_logging
from roverlab.launch import LaunchError, NodeSpec, build_launch, load_launch
from roverlab.launch.process import ChildNetwork, ScriptProcess
from roverlab.maps import save_map

TF = '<node pkg="tf" type="static_transform_publisher" name="{name}" args="0 0 0 0 0 0 a b 100"{extra}/>'  # noqa: E501


def _launch(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "x.launch"
    path.write_text(f"<launch>\n{body}\n</launch>\n")
    return path


def _map_server(name: str, extra: str, map_file: str) -> str:
    return f'<node pkg="map_server" type="map_server" name="{name}" args="{map_file}"{extra}/>'


def test_attributes_are_read_and_checked(tmp_path: Path) -> None:
    spec = load_launch(_launch(tmp_path, "\n".join([
        TF.format(name="a", extra=' output="screen" respawn="true" respawn_delay="2.5"'),
        TF.format(name="b", extra=' required="True"'),
        TF.format(name="c", extra=""),
    ])))  # fmt: skip
    a, b, c = spec.nodes
    assert (a.output, a.respawn, a.respawn_delay, a.required) == ("screen", True, 2.5, False)
    assert (b.respawn, b.required) == (False, True)
    assert (c.output, c.respawn, c.required) == ("log", False, False)  # roslaunch's defaults
    for extra, message in [
        (' output="file"', "output must be 'log' or 'screen'"),
        (' respawn="yes"', "respawn must be true or false"),
        (' respawn_delay="soon"', "respawn_delay must be a number"),
        (' respawn_delay="-1"', "respawn_delay must be >= 0"),
        (' respawn="true" required="true"', "respawn and required cannot both be true"),
    ]:
        with pytest.raises(LaunchError, match=message):
            load_launch(_launch(tmp_path, TF.format(name="a", extra=extra)))


def test_a_node_that_fails_to_start_is_reported_and_the_others_run(tmp_path: Path) -> None:
    path = _launch(tmp_path, TF.format(name="tf_a", extra="") + "\n"
                   + _map_server("map_server", "", str(tmp_path / "missing.yaml")))  # fmt: skip
    ctx = Context()
    try:
        launch = build_launch(path, context=ctx)
        assert [n.get_name() for n in launch.nodes] == ["tf_a"]
        assert len(launch.deaths) == 1
        assert launch.deaths[0].startswith("process [/map_server] has died: ")
        assert "missing.yaml" in launch.deaths[0]
    finally:
        ctx.shutdown()


def test_a_required_node_that_fails_to_start_ends_the_launch(tmp_path: Path) -> None:
    server = _map_server("map_server", ' required="true"', str(tmp_path / "no.yaml"))
    path = _launch(tmp_path, TF.format(name="tf_a", extra="") + "\n" + server)
    ctx = Context()
    with pytest.raises(LaunchError, match=r"REQUIRED process \[/map_server\] has died"):
        build_launch(path, context=ctx)
    assert ctx.is_shutdown()


def test_respawn_retries_after_the_delay_until_the_node_starts(tmp_path: Path) -> None:
    map_file = tmp_path / "late.yaml"
    path = _launch(tmp_path, _map_server("map_server", ' respawn="true" respawn_delay="0.3"',
                                         str(map_file)))  # fmt: skip
    ctx = Context(clock="wall")
    try:
        launch = build_launch(path, context=ctx)
        assert launch.nodes == [] and "respawning in 0.3 s" in launch.deaths[0]
        ctx.spin_for(0.5)
        assert len(launch.deaths) >= 2  # tried again after 0.3 s, still no map
        grid = np.zeros((10, 10), dtype=np.int8)
        save_map(tmp_path / "late", grid, resolution=0.1, origin=(0.0, 0.0, 0.0))
        deadline = time.monotonic() + 5.0
        while "/map_server" not in launch.running and time.monotonic() < deadline:
            ctx.spin_for(0.1)
        assert "/map_server" in launch.running  # the map appeared: it started
        assert [n.get_name() for n in launch.nodes] == ["map_server"]
    finally:
        ctx.shutdown()


def test_a_node_that_ends_is_respawned_or_ends_a_required_launch(tmp_path: Path) -> None:
    path = _launch(tmp_path, "\n".join([
        TF.format(name="again", extra=' respawn="true"'),
        TF.format(name="needed", extra=' required="true"'),
    ]))  # fmt: skip
    ctx = Context(clock="wall")
    try:
        launch = build_launch(path, context=ctx)
        launch.supervise(period_s=0.05)
        first = launch.running["/again"][1]
        first.destroy_node()
        deadline = time.monotonic() + 5.0
        while launch.running.get("/again", (None, first))[1] is first:
            assert time.monotonic() < deadline, launch.deaths
            ctx.spin_for(0.05)
        assert launch.deaths == ["process [/again] has died: it ended; respawning in 0 s"]
        assert not launch.running["/again"][1].is_destroyed()
        launch.running["/needed"][1].destroy_node()
        while not ctx.is_shutdown():
            assert time.monotonic() < deadline, launch.deaths
            ctx.spin_for(0.05)
        assert launch.deaths[-1].startswith("REQUIRED process [/needed] has died: it ended")
    finally:
        ctx.shutdown()


def test_map_saver_finishes_cleanly_after_writing_the_map(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # roslaunch: map_saver exits 0 once the map is written ("process has finished
    # cleanly"); it used to go on listening for ever
    saved = save_map(tmp_path / "room", np.zeros((4, 5), np.int8), resolution=0.1)
    path = _launch(tmp_path, "\n".join([
        _map_server("map_server", "", str(saved.yaml_path)),
        f'<node pkg="map_server" type="map_saver" name="saver" args="-f {tmp_path / "copy"}"/>',
    ]))  # fmt: skip
    ctx = Context(clock="wall")
    try:
        launch = build_launch(path, context=ctx)
        launch.supervise(period_s=0.05)
        deadline = time.monotonic() + 5.0
        while "/saver" in launch.running:
            assert time.monotonic() < deadline, launch.deaths
            ctx.spin_for(0.05)
        assert launch.deaths == []
        assert "[INFO] process [/saver] has finished cleanly" in capsys.readouterr().err
        assert (tmp_path / "copy.pgm").is_file()
    finally:
        ctx.shutdown()


def test_output_log_keeps_info_off_the_screen_and_in_the_nodes_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("ROVERLAB_LOG_DIR", str(tmp_path / "logs"))
    path = _launch(tmp_path, "\n".join([
        TF.format(name="quiet", extra=""),
        TF.format(name="loud", extra=' output="screen"'),
    ]))  # fmt: skip
    root = logging.getLogger("roverlab")
    saved = (root.handlers[:], root.level, root.propagate)
    configure_logging(logging.INFO)  # to capsys's stderr: put the old handlers back after
    ctx = Context()
    try:
        launch = build_launch(path, context=ctx)
        for name in ("quiet", "loud"):
            node = launch.running[f"/{name}"][1]
            node.get_logger().info(f"{name} says hello")
            node.get_logger().warning(f"{name} warns")
    finally:
        ctx.shutdown()
        root.handlers[:], root.level, root.propagate = saved
    err = capsys.readouterr().err
    assert "loud says hello" in err and "loud warns" in err and "quiet warns" in err
    assert "quiet says hello" not in err
    text = (tmp_path / "logs" / "quiet.log").read_text()
    assert "[INFO]" in text and "quiet says hello" in text and "quiet warns" in text
    assert not (tmp_path / "logs" / "loud.log").exists()


def test_same_named_nodes_in_two_namespaces_log_to_files_of_their_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The log file is named after the node's resolved name (roslaunch's, with ``-`` for
    the slashes): ``/robot1/tf`` and ``/robot2/tf`` do not share ``tf.log``."""
    monkeypatch.setenv("ROVERLAB_LOG_DIR", str(tmp_path / "logs"))
    path = _launch(tmp_path, "\n".join(
        f'<group ns="{ns}">{TF.format(name="tf", extra="")}</group>' for ns in ("robot1", "robot2")
    ))  # fmt: skip
    ctx = Context()
    try:
        launch = build_launch(path, context=ctx)
        for ns in ("robot1", "robot2"):
            launch.running[f"/{ns}/tf"][1].get_logger().warning(f"{ns} says hello")
    finally:
        ctx.shutdown()
    for ns, other in (("robot1", "robot2"), ("robot2", "robot1")):
        text = (tmp_path / "logs" / f"{ns}-tf.log").read_text()
        assert f"{ns} says hello" in text and other not in text
    assert not (tmp_path / "logs" / "tf.log").exists()


def test_same_named_script_processes_log_to_files_of_their_own(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A script process's stdout (``output="log"``) goes to the file of its resolved name;
    ``launch-prefix="echo"`` makes the process print its own command line there."""
    monkeypatch.setenv("ROVERLAB_LOG_DIR", str(tmp_path / "logs"))
    script = tmp_path / "talker.py"
    script.write_text("print('hi')\n")
    procs = []
    for ns in ("/robot1", "/robot2"):
        spec = NodeSpec("my_pkg", "talker.py", "talker", namespace=ns, launch_prefix="echo")
        procs.append(ScriptProcess(spec, script, clock="wall", params={}, network=ChildNetwork()))
    for proc in procs:
        assert proc.popen.wait(10) == 0
        proc.stop()
    logs = tmp_path / "logs"
    assert sorted(p.name for p in logs.iterdir()) == ["robot1-talker.log", "robot2-talker.log"]
    for ns in ("robot1", "robot2"):
        assert (logs / f"{ns}-talker.log").read_text().split()[-1] == f"__ns:=/{ns}"


def test_env_is_set_for_the_nodes_of_its_scope_only(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from roverlab.launch import registry

    seen: dict[str, str | None] = {}

    def spy(state: object, spec: object) -> None:
        import os

        seen[spec.name] = os.environ.get("ROVERLAB_TEST_ENV")  # type: ignore[attr-defined]

    monkeypatch.setitem(registry.REGISTRY, ("spy", "spy"), spy)
    monkeypatch.delenv("ROVERLAB_TEST_ENV", raising=False)
    inc = tmp_path / "inc.launch"
    inc.write_text('<launch><node pkg="spy" type="spy" name="included"/></launch>')
    path = _launch(
        tmp_path,
        f"""
<node pkg="spy" type="spy" name="before"/>
<group>
  <env name="ROVERLAB_TEST_ENV" value="group"/>
  <node pkg="spy" type="spy" name="in_group"/>
</group>
<node pkg="spy" type="spy" name="own"><env name="ROVERLAB_TEST_ENV" value="node"/></node>
<include file="{inc}"><env name="ROVERLAB_TEST_ENV" value="include"/></include>
<env name="ROVERLAB_TEST_ENV" value="file"/>
<node pkg="spy" type="spy" name="after"/>""",
    )
    ctx = Context()
    try:
        build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    assert seen == {"before": None, "in_group": "group", "own": "node", "included": "include",
                    "after": "file"}  # fmt: skip
    import os

    assert "ROVERLAB_TEST_ENV" not in os.environ  # the launch's own environment is untouched
