"""Many fixed-goal episodes in one run (``roverlab nav bench --worlds ...``), and BARN's
suite (``--suite barn``): every ``world_N.world`` of a folder, from BARN's start to its
goal, scored against ``../path_files/path_N.npy``.

BARN's rules (its ``run.py``, described in the data's README): start ``(-2.25, 3.0,
1.57)`` in the world, goal 10 m ahead at ``(-2.25, 13.0)``; the clock starts when the
robot is 0.1 m from its start; success within 1 m of the goal; any contact is a
collision and ends the episode; 100 s limit; odometry only, no prior map. The reference
path is the start, the cells of ``path_N.npy`` (``x = col * 0.15 - 0.075 - 4.5``, ``y =
row * 0.15 + 0.075 + 5``; ``col`` the first entry of a row, as run.py reads it) and the
goal; the optimal time is its length at 2 m/s.

Episodes run one after another, or in parallel on Ray (``workers``/``address``) as the
other batches do; each returns its files, which the driver writes into ``out`` with
``summary.json`` and ``worlds.csv``.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.batch import Episode, run_batch
from roverlab.description import find_package
from roverlab.fileio import atomic_write_bytes
from roverlab.navbench.fixed import FixedConfig, run_fixed
from roverlab.navbench.harness import BenchError

__all__ = [
    "BARN_GOAL",
    "BARN_START",
    "SUITES",
    "barn_reference",
    "barn_worlds",
    "run_suite",
    "suite_episode",
    "summarize",
]

SUITES = ("barn",)
BARN_START = (-2.25, 3.0, 1.57)
BARN_GOAL = (-2.25, 13.0, 0.0)  # (0, 10) from the start, yaw 0 (the quaternion run.py sends)
_BARN_CELL = 0.15
_WORLD_RE = re.compile(r"^world_(\d+)\.world$")


def barn_worlds(folder: Path) -> list[tuple[int, Path, Path | None]]:
    """``(N, world_N.world, path_N.npy or None)`` of every BARN world in ``folder``, by N.

    Raises:
        BenchError: no such folder, or no ``world_N.world`` in it.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise BenchError(f"{folder}: worlds folder not found")
    found = []
    for p in folder.iterdir():
        m = _WORLD_RE.match(p.name)
        if m:
            n = int(m.group(1))
            ref = folder.parent / "path_files" / f"path_{n}.npy"
            found.append((n, p, ref if ref.is_file() else None))
    if not found:
        raise BenchError(f"{folder}: no world_N.world files")
    return sorted(found)


def barn_reference(path_file: Path) -> tuple[tuple[float, float], ...]:
    """BARN's reference path in world coordinates: start, the path's cells, goal.

    Raises:
        BenchError: the file is not a readable (K, 2) array.
    """
    try:
        cells = np.load(path_file)
    except (OSError, ValueError) as err:
        raise BenchError(f"{path_file}: not a numpy path file: {err}") from err
    cells = np.asarray(cells, dtype=np.float64)
    if cells.ndim != 2 or cells.shape[1] != 2:
        raise BenchError(f"{path_file}: expected (K, 2) cells, got shape {cells.shape}")
    x = cells[:, 0] * _BARN_CELL - _BARN_CELL / 2 - 30 * _BARN_CELL
    y = cells[:, 1] * _BARN_CELL + _BARN_CELL / 2 + 5.0
    pts = [BARN_START[:2], *zip(x.tolist(), y.tolist(), strict=True), BARN_GOAL[:2]]
    return tuple((float(a), float(b)) for a, b in pts)


def _to_dict(cfg: FixedConfig) -> dict[str, Any]:
    d = asdict(cfg)
    for k in ("out", "params_dir", "launch", "teb_params"):
        d[k] = str(d[k]) if d[k] is not None else None
    return d


