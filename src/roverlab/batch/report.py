"""A batch's outputs: every episode's row (JSON + CSV), the aggregate, a plot, each
episode's own files, and what a larger batch would take."""

from __future__ import annotations

import csv
import io
import json
import math
import statistics
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from roverlab.batch.runner import Episode
from roverlab.charts import write_line_chart

__all__ = ["aggregate", "estimate_hours", "write_batch_outputs"]

_COLOURS = [(30, 90, 200), (200, 80, 30), (40, 150, 60), (150, 60, 160)]


def _numbers(rows: Sequence[dict[str, Any]], key: str) -> list[float]:
    out = []
    for row in rows:
        v = row.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            continue
        if math.isfinite(v):
            out.append(float(v))
    return out


def aggregate(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Per numeric column: mean, std, median, min, max over the episodes that have it; per
    boolean column: the share that is true; plus the episode and error counts."""
    keys: list[str] = []
    for row in rows:
        keys += [k for k in row if k not in keys and k not in ("episode", "seed")]
    out: dict[str, Any] = {
        "episodes": len(rows),
        "errors": sum(1 for r in rows if r.get("error")),
    }
    for key in keys:
        flags = [r[key] for r in rows if isinstance(r.get(key), bool)]
        if flags:
            out[key] = {"share": round(sum(flags) / len(flags), 5), "n": len(flags)}
            continue
        values = _numbers(rows, key)
        if not values:
            continue
        out[key] = {
            "mean": round(statistics.fmean(values), 6),
            "std": round(statistics.pstdev(values), 6),
            "median": round(statistics.median(values), 6),
            "min": min(values),
            "max": max(values),
            "n": len(values),
        }
    return out


def estimate_hours(rows: Sequence[dict[str, Any]], episodes: int, cores: int) -> float:
    """Wall hours for ``episodes`` episodes on ``cores`` cores at the measured mean cost of
    one episode on one core (nan without a measured episode)."""
    walls = _numbers(rows, "wall_s")
    if not walls or cores < 1:
        return math.nan
    return statistics.fmean(walls) * math.ceil(episodes / cores) / 3600.0


def _atomic_write(path: Path, data: bytes) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_bytes(data)
    tmp.replace(path)


def write_batch_outputs(
    out: Path,
    episodes: Sequence[Episode],
    *,
    config: dict[str, Any],
    plot: Sequence[tuple[str, str]],
    title: str,
    wall_s: float,
    workers: int,
) -> list[Path]:
    """Write ``out``/episodes.json (config, rows, aggregate, wall time, a 10,000-episode
    estimate), episodes.csv (one row per episode), episodes.png (the ``plot`` columns,
    ``(key, label)``, per episode) and each episode's files under ``episode_NNN/``.
    Returns the written paths."""
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    rows = [e.row for e in episodes]
    for e in episodes:
        folder = out / f"episode_{int(e.row['episode']):03d}"
        for name, data in e.files.items():
            folder.mkdir(exist_ok=True)
            _atomic_write(folder / name, data)
            written.append(folder / name)
    summary = {
        "config": config,
        "workers": workers,
        "wall_s": round(wall_s, 3),
        "aggregate": aggregate(rows),
        "estimate_10000_episodes_hours": {
            f"{n} cores": round(estimate_hours(rows, 10_000, n), 2) for n in (2, 16, 64, 256)
        },
        "episodes": [
            {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
             for k, v in r.items()}
            for r in rows
        ],
    }  # fmt: skip
    _atomic_write(out / "episodes.json", (json.dumps(summary, indent=1) + "\n").encode())
    written.append(out / "episodes.json")
    columns: list[str] = []
    for r in rows:
        columns += [k for k in r if k not in columns and not isinstance(r[k], (list, dict))]
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=columns, extrasaction="ignore")
    writer.writeheader()
    writer.writerows(rows)
    _atomic_write(out / "episodes.csv", text.getvalue().encode())
    written.append(out / "episodes.csv")
    series = []
    for k, (key, label) in enumerate(plot):
        points = [(float(r["episode"]), float(r[key])) for r in rows
                  if isinstance(r.get(key), (int, float)) and math.isfinite(r[key])]  # fmt: skip
        if points:
            xs, ys = zip(*points, strict=True)
            series.append((list(xs), list(ys), _COLOURS[k % len(_COLOURS)], label))
    if series:
        values = [y for _, ys, _, _ in series for y in ys]
        shares = all(0.0 <= y <= 1.0 for y in values)
        write_line_chart(
            out / "episodes.png", series, title=title, xlabel="episode",
            ylabel="share" if shares else "value", y_range=(0.0, 1.0) if shares else None,
            markers=True,
        )  # fmt: skip
        written.append(out / "episodes.png")
    return written
