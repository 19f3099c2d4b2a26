"""SLAM accuracy on the real logs, the way ``roverlab slam run`` maps them.

Each method maps a whole Radish log with its shipped defaults (the log read as ``slam run``
reads it: CARMEN odometry repaired where it counted reversing as driving forward) and is
scored with the Kuemmerle metric over every relation of the log. The limits are
independent references, not figures this code once gave: the published results in
``shared/data/README.md`` (Kuemmerle et al. 2009; Hess et al. 2016 for Cartographer) and
the target of issue 17 for gmapping on fr079.

One full-log run per method and log (on the 2-core machine, nearly quiet: hector 7 s,
graph 68 s, gmapping ~75 s for both logs), and the stretch of mit-csail where its odometry
reports a turn late; the ``--no-smooth`` variants are ``slow``. Without ``shared/data`` the
tests skip and say where they looked.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest

from roverlab.cli.slam_run import MethodResult, run_gmapping, run_graph, run_hector
from roverlab.slam.data import LaserLog, Metrics, Trajectory, evaluate, load_log, read_relations
from roverlab.slam.data.reversing import ReversingRepair
from roverlab.slam.data.straightness import STRAIGHT_CORRIDORS, straightness

#: ``../shared/data/radish`` relative to the repository root (never copied into it).
RADISH = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "radish"

# Published translational errors (m) from shared/data/README.md.
GRAPH_MAPPING = {"intel": 0.031, "fr079": 0.056}  # Kuemmerle et al. 2009, graph mapping
CARTOGRAPHER = {"intel": 0.0229, "fr079": 0.0452}  # Hess et al. 2016
RBPF = {"intel": 0.070, "fr079": 0.061}  # Kuemmerle et al. 2009, RBPF (gmapping)
#: issue 17's target for gmapping (30 particles) on fr079.
GMAPPING_FR079_TARGET = 0.060


def _path(name: str) -> Path:
    path = RADISH / name
    if not path.is_file():
        pytest.skip(f"shared benchmark data not found at {path} (see shared/data/README.md)")
    return path


_LOGS: dict[str, LaserLog] = {}


def _log(name: str) -> LaserLog:
    """The log as ``slam run`` reads it (odometry repaired), read once per session."""
    if name not in _LOGS:
        _LOGS[name] = load_log(_path(f"{name}.clf.bz2"), reversing=ReversingRepair())
    return _LOGS[name]


def _score(name: str, log: LaserLog, result: MethodResult) -> Metrics:
    relations = read_relations(_path(f"{name}.relations"))
    traj = Trajectory.from_poses(list(log.timestamp_texts), result.poses)
    metrics = evaluate(traj, relations)
    assert metrics.matched == len(relations)
    return metrics


@pytest.mark.parametrize("name", ["intel", "fr079"])
def test_graph_full_log_beats_cartographer(name: str) -> None:
    """Deterministic (no random draws): at or below Cartographer's published figure."""
    log = _log(name)
    start = time.perf_counter()
    result = run_graph(log, {})
    wall = time.perf_counter() - start
    metrics = _score(name, log, result)
    print(f"\ngraph {name}: {log.duration_s / wall:.0f}x real time\n{metrics}")
    assert metrics.trans_mean <= CARTOGRAPHER[name], str(metrics)


@pytest.mark.parametrize("name", ["intel", "fr079"])
def test_hector_full_log_matches_published_graph_mapping(name: str) -> None:
    """hector as ``slam run`` runs it (the log's odometry as start estimate, no loop
    closure) with the map sized from the log: within the published graph-mapping error
    (plain scan matching: 0.22 / 0.26). Issue 30: no worse than pure scan matching was
    (0.0169 / 0.0335); measured 0.0161 / 0.0333."""
    log = _log(name)
    start = time.perf_counter()
    result = run_hector(log, {})
    wall = time.perf_counter() - start
    metrics = _score(name, log, result)
    print(f"\nhector {name}: {log.duration_s / wall:.0f}x real time\n{metrics}")
    assert metrics.trans_mean <= GRAPH_MAPPING[name], str(metrics)


