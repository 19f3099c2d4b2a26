"""run_explore: one seeded exploration episode of seed 003's maze (gmapping + move_base +
explore_lite), scored against the world, and the same figures again with the same seed."""

from __future__ import annotations

import gc
import json
import math
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numba
import numpy as np
import pytest

from roverlab.autonomy.explore_run import ExploreEpisode, run_explore, write_explore_outputs
from roverlab.autonomy.stack import AutonomyError
from roverlab.maps import load_map


@pytest.fixture(scope="module")
def episodes() -> tuple[ExploreEpisode, ExploreEpisode]:
    first = run_explore(world="maze", slam="gmapping", seed=3, duration_s=300.0)
    again = run_explore(world="maze", slam="gmapping", seed=3, duration_s=300.0)
    return first, again


def test_the_maze_is_mapped_without_touching_a_wall(episodes: tuple[ExploreEpisode, ...]) -> None:
    r = episodes[0].result
    assert r.finished and r.reason == "no frontier left"
    assert r.coverage >= 0.95, r.summary()
    assert r.accuracy >= 0.95, r.summary()
    assert r.contacts == 0 and episodes[0].monitor.contact_events == []
    assert r.time_to_95_s <= r.sim_s <= 300.0
    # the maze's 25 cells of 1.6 m, walls excluded, are about 56 m^2 reachable
    assert 50.0 <= r.reachable_m2 <= 60.0
    assert r.explored_m2 >= r.coverage * r.reachable_m2
    assert r.goals_sent >= 5 and r.distance_m > 10.0
    # the coverage series grows to the final figure
    fractions = [s.fraction for s in episodes[0].monitor.coverage]
    assert fractions[0] < 0.5 and max(fractions) == pytest.approx(r.coverage, abs=1e-4)


def test_the_same_seed_gives_the_same_episode(episodes: tuple[ExploreEpisode, ...]) -> None:
    a, b = (e.result.to_dict() for e in episodes)
    a.pop("wall_s"), b.pop("wall_s")
    assert a == b
    np.testing.assert_array_equal(episodes[0].monitor.world_path, episodes[1].monitor.world_path)
    np.testing.assert_array_equal(
        np.asarray(episodes[0].map_msg.data), np.asarray(episodes[1].map_msg.data)
    )


@contextmanager
def _thread_timing_shaken() -> Iterator[None]:
    """A thread that holds the GIL as much as it can, a thread switch every 10 us, a garbage
    collection every 100 allocations and one numba thread instead of the machine's: what a
    loaded machine (or a test process with threads left over) changes in a run."""
    stop = threading.Event()

    def busy() -> None:
        while not stop.is_set():
            _ = [object() for _ in range(100)]

    switch, threshold = sys.getswitchinterval(), gc.get_threshold()
    threads = numba.get_num_threads()
    thread = threading.Thread(target=busy, daemon=True)
    sys.setswitchinterval(1e-5)
    gc.set_threshold(100)
    numba.set_num_threads(1)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()
        sys.setswitchinterval(switch)
        gc.set_threshold(*threshold)
        numba.set_num_threads(threads)


def test_thread_timing_does_not_steer_a_seeded_episode(
    episodes: tuple[ExploreEpisode, ...],
) -> None:
    # the first 15 s of the same seed, run while threads and the collector are shaken, are
    # the first 15 s of the episode run undisturbed (the last sample repeats t = 15 s)
    with _thread_timing_shaken():
        short = run_explore(world="maze", slam="gmapping", seed=3, duration_s=15.0)
    path = short.monitor.world_path
    assert len(path) > 100
    np.testing.assert_array_equal(path[:-1], episodes[0].monitor.world_path[: len(path) - 1])


def test_outputs_are_the_map_the_plots_and_the_summary(
    episodes: tuple[ExploreEpisode, ...], tmp_path: Path
) -> None:
    written = write_explore_outputs(episodes[0], tmp_path / "out")
    names = sorted(p.name for p in written)
    assert names == ["coverage.png", "map.pgm", "map.png", "map.yaml", "summary.json"]
    assert not list((tmp_path / "out").glob("*.part"))
    saved = load_map(tmp_path / "out" / "map.yaml")
    msg = episodes[0].map_msg
    np.testing.assert_array_equal(
        np.asarray(saved.data) >= 0, np.asarray(msg.data).reshape(saved.data.shape) >= 0
    )
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["coverage"] == episodes[0].result.coverage
    assert summary["contacts"] == 0 and summary["world"] == "maze"
    series = summary["coverage_series"]
    assert len(series) == len(episodes[0].monitor.coverage) and series[-1][2] <= 1.0


def test_a_time_limit_ends_the_episode_early() -> None:
    r = run_explore(world="maze", slam="graph", seed=0, duration_s=15.0).result
    assert not r.finished and r.reason == "time limit"
    assert 15.0 <= r.sim_s < 16.0 and 0.0 < r.coverage < 0.95
    assert not math.isnan(r.accuracy)


def test_an_unknown_slam_method_is_one_clear_error() -> None:
    with pytest.raises(AutonomyError, match="unknown SLAM method 'karto'"):
        run_explore(world="maze", slam="karto", duration_s=5.0)
