"""``roverlab run``: a registry node (rosrun), a script found in a package, bad targets."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from roverlab.maps import save_map
from tests.helpers.nodes import run_main
from tests.helpers.procs import Proc

pytestmark = pytest.mark.zenoh


def _map_server(yaml_path: Path, *args: str) -> Proc:
    """``roverlab run map_server map_server YAML ARGS...`` in a process of its own."""
    command = ["run", "map_server", "map_server", str(yaml_path), *args]
    return Proc([sys.executable, "-m", "roverlab.cli", *command])


def test_run_registry_node_serves_static_map(
    cli: Any, tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    grid = np.zeros((20, 30), np.int8)
    grid[5, :] = 100
    saved = save_map(tmp_path / "room", grid, resolution=0.1, origin=(-1.0, -1.0, 0.0))
    server = _map_server(saved.yaml_path, "__name:=my_map_server", "_frame_id:=world")
    try:
        r = cli("service", "call", "/static_map", "nav_msgs/GetMap", "--timeout", "15")
        assert r.returncode == 0, r.stderr
        reply = yaml.safe_load(r.stdout.split("response:")[1])
        info = reply["map"]["info"]
        assert (info["width"], info["height"]) == (30, 20)
        assert reply["map"]["header"]["frame_id"] == "world"
        # node list through the entry point in this process (a process adds an import)
        capfd.readouterr()
        assert run_main(["node", "list"]) == 0
        assert "/my_map_server" in capfd.readouterr().out.split()
    finally:
        server.stop()


def test_run_map_saver_exits_once_the_map_is_written(cli: Any, tmp_path: Path) -> None:
    # `rosrun map_server map_saver -f NAME` exits 0 after "Done"; roverlab's run used to
    # keep spinning after writing the map, until Ctrl-C
    grid = np.zeros((10, 12), np.int8)
    grid[2, :] = 100
    saved = save_map(tmp_path / "room", grid, resolution=0.1, origin=(0.0, 0.0, 0.0))
    server = _map_server(saved.yaml_path)
    try:
        r = cli("run", "map_server", "map_saver", "-f", str(tmp_path / "copy"), timeout=60)
        assert r.returncode == 0, r.stderr
        assert "Done" in r.stderr
        assert (tmp_path / "copy.pgm").read_bytes() == saved.image_path.read_bytes()
    finally:
        server.stop()


def _hello_pkg(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Package hello_pkg in ``tmp_path/ws`` (on ROVERLAB_PACKAGE_PATH): its folder."""
    pkg = tmp_path / "ws" / "hello_pkg"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>hello_pkg</name></package>")
    monkeypatch.setenv("ROVERLAB_PACKAGE_PATH", str(tmp_path / "ws"))
    return pkg


@pytest.mark.parametrize("executable", [True, False])
def test_run_script_from_a_package(
    cli: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, executable: bool
) -> None:
    script = _hello_pkg(tmp_path, monkeypatch) / "scripts" / "hello.py"
    script.write_text(
        "import rospy\n"
        "rospy.init_node('hello')\n"
        "rospy.loginfo('hello from %s with %s', rospy.get_name(), rospy.get_param('~who'))\n"
    )
    script.chmod(0o755 if executable else 0o644)
    r = cli("run", "--clock", "wall", "hello_pkg", "hello.py", "_who:=ros")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().endswith("]: hello from /hello with ros")
    # rosrun refuses a file without the executable bit: roverlab runs it, with a note
    notes = [line for line in r.stderr.splitlines() if line.startswith("note: ")]
    if executable:
        assert notes == [], r.stderr
    else:
        assert notes == [f"note: {script} is not executable (rosrun refuses it; chmod +x it "
                         "for ROS): run anyway"], r.stderr  # fmt: skip


def test_run_refuses_an_ambiguous_or_compiled_package_script(
    daemon: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
) -> None:
    pkg = _hello_pkg(tmp_path, monkeypatch)
    (pkg / "nodes").mkdir()
    for folder in ("scripts", "nodes"):  # rosrun asks which; roslaunch refuses the node
        (pkg / folder / "twice.py").write_text("print('ran')\n")
        (pkg / folder / "twice.py").chmod(0o755)
    (pkg / "nodes" / "driver_node").write_bytes(b"\x7fELF\x02\x01\x01")
    (pkg / "nodes" / "driver_node").chmod(0o755)
    assert run_main(["run", "hello_pkg", "twice.py"]) == 2
    out, err = capfd.readouterr()
    assert "ran" not in out
    (line,) = err.strip().splitlines()
    assert "multiple files named [twice.py] in package [hello_pkg]" in line
    assert str(pkg / "nodes" / "twice.py") in line and str(pkg / "scripts" / "twice.py") in line
    assert line.endswith("(name one by its path in the package: nodes/twice.py)")
    # rosrun's PKG PATH: a path inside the package names one file; one leaving it is refused
    assert run_main(["run", "hello_pkg", "scripts/twice.py"]) == 0
    assert capfd.readouterr().out == "ran\n"
    assert run_main(["run", "hello_pkg", "scripts/../../hello_pkg/nodes/twice.py"]) == 2
    (line,) = capfd.readouterr().err.strip().splitlines()
    assert line.endswith(
        f"'scripts/../../hello_pkg/nodes/twice.py' is outside package hello_pkg ({pkg})"
    )
    assert run_main(["run", "hello_pkg", "driver_node"]) == 2
    (line,) = capfd.readouterr().err.strip().splitlines()
    assert f"{pkg / 'nodes' / 'driver_node'} is not a Python script" in line
    # the type is a file name, not a pattern (rosrun matches names exactly)
    assert run_main(["run", "hello_pkg", "tw*.py"]) == 2
    (line,) = capfd.readouterr().err.strip().splitlines()
    assert "no file 'tw*.py' in package hello_pkg" in line


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["no_such_script.py"], "no_such_script.py: no such file"),
        (["no_such_pkg", "thing"], "not a roverlab node, and package 'no_such_pkg' not found"),
        (["mbot_navigation", "nothing.py"], "no file 'nothing.py' in package mbot_navigation"),
        (["--clock", "sometimes", "map_server", "map_server", "x.yaml"], "unknown --clock"),
    ],
)
def test_run_bad_targets_are_one_line_exit_2(
    daemon: str, args: list[str], needle: str, capfd: pytest.CaptureFixture[str]
) -> None:
    # in this process, stderr captured at the file descriptor (a process per case costs an
    # import; test_run_map_server_bad_map_is_one_line runs one)
    assert run_main(["run", *args]) == 2
    err = capfd.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], err


def test_run_map_server_bad_map_is_one_line(cli: Any, tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "image: missing.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    r = cli("run", "map_server", "map_server", str(bad))
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1 and "missing.pgm" in r.stderr
    assert os.path.exists(bad)