def _from_dict(d: dict[str, Any]) -> FixedConfig:
    fields = dict(d)
    for k in ("out", "params_dir", "launch", "teb_params"):
        fields[k] = Path(fields[k]) if fields[k] is not None else None
    for k in ("start", "goal"):
        fields[k] = tuple(fields[k])
    if fields.get("reference") is not None:
        fields["reference"] = tuple(tuple(p) for p in fields["reference"])
    return FixedConfig(**fields)


def suite_episode(config: dict[str, Any], index: int) -> Episode:
    """Episode ``index`` of a suite (``config["episodes"]``: one FixedConfig as a dict
    each): a plain function of picklable arguments, for a worker process or Ray. The row
    is the episode's JSON without its path; the files are its JSON, CSV and PNG."""
    cfg = _from_dict(config["episodes"][index])
    result, files = run_fixed(cfg, write=False)
    row = result.to_json()
    for key in ("path", "contact_points", "warnings", "start", "goal", "end"):
        row.pop(key, None)
    return Episode(row=row, files=files)


def _mean(values: list[float]) -> float | None:
    vals = [v for v in values if v is not None and math.isfinite(v)]
    return round(float(np.mean(vals)), 4) if vals else None


def _median(values: list[float | None]) -> float | None:
    vals = [v for v in values if v is not None and math.isfinite(v)]
    return round(float(np.median(vals)), 2) if vals else None


def summarize(rows: list[dict[str, Any]], **extra: Any) -> dict[str, Any]:
    """``summary.json``: worlds, rates, BARN's mean score, mean time of the successful
    episodes, the worst world's control-cycle CPU p99, the real-time factor per CPU
    second of the whole stack, and what was run (``extra``)."""
    ok = [r for r in rows if not r.get("error") and r.get("status") != "interrupted"]
    n = len(ok)

    def rate(status: str) -> float | None:
        return round(sum(r["status"] == status for r in ok) / n, 4) if n else None

    p99 = [r["control_ms_p99"] for r in ok if r.get("control_ms_p99") is not None]
    sim = sum(r.get("sim_time_s") or 0.0 for r in ok)
    cpu = sum(r.get("cpu_s") or 0.0 for r in ok)
    scores = [r["score"] for r in ok if r.get("score") is not None]
    return {
        "worlds": n,
        "errors": sum(1 for r in rows if r.get("error")),
        "interrupted": sum(1 for r in rows if r.get("status") == "interrupted"),
        "success_rate": rate("succeeded"),
        "collision_rate": rate("collided"),
        "timeout_rate": rate("timeout"),
        "score_mean": _mean(scores) if scores else None,
        "time_mean_s": _mean([r["time_s"] for r in ok if r["status"] == "succeeded"]),
        "control_ms_p99_max": round(max(p99), 3) if p99 else None,
        "control_ms_p99_worst_world": max(ok, key=lambda r: r.get("control_ms_p99") or 0.0)["world"]
        if p99
        else None,
        "rtf_per_cpu_s": round(sim / cpu, 2) if cpu > 0 else None,
        # per world (the first world of a process also loads the compiled kernels)
        "rtf_per_cpu_s_median": _median([r.get("rtf_per_cpu_s") for r in ok]),
        "sim_time_s": round(sim, 2),
        "cpu_s": round(cpu, 2),
        **extra,
    }


def _csv(rows: list[dict[str, Any]]) -> bytes:
    keys = [
        "episode", "world", "status", "move_base_status", "time_s", "score", "reference_m",
        "driven_m", "contacts", "recoveries", "control_ms_p99", "planner_ms_p99",
        "sim_time_s", "cpu_s", "rtf_per_cpu_s", "text", "error",
    ]  # fmt: skip
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=keys, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow(r)
    return buf.getvalue().encode()


