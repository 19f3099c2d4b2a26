"""Batch runs: the same per-episode results serially and on Ray, outputs, errors."""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from roverlab.autonomy.explore_batch import explore_episode
from roverlab.autonomy.explore_run import run_explore
from roverlab.batch import BatchError, Episode, aggregate, estimate_hours, run_batch
from tests.helpers.nodes import run_main

CONFIG: dict[str, Any] = {
    "world": "maze", "robot": "mybot", "slam": "gmapping", "duration_s": 8.0,
    "spawn": [0.0, 0.0, 0.0],
}  # fmt: skip


def _without_wall(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]


def _explore_cli(out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "roverlab.cli", *_explore_args(out), *extra],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip


def _explore_args(out: Path) -> list[str]:
    return ["explore", "--duration", "8", "--episodes", "3", "--seed", "2", "--out", str(out)]


@pytest.fixture(scope="module")
def serial_batch(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``roverlab explore --episodes 3 --seed 2`` (serial): seeds 2, 3, 4. Run once for the
    module, through the entry point in this process (a process would only add an import):
    the single-run and the Ray tests both compare with it."""
    out = tmp_path_factory.mktemp("serial")
    assert run_main(_explore_args(out)) == 0
    return out


def test_episode_i_is_the_single_run_with_seed_s_plus_i(serial_batch: Path) -> None:
    rows = json.loads((serial_batch / "episodes.json").read_text())["episodes"]
    assert [r["seed"] for r in rows] == [2, 3, 4] and [r["episode"] for r in rows] == [0, 1, 2]
    single = run_explore(world="maze", slam="gmapping", seed=3, duration_s=8.0).result.to_dict()
    single.pop("wall_s")
    row = {k: v for k, v in rows[1].items() if k not in ("wall_s", "episode")}
    assert row == single
    assert rows[0]["distance_m"] > 0.5  # the robot explored
    files = {p.name for p in (serial_batch / "episode_000").iterdir()}
    assert {"map.png", "map.yaml", "map.pgm", "coverage.png", "summary.json"} <= files


def test_a_failing_episode_is_a_row_with_its_error_and_the_batch_goes_on() -> None:
    config = {**CONFIG, "world": "/nonexistent/x.world"}
    done = run_batch(explore_episode, config, episodes=2, seed=0)
    assert len(done) == 2
    assert all("x.world" in e.row["error"] and "\n" not in e.row["error"] for e in done)
    assert aggregate([e.row for e in done])["errors"] == 2


def test_bad_batch_arguments() -> None:
    with pytest.raises(BatchError, match="--episodes must be at least 1"):
        run_batch(explore_episode, CONFIG, episodes=0)
    with pytest.raises(BatchError, match="--workers must be at least 1"):
        run_batch(explore_episode, CONFIG, episodes=1, workers=0)
    with pytest.raises(BatchError, match="module level"):
        run_batch(lambda c, s: Episode(row={}), CONFIG, episodes=1)


def test_missing_ray_is_one_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray -> ImportError
    with pytest.raises(BatchError, match=r"pip install 'roverlab\[ray\]'"):
        run_batch(explore_episode, CONFIG, episodes=2, workers=2)


def test_aggregate_and_estimate() -> None:
    rows = [
        {"episode": 0, "seed": 0, "coverage": 0.5, "finished": True, "wall_s": 10.0},
        {"episode": 1, "seed": 1, "coverage": 1.0, "finished": False, "wall_s": 30.0},
        {"episode": 2, "seed": 2, "coverage": None, "error": "X: y", "wall_s": 2.0},
    ]
    agg = aggregate(rows)
    assert agg["episodes"] == 3 and agg["errors"] == 1
    assert agg["coverage"] == {"mean": 0.75, "std": 0.25, "median": 0.75, "min": 0.5,
                               "max": 1.0, "n": 2}  # fmt: skip
    assert agg["finished"] == {"share": 0.5, "n": 2}
    # 14 s per episode on average: 10,000 episodes on 4 cores = 2,500 rounds
    assert estimate_hours(rows, 10_000, 4) == pytest.approx(14.0 * 2500 / 3600)
    assert math.isnan(estimate_hours([], 10, 1))


def test_cli_serial_and_ray_give_the_same_episodes(serial_batch: Path, tmp_path: Path) -> None:
    pytest.importorskip("ray", reason="the 'ray' extra is not installed")
    parallel = _explore_cli(tmp_path / "ray", "--workers", "2")
    assert parallel.returncode == 0, parallel.stderr
    assert "batch: 3/3 episodes" in parallel.stdout and "2 worker(s), 0 failed" in parallel.stdout
    a = json.loads((serial_batch / "episodes.json").read_text())
    b = json.loads((tmp_path / "ray" / "episodes.json").read_text())
    assert [r["seed"] for r in b["episodes"]] == [2, 3, 4]
    assert _without_wall(a["episodes"]) == _without_wall(b["episodes"])
    assert a["aggregate"]["coverage"] == b["aggregate"]["coverage"]
    assert b["workers"] == 2 and b["estimate_10000_episodes_hours"]["16 cores"] > 0
    with (tmp_path / "ray" / "episodes.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [int(r["seed"]) for r in rows] == [2, 3, 4] and "coverage" in rows[0]
    for i in range(3):
        assert (tmp_path / "ray" / f"episode_{i:03d}" / "map.png").stat().st_size > 1000
    assert (tmp_path / "ray" / "episodes.png").stat().st_size > 1000


def test_cli_refuses_a_paced_batch(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    assert run_main([*_explore_args(tmp_path), "--rate", "2"]) == 2
    err = capfd.readouterr().err
    assert err.strip().splitlines()[-1].endswith("--episodes/--workers run at --rate max only")


def test_nav_bench_episodes_are_its_single_runs(tmp_path: Path) -> None:
    args = ["nav", "bench", "--world", "maze", "--goals", "1", "--seed", "3", "--quiet"]
    batch = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", *args, "--episodes", "2", "--out",
         str(tmp_path / "b")], capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert batch.returncode == 0, batch.stderr
    rows = json.loads((tmp_path / "b" / "episodes.json").read_text())["episodes"]
    assert [r["seed"] for r in rows] == [3, 4] and all(r["goals"] == 1 for r in rows)
    # the single run through the entry point in this process (a process adds an import)
    assert run_main([*args[:-3], "--seed", "4", "--out", str(tmp_path / "s")]) == 0
    one = json.loads((tmp_path / "s" / "bench.json").read_text())
    timing = ("wall", "_ms", "map", "machine")
    assert {k: v for k, v in one.items() if k in rows[1] and not any(t in k for t in timing)} == {
        k: v for k, v in rows[1].items() if k in one and not any(t in k for t in timing)
    }
    assert (tmp_path / "b" / "episode_001" / "bench.json").is_file()
