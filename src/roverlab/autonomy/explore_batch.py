"""Exploration episodes as a batch (``roverlab explore --episodes N --workers K``)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

from roverlab.autonomy.explore_run import run_explore, write_explore_outputs
from roverlab.batch import Episode, episode_stop
from roverlab.sim.node import SpawnPose

__all__ = ["PLOT_COLUMNS", "explore_episode"]

# what episodes.png draws per episode
PLOT_COLUMNS = [("coverage", "coverage (share)"), ("accuracy", "map accuracy (share)")]


def explore_episode(config: dict[str, Any], seed: int) -> Episode:
    """One ``roverlab explore`` episode with ``seed``; ``config`` holds world, robot,
    slam, duration_s and spawn ``[x, y, yaw]``. The row is the episode's summary; the
    files are what ``roverlab explore`` writes for one episode."""
    x, y, yaw = config.get("spawn", (0.0, 0.0, 0.0))
    episode = run_explore(
        world=config["world"], robot=config["robot"], slam=config["slam"], seed=seed,
        duration_s=float(config["duration_s"]), spawn=SpawnPose(x, y, yaw),
        stop=episode_stop(),
    )  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="roverlab-explore-") as folder:
        written = write_explore_outputs(episode, Path(folder))
        files = {p.name: p.read_bytes() for p in written}
    return Episode(row=episode.result.to_dict(), files=files)
