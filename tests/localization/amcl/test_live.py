"""The simulator acceptance: mybot in the maze under the amcl node (its defaults), against
``/ground_truth/state`` (harness: ``benchmarks/amcl.py``, which runs the long versions).

Default runs are shorter (a 5-minute drive, three seeds, one kidnapping); the issue's full runs (a
10-minute drive, 10 seeds) are ``slow``.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from benchmarks.amcl import Drive, drive, gmapping_map, map_alignment, world_map

RECOVERY = {"recovery_alpha_slow": 0.001, "recovery_alpha_fast": 0.1}


@pytest.fixture(scope="module")
def maze_maps(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, object]]:
    """The maze rasterised from the world, and the one saved from slam_gmapping (with where
    its frame lies in the world)."""
    world = world_map(tmp_path_factory.mktemp("maze"))
    gmap = gmapping_map()
    return {"world": (world, None), "gmapping": (gmap, map_alignment(gmap))}


def _check_tracking(d: Drive, name: str) -> None:
    med, p95, yaw = d.stats(after=5.0)
    print(f"\n{name}: median {100 * med:.2f} cm, p95 {100 * p95:.2f} cm, yaw {yaw:.2f} deg, "
          f"{d.wall_s:.1f} s wall")  # fmt: skip
    assert med <= 0.03 and p95 <= 0.08 and yaw <= 1.0


@pytest.mark.parametrize("name", ["world", "gmapping"])
def test_tracking_accuracy(name: str, maze_maps: dict[str, tuple[Path, object]]) -> None:
    path, frame = maze_maps[name]
    _check_tracking(drive(path, duration_s=300.0, world_t_map=frame), name)  # type: ignore[arg-type]


def _global(maze_maps: dict[str, tuple[Path, object]], seeds: range) -> list[float | None]:
    path, _ = maze_maps["world"]
    return [drive(path, duration_s=80.0, seed=s, global_start=True).converged_at() for s in seeds]


def test_global_localization_converges(maze_maps: dict[str, tuple[Path, object]]) -> None:
    times = _global(maze_maps, range(3))
    print(f"\nconverged after {times} s")
    assert all(t is not None and t <= 60.0 for t in times)


def _kidnap(maze_maps: dict[str, tuple[Path, object]], seed: int) -> float | None:
    path, _ = maze_maps["world"]
    d = drive(path, duration_s=110.0, seed=seed, kidnap_at_s=40.0, encoder_odometry=True,
              params=RECOVERY)  # fmt: skip
    before = d.position_error[(d.times > 10.0) & (d.times < 40.0)]
    assert before.max() < 0.15  # tracking before the teleport (encoder odometry, slip)
    t = d.converged_at(after=40.0)
    return None if t is None else t - 40.0


def test_kidnapping_is_recovered(maze_maps: dict[str, tuple[Path, object]]) -> None:
    t = _kidnap(maze_maps, 0)
    print(f"\nrecovered {t} s after the teleport")
    assert t is not None and t <= 60.0


@pytest.mark.slow
@pytest.mark.parametrize("name", ["world", "gmapping"])
def test_ten_minute_drive(name: str, maze_maps: dict[str, tuple[Path, object]]) -> None:
    path, frame = maze_maps[name]
    _check_tracking(drive(path, duration_s=600.0, world_t_map=frame), name)  # type: ignore[arg-type]


@pytest.mark.slow
def test_global_localization_ten_seeds(maze_maps: dict[str, tuple[Path, object]]) -> None:
    times = _global(maze_maps, range(10))
    assert sum(t is not None and t <= 60.0 for t in times) >= 9, times


@pytest.mark.slow
def test_kidnapping_five_seeds(maze_maps: dict[str, tuple[Path, object]]) -> None:
    times = [_kidnap(maze_maps, s) for s in range(5)]
    assert all(t is not None and t <= 60.0 for t in times), times