def barn_configs(
    worlds_dir: Path, base: FixedConfig, *, only: int | None = None
) -> list[FixedConfig]:
    """One FixedConfig per BARN world of ``worlds_dir`` (the first ``only``), from
    ``base`` with BARN's start, goal, rules and reference path; the parameters default
    to BARN's own beside the worlds (``../params``), TEB's to the bundled Jackal file."""
    params = base.params_dir
    if params is None and (Path(worlds_dir).parent / "params").is_dir():
        params = Path(worlds_dir).parent / "params"
    teb = base.teb_params
    if teb is None and not (params and (Path(params) / "teb_local_planner_params.yaml").is_file()):
        teb = (
            find_package("robot_navigation") / "param" / "Jackal" / "teb_local_planner_params.yaml"
        )
    out = []
    for n, world, ref in barn_worlds(Path(worlds_dir))[:only]:
        out.append(
            replace(
                base,
                world=str(world.resolve()),
                name=f"world_{n}",
                start=BARN_START,
                goal=BARN_GOAL,
                params_dir=params,
                teb_params=teb,
                goal_tolerance_m=1.0,
                time_limit_s=100.0,
                start_move_m=0.1,
                on_collision="end",
                localization="odom",
                reference=barn_reference(ref) if ref else None,
            )
        )
    return out


def run_suite(
    configs: list[FixedConfig],
    out: Path,
    *,
    workers: int = 1,
    address: str | None = None,
    stop: threading.Event | None = None,
    log: Callable[[str], None] = lambda _l: None,
    extra: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Run every episode, write each one's files, ``worlds.csv`` and ``summary.json``
    into ``out`` (after every episode, replaced atomically); return the summary.

    Raises:
        BenchError: a bad option (checked on the first configuration before any run).
    """
    if not configs:
        raise BenchError("no worlds to run")
    configs[0].validate()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    wall0 = time.perf_counter()
    rows: list[dict[str, Any]] = []
    info = {
        "date": datetime.now(UTC).strftime("%Y-%m-%d"),
        "planner": configs[0].planner,
        "robot": configs[0].robot,
        "localization": configs[0].localization,
        "max_speed": configs[0].max_speed,
        "params": str(configs[0].params_dir) if configs[0].params_dir else None,
        "launch": str(configs[0].launch) if configs[0].launch else None,
        "seed": configs[0].seed,
        "workers": workers,
        **(extra or {}),
    }

    def write() -> dict[str, Any]:
        ordered = sorted(rows, key=lambda r: r["episode"])
        summary = summarize(
            ordered, **info, wall_s=round(time.perf_counter() - wall0, 2),
            machine={"cpus": os.cpu_count(), "load_average": list(os.getloadavg())},
        )  # fmt: skip
        atomic_write_bytes(out / "worlds.csv", _csv(ordered))
        atomic_write_bytes(out / "summary.json", (json.dumps(summary, indent=1) + "\n").encode())
        return summary

    def done(ep: Episode, n: int, total: int) -> None:
        row = ep.row
        i = int(row["episode"])
        row.setdefault("world", configs[i].name)
        row["seed"] = configs[i].seed  # run_batch's "seed" is the episode's index
        for fname, data in ep.files.items():
            atomic_write_bytes(out / fname, data)
        rows.append(row)
        write()
        if row.get("error"):
            log(f"[{n}/{total}] {row['world']}: error: {row['error']}")
        else:
            score = f", score {row['score']:.3f}" if row.get("score") is not None else ""
            log(
                f"[{n}/{total}] {row['world']}: {row['status']} in {row['time_s']:.1f} s"
                f"{score}, control p99 {row['control_ms_p99'] or math.nan:.1f} ms, "
                f"{row['rtf_per_cpu_s'] or math.nan:.0f}x per CPU s"
                + ("" if row["status"] == "succeeded" else f" ({row['move_base_status']}"
                   f"{': ' + row['text'] if row.get('text') else ''})")
            )  # fmt: skip

    run_batch(
        suite_episode, {"episodes": [_to_dict(c) for c in configs]},
        episodes=len(configs), seed=0, workers=workers, address=address, stop=stop,
        on_done=done,
    )  # fmt: skip
    return write()
