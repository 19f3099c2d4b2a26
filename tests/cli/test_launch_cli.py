"""``roverlab launch``: the clock a launch runs on, and a SLAM launch beside a simulator."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.cli.launch import choose_clock
from roverlab.launch import LaunchError, load_launch
from tests.helpers.procs import Proc

FIXTURES = Path(__file__).resolve().parents[1] / "slam" / "fixtures"


def _launch(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "x.launch"
    path.write_text(f"<launch>{body}</launch>")
    return path


def test_a_launch_with_a_simulator_runs_its_own_clock(tmp_path: Path) -> None:
    path = _launch(
        tmp_path,
        '<node pkg="gazebo_ros" type="gzserver" name="gazebo" args="worlds/empty.world"/>',
    )
    assert choose_clock(load_launch(path), "auto", 1.0) == ("paced", "")
    assert choose_clock(load_launch(path), "auto", float("inf")) == ("sim", "")


def test_a_launch_without_a_simulator_follows_clock_or_wall_time(tmp_path: Path) -> None:
    mode, note = choose_clock(load_launch(FIXTURES / "gmapping.launch"), "auto", 1.0)
    assert mode == "external" and "/clock" in note
    off = _launch(tmp_path, '<param name="/use_sim_time" value="false"/>')
    assert choose_clock(load_launch(off), "auto", 1.0)[0] == "wall"
    assert choose_clock(load_launch(off), "sim", 1.0) == ("paced", "")
    assert choose_clock(load_launch(off), "external", 1.0) == ("external", "")
    with pytest.raises(LaunchError, match="unknown --clock 'gps'"):
        choose_clock(load_launch(off), "gps", 1.0)


@pytest.mark.zenoh
def test_seed_gmapping_launch_maps_a_simulator_in_another_process(
    daemon: str, tmp_path: Path
) -> None:
    """Seed 000's workflow on three terminals: the simulator, the gmapping launch file,
    a turning command; then map_saver writes the map the launch's node built."""
    cli = [sys.executable, "-m", "roverlab.cli"]
    sim = Proc([*cli, "sim", "--world", "maze", "--robot", "mybot", "--rate", "2",
                "--duration", "60"])  # fmt: skip
    slam = Proc([*cli, "launch", str(FIXTURES / "gmapping.launch"), "--duration", "50"])
    pub = Proc([*cli, "topic", "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist",
                "{angular: {z: 0.6}}"])  # fmt: skip
    try:
        saver = Proc([*cli, "map", "save", "-f", str(tmp_path / "maze"), "--timeout", "90"])
        assert saver.popen.wait(timeout=120) == 0, saver.stop()
    finally:
        pub.stop()
        slam_err = slam.stop()
        sim.stop()
    assert "following /clock from another process" in slam_err
    pgm = Image.open(tmp_path / "maze.pgm")
    img = np.asarray(pgm)
    # map_saver's values: free 254, occupied 0, unknown 205; the robot saw walls around it
    assert (img == 254).sum() > 500 and (img == 0).sum() > 50
    assert (tmp_path / "maze.yaml").read_text().startswith("image: ")
    # and the saved map matches the world (roverlab slam mapeval)
    r = subprocess.run(
        [*cli, "slam", "mapeval", str(tmp_path / "maze.yaml"), "--world", "maze",
         "--min-accuracy", "0.95", "--png", str(tmp_path / "overlay.png")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 0, r.stdout + r.stderr
    assert "known cells correct" in r.stdout and (tmp_path / "overlay.png").is_file()


def test_bundled_mbot_navigation_has_the_seed_launch_files() -> None:
    from roverlab.core import Context
    from roverlab.description import find_package
    from roverlab.launch import build_launch

    pkg = find_package("mbot_navigation")
    demo = load_launch(pkg / "launch" / "gmapping_demo.launch")
    assert [(n.pkg, n.type) for n in demo.nodes] == [
        ("gmapping", "slam_gmapping"),
        ("rviz", "rviz"),
    ]
    assert demo.nodes[1].args.endswith("mbot_navigation/rviz/gmapping.rviz")
    assert (pkg / "rviz" / "gmapping.rviz").is_file()
    for name, node in (("gmapping.launch", "slam_gmapping"), ("hector.launch", "hector_mapping")):
        ctx = Context()
        try:
            started = build_launch(pkg / "launch" / name, context=ctx)
            assert [n.get_name() for n in started.nodes] == [node]
        finally:
            ctx.shutdown()


def test_a_launch_with_driver_nodes_runs_on_wall_time(tmp_path: Path) -> None:
    from roverlab.description import find_package

    for pkg, launch_file in (
        ("roborts_bringup", "launch/Ymap_move_face1.launch"),
        ("urdlee", "launch/car_ee.launch"),
    ):
        mode, note = choose_clock(load_launch(find_package(pkg) / launch_file), "auto", 1.0)
        assert mode == "wall" and "driver nodes" in note


def test_only_nodes_that_run_as_scripts_open_the_script_endpoint(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capfd: pytest.CaptureFixture[str]
) -> None:
    """A node whose type names several files or a compiled one is skipped by the runner, so
    it neither exposes the launch (``--rate max`` stays private) nor opens the socket."""
    from roverlab.cli import launch as launch_cli
    from tests.helpers.nodes import run_main

    pkg = tmp_path / "ws" / "my_pkg"
    for sub in ("scripts", "nodes"):
        (pkg / sub).mkdir(parents=True)
        (pkg / sub / "twice.py").write_text("print('ran')\n")
    (pkg / "package.xml").write_text("<package><name>my_pkg</name></package>")
    (pkg / "nodes" / "driver_node").write_bytes(b"\x7fELF\x02\x01\x01")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    path = _launch(
        tmp_path,
        '<node pkg="my_pkg" type="twice.py" name="a"/>'
        '<node pkg="my_pkg" type="driver_node" name="b"/>',
    )
    asked: list[tuple[bool | None, tuple[str, ...]]] = []

    def expose_if_asked(ctx: object, context: object, expose: bool | None, pace: float, *,
                        also_listen: tuple[str, ...] = ()) -> None:  # fmt: skip
        asked.append((expose, also_listen))

    monkeypatch.setattr(launch_cli, "expose_if_asked", expose_if_asked)
    argv = ["launch", str(path), "--rate", "max", "--clock", "wall", "--duration", "0.05"]
    assert run_main(argv) == 0
    assert asked == [(None, ())]
    err = capfd.readouterr().err
    assert "multiple files named [twice.py]" in err and "driver_node is not a Python" in err


def test_each_script_node_type_is_looked_up_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``roverlab launch`` finds the scripts (to know whether it needs the script endpoint)
    and the runner starts them from that: the package is not walked again per node."""
    from roverlab.launch import process
    from tests.helpers.nodes import run_main

    pkg = tmp_path / "ws" / "my_pkg"
    (pkg / "nodes").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>my_pkg</name></package>")
    (pkg / "nodes" / "driver_node").write_bytes(b"\x7fELF\x02\x01\x01")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ws"))
    path = _launch(
        tmp_path,
        '<node pkg="my_pkg" type="driver_node" name="a"/>'
        '<node pkg="my_pkg" type="driver_node" name="a" ns="r2"/>'
        '<node pkg="my_pkg" type="absent.py" name="c"/>',
    )
    looked_up: list[tuple[str, str]] = []
    find_script = process.find_script

    def counting(pkg: str, type_: str, package_path: tuple[str, ...] = ()) -> Path:
        looked_up.append((pkg, type_))
        return find_script(pkg, type_, package_path)

    monkeypatch.setattr(process, "find_script", counting)
    monkeypatch.setattr("roverlab.launch.runner.find_script", counting)
    argv = ["launch", str(path), "--rate", "max", "--clock", "wall", "--duration", "0.05"]
    assert run_main(argv) == 0
    assert sorted(looked_up) == [("my_pkg", "absent.py"), ("my_pkg", "driver_node")]
