"""nav bench episodes as a batch (``roverlab nav bench --episodes N --workers K``)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

from roverlab.batch import Episode, episode_stop
from roverlab.navbench.harness import BenchConfig, run_bench

__all__ = ["PLOT_COLUMNS", "nav_episode"]

# what episodes.png draws per episode
PLOT_COLUMNS = [("success_rate", "success rate"), ("path_ratio_median", "path ratio (median)")]


def nav_episode(config: dict[str, Any], seed: int) -> Episode:
    """One ``roverlab nav bench`` run with ``seed``. ``config`` holds BenchConfig's fields
    but ``out`` and ``seed`` (paths as strings). The row is the run's summary (the machine
    left out; the measured compute times are the only figures that differ between runs of
    the same seed); the files are bench.json, bench.png and the map it drew."""
    fields = dict(config)
    for key in ("map_yaml", "params_dir"):
        if fields.get(key) is not None:
            fields[key] = Path(fields[key])
    with tempfile.TemporaryDirectory(prefix="roverlab-navbench-") as folder:
        out = Path(folder)
        cfg = BenchConfig(out=out, seed=seed, **fields)
        report = run_bench(cfg)  # handles Ctrl-C itself: the goals so far, then stop
        if report.interrupted:
            episode_stop().set()  # and no further episode
        files = {p.name: p.read_bytes() for p in sorted(out.iterdir()) if p.is_file()}
        row = {k: v for k, v in report.summary().items() if k != "machine"}
        if isinstance(row.get("map"), str) and row["map"].startswith(folder):
            row["map"] = Path(row["map"]).name  # drawn in the episode's own folder
    return Episode(row=row, files=files)
