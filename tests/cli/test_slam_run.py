"""``roverlab slam run`` on a slice of a real benchmark log, then ``slam eval``."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.cli.test_amcl_run import _reversing_log, _translational_error

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "radish"


@pytest.mark.skipif(not (DATA / "intel.clf.bz2").is_file(), reason="shared/data/radish is absent")
def test_hector_on_an_intel_slice_writes_map_trajectory_and_scores(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(DATA / "intel.clf.bz2"),
         "--method", "hector", "--first", "1500", "--param", "map_size:=2048", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    for name in ("map.yaml", "map.pgm", "map.png", "trajectory.tum"):
        assert (out / name).is_file()
    lines = (out / "trajectory.tum").read_text().splitlines()
    assert len(lines) == 1500 and lines[0].split()[0] == "976052857.337530"
    trans = _translational_error(out / "trajectory.tum", DATA / "intel.relations", capfd)
    assert trans < 0.05  # the slice's relations (the full log scores 0.021 m)


def test_unknown_method_is_one_line_exit_2(tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(tmp_path / "x.clf"),
         "--method", "karto"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 2
    assert r.stderr.strip() == "error: unknown method 'karto' (hector, gmapping or graph)"


@pytest.mark.skipif(not (DATA / "intel.clf.bz2").is_file(), reason="shared/data/radish is absent")
def test_gmapping_on_an_intel_slice_is_seeded_and_scores(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    def run(out: Path, seed: int) -> str:
        r = subprocess.run(
            [sys.executable, "-m", "roverlab.cli", "slam", "run", str(DATA / "intel.clf.bz2"),
             "--method", "gmapping", "--first", "700", "--seed", str(seed), "--out", str(out)],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        assert "gmapping: " in r.stderr and "filter updates" in r.stderr
        return (out / "trajectory.tum").read_text()

    a = run(tmp_path / "a", 3)
    assert a == run(tmp_path / "b", 3)  # same seed, same trajectory
    lines = a.splitlines()
    assert len(lines) == 700 and lines[0].split()[0] == "976052857.337530"
    assert (tmp_path / "a" / "map.pgm").is_file() and (tmp_path / "a" / "map.png").is_file()
    trans = _translational_error(tmp_path / "a" / "trajectory.tum", DATA / "intel.relations", capfd)
    assert trans < 0.08


def test_hector_map_is_sized_to_the_odometry_unless_set() -> None:
    from roverlab.cli.slam_run import hector_auto_size
    from roverlab.geometry import SE2
    from roverlab.slam.data.logs import LaserLog, ScanRecord

    recs = [
        ScanRecord(timestamp=float(i), ranges=np.ones(10, np.float32), angle_min=-1.0,
                   angle_increment=0.2, range_min=0.0, range_max=30.0,
                   odom_pose=SE2(10.0 + x, 5.0, math.pi / 2))
        for i, x in enumerate([0.0, -20.0, -40.0])
    ]  # fmt: skip
    log = LaserLog(recs)
    sized = hector_auto_size(log, {})
    # in the first pose's frame (facing +y) the robot moves 40 m along +y
    size_m = float(sized["map_size"]) * 0.025  # type: ignore[arg-type]
    assert size_m >= 40.0 + 2 * (5.0 + 0.15 * 40.0)
    assert int(sized["map_size"]) % 256 == 0  # type: ignore[call-overload]
    # the box (x 0..0, y 0..40) is centred in the map
    assert float(sized["map_start_y"]) * size_m == pytest.approx(size_m / 2 - 20.0)  # type: ignore[arg-type]
    assert float(sized["map_start_x"]) == pytest.approx(0.5)  # type: ignore[arg-type]
    given = {"map_size": 512}
    assert hector_auto_size(log, given) is given


def test_hector_grows_its_map_when_the_log_has_no_odometry() -> None:
    # a log without odometry (a hand-held lidar): the first pass sees no motion, the
    # default map (25.6 m) is too small for a 40 m corridor, and hector grows it
    from roverlab.cli.slam_run import run_hector
    from roverlab.geometry import SE2
    from roverlab.raycast import Scene, cast_2d
    from roverlab.slam.data.logs import LaserLog, ScanRecord

    box = [[-2.0, -1.0, 42.0, -1.0], [-2.0, 1.0, 42.0, 1.0], [-2.0, -1.0, -2.0, 1.0],
           [42.0, -1.0, 42.0, 1.0]]  # fmt: skip
    walls = np.array(box + [[x, -1.0, x, -0.7] for x in range(0, 41, 3)])  # posts: features
    scene = Scene(segments=walls)
    beams = np.radians(np.linspace(-135.0, 135.0, 541))
    rng = np.random.default_rng(1)
    xs = np.arange(0.0, 40.0, 0.1)
    recs = [
        ScanRecord(timestamp=float(i), angle_min=float(beams[0]),
                   angle_increment=float(beams[1] - beams[0]), range_min=0.0, range_max=30.0,
                   ranges=(cast_2d(scene, x, 0.0, 0.5, beams, 30.0)
                           + rng.normal(0.0, 0.01, beams.size)).astype(np.float32),
                   odom_pose=SE2(0.0, 0.0, 0.0))
        for i, x in enumerate(xs)
    ]  # fmt: skip
    res = run_hector(LaserLog(recs), {})
    assert any("grown to 4096 cells" in n for n in res.notes), res.notes
    end = np.asarray(res.poses)[-1]
    assert end[0] == pytest.approx(xs[-1], abs=0.3) and abs(end[1]) < 0.25


@pytest.mark.skipif(not (DATA / "intel.clf.bz2").is_file(), reason="shared/data/radish is absent")
def test_graph_on_an_intel_slice_scores(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "g"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(DATA / "intel.clf.bz2"),
         "--method", "graph", "--first", "1000", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "graph: " in r.stderr and "keyframes" in r.stderr
    assert len((out / "trajectory.tum").read_text().splitlines()) == 1000
    assert _translational_error(out / "trajectory.tum", DATA / "intel.relations", capfd) < 0.05


def test_graph_parameter_errors_come_before_reading_the_log(tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "slam", "run", str(tmp_path / "absent.clf"),
         "--method", "graph", "--param", "no_such_thing:=1"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 2
    assert "no_such_thing" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_graph_node_settings_are_named_as_ignored_offline() -> None:
    from roverlab.cli.slam_run import run_graph
    from roverlab.geometry import SE2
    from roverlab.slam.data.logs import LaserLog, ScanRecord

    beams = np.linspace(-1.5, 1.5, 181)
    recs = [
        ScanRecord(timestamp=float(i), ranges=np.full(beams.size, 3.0, np.float32),
                   angle_min=float(beams[0]), angle_increment=float(beams[1] - beams[0]),
                   range_min=0.0, range_max=30.0, odom_pose=SE2(0.1 * i, 0.0, 0.0))
        for i in range(3)
    ]  # fmt: skip
    params = {"minimum_time_interval": 0.5, "use_scan_barycenter": True, "mode": "mapping",
              "resolution": 0.05}  # fmt: skip
    notes = run_graph(LaserLog(recs), params).notes
    assert notes[-1] == (
        "warning: slam_toolbox node parameters have no effect on an offline run (ignored): "
        "minimum_time_interval, mode, use_scan_barycenter"
    )
    assert not any("ignored" in n for n in run_graph(LaserLog(recs), {"resolution": 0.05}).notes)


@pytest.mark.parametrize("method", ["hector", "gmapping", "graph"])
def test_a_simulator_recording_maps_the_maze(tmp_path: Path, method: str) -> None:
    """A recording of ``roverlab sim`` (odometry from TF) -> ``slam run`` -> ``slam mapeval``."""
    from roverlab.bag import BagRecorder
    from roverlab.core import Context
    from roverlab.msgs import Twist
    from roverlab.sim.app import Simulation

    rec = tmp_path / "sim.mcap"
    context = Context(clock="sim")
    context.add_transport(BagRecorder(rec))
    Simulation(context=context, world="maze", robot="mybot", cameras=False)
    driver = context.create_node("driver")
    pub = driver.create_publisher(Twist, "/cmd_vel", 10)
    driver.create_timer(0.1, lambda: pub.publish(Twist(linear_x=0.05, angular_z=0.6)))
    context.spin_for(15.0)
    context.shutdown()

    out = tmp_path / method
    cli = [sys.executable, "-m", "roverlab.cli", "slam"]
    r = subprocess.run(
        [*cli, "run", str(rec), "--method", method, "--odom-topic", "", "--out", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert len((out / "trajectory.tum").read_text().splitlines()) >= 100  # 7 Hz x 15 s
    e = subprocess.run(
        [*cli, "mapeval", str(out / "map.yaml"), "--world", "maze", "--min-accuracy", "0.95"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert e.returncode == 0, e.stdout + e.stderr


def test_slam_run_repairs_odometry_logged_forward_while_reversing(tmp_path: Path) -> None:
    """As ``amcl run``: a CARMEN log's steps that went forward while ``tv`` < 0 are reversed
    (the graph without scan matching follows the odometry, so its trajectory shows it)."""
    log = _reversing_log(tmp_path / "rev.clf")

    def run(out: str, *extra: str) -> tuple[str, np.ndarray]:
        r = subprocess.run(
            [sys.executable, "-m", "roverlab.cli", "slam", "run", str(log), "--method", "graph",
             "--param", "use_scan_matching:=false", "--out", str(tmp_path / out), *extra],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
        assert r.returncode == 0, r.stderr
        return r.stderr, np.loadtxt(tmp_path / out / "trajectory.tum")

    err, fixed = run("a")
    assert "odometry: 10 of 29 steps moved forward while the velocity was negative" in err
    raw_err, logged = run("b", "--logged-odometry")
    assert "odometry:" not in raw_err
    # 30 steps of 3 cm: as logged all forward (0.87 m), repaired 19 forward and 10 back
    assert logged[-1, 1] - logged[0, 1] == pytest.approx(0.87, abs=1e-6)
    assert fixed[-1, 1] - fixed[0, 1] == pytest.approx(0.27, abs=1e-6)
