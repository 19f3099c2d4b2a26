"""Batch evaluation: many seeded episodes, serially or in parallel on Ray, with one
aggregate (JSON, CSV, a plot). Used by ``roverlab explore`` and ``roverlab nav bench``
(``--episodes N --workers K [--ray-address ADDR]``)."""

from roverlab.batch.report import aggregate, estimate_hours, write_batch_outputs
from roverlab.batch.runner import BatchError, Episode, EpisodeFn, episode_stop, run_batch

__all__ = [
    "BatchError",
    "Episode",
    "EpisodeFn",
    "aggregate",
    "episode_stop",
    "estimate_hours",
    "run_batch",
    "write_batch_outputs",
]
