"""``roverlab nav bench``: the grid's shortest paths and seeded goals, the report's
figures and files, bad input, and live episodes of the whole stack (seeded: the same
results twice)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.navbench import (
    TIMING_KEYS,
    BenchConfig,
    BenchError,
    BenchGrid,
    BenchReport,
    GoalRecord,
    GoalSamplingError,
    run_episode,
    sample_goals,
)
from tests.helpers.nodes import run_main

RES = 0.05


def _room(wall_gap: bool = True) -> BenchGrid:
    """A 4 x 3 m free room (80 x 60 cells), walled, with a wall at x = 2 m from the floor
    up to y = 2 m (a gap above it) or to the ceiling."""
    costs = np.zeros((60, 80), dtype=np.uint8)
    costs[0, :] = costs[-1, :] = costs[:, 0] = costs[:, -1] = 254
    costs[: 40 if wall_gap else 60, 40] = 254
    return BenchGrid(costs, RES, (0.0, 0.0))


def test_shortest_path_goes_around_the_wall_by_line_of_sight() -> None:
    g = _room()
    a, b = g.centre(10, 30), g.centre(10, 50)  # (1.525, 0.525) and (2.525, 0.525)
    corner = g.centre(40, 40)  # the wall's end; the path passes beside it
    around = math.dist(a, corner) + math.dist(corner, b)
    d = g.shortest_path(a, b)
    assert around * 0.97 < d < around * 1.03
    # in the open: the straight line (cell centres)
    assert g.shortest_path(g.centre(50, 5), g.centre(50, 35)) == pytest.approx(1.5, abs=1e-9)
    assert math.isinf(_room(wall_gap=False).shortest_path(a, b))
    reach = _room(wall_gap=False).reachable(*a)
    assert reach[10, 30] and not reach[10, 50]


def test_goals_are_seeded_reachable_clear_and_apart() -> None:
    g = _room()
    spawn = g.centre(10, 10)
    goals = sample_goals(g, spawn, 30, np.random.default_rng(4), clearance=0.25)
    again = sample_goals(g, spawn, 30, np.random.default_rng(4), clearance=0.25)
    assert np.array_equal(goals, again)
    assert not np.array_equal(goals, sample_goals(g, spawn, 30, np.random.default_rng(5),
                                                  clearance=0.25))  # fmt: skip
    pts = np.vstack([spawn, goals[:, :2]])
    assert (np.hypot(*np.diff(pts, axis=0).T) >= 2.0).all()
    for x, y, yaw in goals:
        r, c = g.cell(x, y) or (-1, -1)
        assert g.clearance[r, c] >= 0.25 and -math.pi <= yaw <= math.pi
    assert (goals[:, 0] > 2.0).any() and (goals[:, 0] < 2.0).any()  # both halves
    with pytest.raises(GoalSamplingError, match=r"0\.50 m clearance"):
        boxed = np.full((20, 20), 254, dtype=np.uint8)
        boxed[5:15, 5:15] = 0
        sample_goals(BenchGrid(boxed, RES, (0.0, 0.0)), (0.5, 0.5), 1,
                     np.random.default_rng(0), clearance=0.5)  # fmt: skip


def _record(i: int, ok: bool, driven: float, shortest: float, t: float) -> GoalRecord:
    path = np.array([[0.5, 0.5], [0.5 + driven, 0.5]])
    return GoalRecord(
        index=i, start=(0.5, 0.5, 0.0), goal=(0.5 + shortest, 0.5, 0.0),
        status="SUCCEEDED" if ok else "ABORTED", text="" if ok else "Failed to find a valid plan.",
        succeeded=ok, time_s=t, driven_m=driven, shortest_m=shortest, end=(0.5 + driven, 0.5, 0.0),
        error_m=0.0, yaw_error=0.0, contacts=0, contact_points=[], planner_calls=3,
        controller_calls=10, failures={}, recoveries=0, path=path,
    )  # fmt: skip


class _Timings:
    plan_cpu = [0.001] * 99 + [0.010]
    plan_wall = [0.002] * 100
    control_cpu = [0.003] * 100
    control_wall = [0.004] * 100


def test_report_figures_json_and_picture(tmp_path: Path) -> None:
    rep = BenchReport(config=BenchConfig(world="maze", out=tmp_path), map_yaml=tmp_path / "m.yaml",
                      grid=_room(), local_planner="dwa_local_planner/DWAPlannerROS")  # fmt: skip
    rep.add(_record(0, True, 1.1, 1.0, 10.0))
    rep.add(_record(1, True, 1.3, 1.0, 30.0))
    rep.add(_record(2, False, 3.0, 1.0, 99.0))  # failures count in neither median
    rep.set_totals(timings=_Timings(), collisions=0, sim_time_s=139.0, wall_time_s=20.0)
    assert rep.succeeded == 2 and rep.success_rate == pytest.approx(2 / 3)
    assert rep.path_ratio_median == pytest.approx(1.2)
    assert rep.time_per_goal_median_s == pytest.approx(20.0)
    assert rep.planner_ms_p99 == pytest.approx(np.percentile(_Timings.plan_cpu, 99) * 1000)
    assert rep.controller_ms_p99 == pytest.approx(3.0)
    rep.write_json(tmp_path / "bench.json")
    data = json.loads((tmp_path / "bench.json").read_text())
    for key in ("goals", "succeeded", "collisions", "path_ratio_median",
                "time_per_goal_median_s", "planner_ms_p99", "controller_ms_p99"):  # fmt: skip
        assert key in data
    assert data["goals"] == 3 and data["succeeded"] == 2 and len(data["records"]) == 3
    assert data["records"][2]["text"] == "Failed to find a valid plan."
    assert "2/3 goals (67 %), 0 collisions, path ratio median 1.200" in rep.summary_line()
    rep.write_png(tmp_path / "bench.png")
    img = np.asarray(Image.open(tmp_path / "bench.png").convert("RGB"))
    assert (img == (214, 39, 40)).all(axis=2).any()  # the failure in red
    assert (img == (0, 0, 0)).all(axis=2).any()  # walls
    assert not list(tmp_path.glob(".*"))  # no temporary files left


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--planner", "mpc"], "error: unknown planner 'mpc': use dwa or teb"),
        (["--localization", "gps"], "error: unknown localization 'gps': use amcl or ground_truth"),
        (["--goals", "0"], "error: --goals must be at least 1, got 0"),
        (["--robot", "mbot"], "error: no navigation parameters for robot 'mbot' (bundled: "
                              "mybot); give a folder of robot_navigation parameter files with "
                              "--params"),
        (["--world", "nowhere.world"], "error: nowhere.world"),
    ],
)  # fmt: skip
def test_bad_input_is_one_line_exit_2(
    tmp_path: Path, args: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert run_main(["nav", "bench", "--out", str(tmp_path / "out"), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(message) and "\n" not in err


def _episode(tmp_path: Path, seed: int, planner: str) -> dict[str, object]:
    cfg = BenchConfig(world="maze", out=tmp_path, planner=planner, localization="ground_truth",
                      goals=2)  # fmt: skip
    return run_episode(cfg, seed)


@pytest.mark.parametrize("planner", ["dwa", "teb"])
def test_episode_reaches_seeded_goals_in_the_maze(tmp_path: Path, planner: str) -> None:
    res = _episode(tmp_path, 3, planner)
    assert res["goals"] == 2 and res["succeeded"] == 2 and res["collisions"] == 0, res
    assert res["seed"] == 3 and res["planner"] == planner
    assert 1.0 <= float(res["path_ratio_median"]) <= 1.25  # type: ignore[arg-type]
    assert 0 < float(res["controller_ms_p99"]) < 100  # type: ignore[arg-type]
    out = tmp_path / "seed-0003"
    assert json.loads((out / "bench.json").read_text())["succeeded"] == 2
    assert (out / "bench.png").is_file() and (out / "map.yaml").is_file()
    records = res["records"]
    assert isinstance(records, list)
    for rec in records:
        assert rec["status"] == "SUCCEEDED" and rec["error_m"] <= 0.25
        assert rec["driven_m"] >= rec["shortest_m"] * 0.95 and len(rec["path"]) > 10


@pytest.mark.slow
def test_an_episode_is_a_function_of_its_seed(tmp_path: Path) -> None:
    a = _episode(tmp_path / "a", 1, "dwa")
    b = _episode(tmp_path / "b", 1, "dwa")
    for key in (*TIMING_KEYS, "map"):
        a.pop(key), b.pop(key)
    assert a == b


def test_bench_error_is_a_roverlab_error() -> None:
    with pytest.raises(BenchError, match="--goal-timeout must be > 0 s, got -1"):
        BenchConfig(world="maze", out=Path("x"), goal_timeout_s=-1).validate()