#: mit-csail's first 1,100 scans: the late-reported turn (scan ~320) and eight of the
#: corridor stretches of :data:`STRAIGHT_CORRIDORS`, the last three (991-1065) after the
#: junction where a bent map turns (graph SLAM with a 0.05 m smear: by 15 degrees). (At
#: 1,000 scans graph SLAM's shipped map is still bent by 13 degrees; the next 100 scans,
#: back in the long corridor, straighten it to 4.7.)
_MIT_SCANS = 1100
#: Three independent methods map the stretches within 5 degrees of one another.
BEND_TOLERANCE_DEG = 8.0


def _mit_bend(result: MethodResult) -> float:
    log = _log("mit-csail")
    stretches = [s for s in STRAIGHT_CORRIDORS["mit-csail"] if s[1] < _MIT_SCANS]
    return straightness(log, result.poses, stretches).bend_deg


def test_graph_follows_a_turn_mit_csails_odometry_reports_late_and_keeps_it_straight() -> None:
    """mit-csail has no relations; its odometry stalls for four scans around scan 320 while
    the robot turns and then reports 50 degrees at once. The reference is the odometry's
    own heading change over the 20 s from scan 300 to 400 (it catches up, so only its slow
    drift remains: hector and gmapping differ from it by 3-5 degrees); a map bent at that
    turn differed by 16 degrees. Its long corridor and those crossing it stay at one
    heading (modulo 90 degrees) within the tolerance."""
    log = _log("mit-csail")[:_MIT_SCANS]
    result = run_graph(log, {})
    odom = log.odom_poses
    turn = result.poses[399, 2] - result.poses[300, 2] - (odom[399, 2] - odom[300, 2])
    assert abs(math.degrees(math.remainder(turn, 2 * math.pi))) < 8.0
    assert _mit_bend(result) < BEND_TOLERANCE_DEG


def test_hector_with_mit_csails_odometry_keeps_the_corridors_straight() -> None:
    """Issue 30: with the odometry as start estimate, the turn mit-csail's odometry reports
    late started hector's matches 50 degrees off and bent the map by 17 degrees (at 1,100
    scans; 42 on the whole log); a second match from the scan-only prediction, taken when
    it fits the map better, keeps it straight (4.3 degrees; pure hector, whole log: 4.8)."""
    assert _mit_bend(run_hector(_log("mit-csail")[:_MIT_SCANS], {})) < BEND_TOLERANCE_DEG


@pytest.mark.slow
def test_the_straightness_check_catches_the_bent_mit_csail_map() -> None:
    """docs/slam.md's leave-one-out: graph SLAM with a 0.05 m smear (the choice of intel
    and fr079) bends mit-csail's map; the check must say so (measured: 15 degrees)."""
    log = _log("mit-csail")[:_MIT_SCANS]
    result = run_graph(log, {"correlation_search_space_smear_deviation": 0.05})
    assert _mit_bend(result) > BEND_TOLERANCE_DEG


def test_gmapping_fr079_seed_0_meets_the_target() -> None:
    """30 particles (gmapping's default), seed 0, smoothed between updates."""
    log = _log("fr079")
    result = run_gmapping(log, {}, seed=0, smooth=True)
    metrics = _score("fr079", log, result)
    print(f"\ngmapping fr079 seed 0\n{metrics}")
    assert metrics.trans_mean <= GMAPPING_FR079_TARGET, str(metrics)


def test_gmapping_intel_seed_0_within_published_rbpf() -> None:
    """30 particles, seed 0, smoothed: at or below the published RBPF figure."""
    log = _log("intel")
    result = run_gmapping(log, {}, seed=0, smooth=True)
    metrics = _score("intel", log, result)
    print(f"\ngmapping intel seed 0\n{metrics}")
    assert metrics.trans_mean <= RBPF["intel"], str(metrics)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "smooth", "limit"),
    [
        ("intel", False, RBPF["intel"]),
        pytest.param(
            "fr079",
            False,
            RBPF["fr079"],
            marks=pytest.mark.xfail(
                strict=True, reason="--no-smooth scores 0.068 m on fr079 (2026-11-25)"
            ),
        ),
    ],
)
def test_gmapping_full_log_within_published_rbpf(name: str, smooth: bool, limit: float) -> None:
    """The other gmapping variants: the published RBPF figure (``--no-smooth`` is what a
    live node reports)."""
    log = _log(name)
    result = run_gmapping(log, {}, seed=0, smooth=smooth)
    metrics = _score(name, log, result)
    assert metrics.trans_mean <= limit, str(metrics)
