"""The benchmark's results: per-goal records, the summary figures, ``bench.json``,
``bench.png`` and the one summary line."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw

from roverlab.fileio import atomic_write, atomic_write_bytes
from roverlab.navbench.grid import BenchGrid

if TYPE_CHECKING:
    from roverlab.navbench.harness import BenchConfig

__all__ = ["BenchReport", "GoalRecord"]

_PATH_STEP_M = 0.05  # path points kept in bench.json


def _r(v: float, nd: int = 4) -> float | None:
    return round(float(v), nd) if math.isfinite(v) else None


def _thin(path: NDArray[np.float64], step: float) -> NDArray[np.float64]:
    """Path points at least ``step`` apart (first and last kept)."""
    if len(path) < 3:
        return path
    keep = [0]
    for i in range(1, len(path) - 1):
        if math.hypot(*(path[i] - path[keep[-1]])) >= step:
            keep.append(i)
    keep.append(len(path) - 1)
    return path[keep]


@dataclass
class GoalRecord:
    """One goal: where from and to, how it ended, what it took.

    ``status`` is the action's final state name (SUCCEEDED, ABORTED, ...) or TIMEOUT
    (canceled by the bench); ``succeeded`` also needs the true position within
    ``SUCCESS_RADIUS_M`` of the goal. ``failures`` counts the planners' failure texts
    (``"control: teb_local_planner: trajectory is not feasible"``: 3). ``path`` is the
    driven ground-truth path; ``recoveries`` counts move_base's CLEARING episodes.
    """

    index: int
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    status: str
    text: str
    succeeded: bool
    time_s: float
    driven_m: float
    shortest_m: float
    end: tuple[float, float, float]
    error_m: float
    yaw_error: float
    contacts: int
    contact_points: list[tuple[float, float]]
    planner_calls: int
    controller_calls: int
    failures: dict[str, int]
    recoveries: int
    path: NDArray[np.float64]

    @property
    def path_ratio(self) -> float:
        """Driven length / shortest path (inf without a shortest path)."""
        if not (math.isfinite(self.shortest_m) and self.shortest_m > 0):
            return math.inf
        return self.driven_m / self.shortest_m

    def to_json(self) -> dict[str, Any]:
        return {
            "index": self.index,
            "start": [_r(v) for v in self.start],
            "goal": [_r(v) for v in self.goal],
            "status": self.status,
            "text": self.text,
            "succeeded": self.succeeded,
            "time_s": _r(self.time_s, 3),
            "driven_m": _r(self.driven_m),
            "shortest_m": _r(self.shortest_m),
            "path_ratio": _r(self.path_ratio),
            "end": [_r(v) for v in self.end],
            "error_m": _r(self.error_m),
            "yaw_error_rad": _r(self.yaw_error),
            "contacts": self.contacts,
            "contact_points": [[_r(x, 3), _r(y, 3)] for x, y in self.contact_points],
            "planner_calls": self.planner_calls,
            "controller_calls": self.controller_calls,
            "failures": self.failures,
            "recoveries": self.recoveries,
            "path": [[_r(x, 3), _r(y, 3)] for x, y in _thin(self.path, _PATH_STEP_M)],
        }

    def progress_line(self, total: int) -> str:
        ok = "ok  " if self.succeeded else "FAIL"
        return (
            f"goal {self.index + 1}/{total} {ok} {self.status:<9} "
            f"({self.goal[0]:.2f}, {self.goal[1]:.2f}) {self.time_s:6.1f} s "
            f"{self.driven_m:5.2f} m / {self.shortest_m:5.2f} m"
            + (f" contacts {self.contacts}" if self.contacts else "")
            + ("" if self.succeeded else f": {self.text}")
        )


def _p99_ms(values: list[float]) -> float:
    return float(np.percentile(values, 99) * 1000.0) if values else math.nan


def _median(values: list[float]) -> float:
    return float(np.median(values)) if values else math.nan


@dataclass
class BenchReport:
    """Records and figures of one run (see :func:`~roverlab.navbench.run_bench`)."""

    config: BenchConfig
    map_yaml: Path
    grid: BenchGrid
    local_planner: str
    records: list[GoalRecord] = field(default_factory=list)
    interrupted: str | None = None
    collisions: int = 0
    planner_ms_p99: float = math.nan
    controller_ms_p99: float = math.nan
    planner_wall_ms_p99: float = math.nan
    controller_wall_ms_p99: float = math.nan
    planner_calls: int = 0
    controller_calls: int = 0
    sim_time_s: float = 0.0
    wall_time_s: float = 0.0

    def add(self, record: GoalRecord) -> None:
        self.records.append(record)

    def set_totals(
        self, *, timings: Any, collisions: int, sim_time_s: float, wall_time_s: float
    ) -> None:
        self.collisions = collisions
        self.planner_ms_p99 = _p99_ms(timings.plan_cpu)
        self.controller_ms_p99 = _p99_ms(timings.control_cpu)
        self.planner_wall_ms_p99 = _p99_ms(timings.plan_wall)
        self.controller_wall_ms_p99 = _p99_ms(timings.control_wall)
        self.planner_calls = len(timings.plan_cpu)
        self.controller_calls = len(timings.control_cpu)
        self.sim_time_s = sim_time_s
        self.wall_time_s = wall_time_s

    # ------------------------------------------------------------------ figures
    @property
    def succeeded(self) -> int:
        return sum(r.succeeded for r in self.records)

    @property
    def success_rate(self) -> float:
        return self.succeeded / len(self.records) if self.records else math.nan

    @property
    def path_ratio_median(self) -> float:
        return _median([r.path_ratio for r in self.records if r.succeeded])

    @property
    def time_per_goal_median_s(self) -> float:
        return _median([r.time_s for r in self.records if r.succeeded])

    def summary(self) -> dict[str, Any]:
        c = self.config
        return {
            "world": c.world,
            "robot": c.robot,
            "map": str(self.map_yaml),
            "planner": c.planner,
            "local_planner": self.local_planner,
            "localization": c.localization,
            "seed": c.seed,
            "goals_requested": c.goals,
            "goal_timeout_s": c.goal_timeout_s,
            "goals": len(self.records),
            "succeeded": self.succeeded,
            "success_rate": _r(self.success_rate),
            "collisions": self.collisions,
            "path_ratio_median": _r(self.path_ratio_median),
            "time_per_goal_median_s": _r(self.time_per_goal_median_s, 3),
            "planner_ms_p99": _r(self.planner_ms_p99, 3),
            "controller_ms_p99": _r(self.controller_ms_p99, 3),
            "planner_wall_ms_p99": _r(self.planner_wall_ms_p99, 3),
            "controller_wall_ms_p99": _r(self.controller_wall_ms_p99, 3),
            "planner_calls": self.planner_calls,
            "controller_calls": self.controller_calls,
            "sim_time_s": _r(self.sim_time_s, 2),
            "wall_time_s": _r(self.wall_time_s, 2),
            "interrupted": self.interrupted,
            "machine": {"cpus": os.cpu_count(), "load_average": list(os.getloadavg())},
        }

    def summary_line(self) -> str:
        c = self.config
        n = len(self.records)
        pct = 100.0 * self.success_rate if n else 0.0
        line = (
            f"{Path(c.world).stem} {c.robot} {c.planner} {c.localization} seed {c.seed}: "
            f"{self.succeeded}/{n} goals ({pct:.0f} %), {self.collisions} collisions, "
            f"path ratio median {self.path_ratio_median:.3f}, "
            f"{self.time_per_goal_median_s:.1f} s/goal median, "
            f"planner p99 {self.planner_ms_p99:.1f} ms, "
            f"controller p99 {self.controller_ms_p99:.1f} ms"
        )
        if self.interrupted:
            line += f" (interrupted by {self.interrupted} after {n} of {c.goals} goals)"
        return line

    # ------------------------------------------------------------------ files
    def to_dict(self) -> dict[str, Any]:
        """What ``bench.json`` holds: :meth:`summary` and ``records``, one per goal."""
        return {**self.summary(), "records": [r.to_json() for r in self.records]}

    def write_json(self, path: Path) -> None:
        atomic_write_bytes(path, (json.dumps(self.to_dict(), indent=1) + "\n").encode())

    def write_png(self, path: Path) -> None:
        img = draw(self.grid, self.records)
        atomic_write(path, lambda fh: img.save(fh, format="PNG"))


_OK_COLOURS = ((31, 119, 180), (44, 160, 44), (148, 103, 189), (23, 190, 207), (140, 86, 75))
_FAIL = (214, 39, 40)
_CONTACT = (255, 127, 14)
_REFERENCE = (230, 120, 200)  # pink: the reference path


def draw(
    grid: BenchGrid,
    records: list[GoalRecord],
    max_px: int = 1200,
    *,
    reference: tuple[tuple[float, float], ...] | None = None,
) -> Image.Image:
    """The map (black lethal, grey inflated to the inscribed radius, light grey unknown),
    every driven path (coloured; red for failed goals), goals as circles with a heading
    tick (a red cross and the goal's number for failures), contacts as orange dots, and
    a ``reference`` path (thin grey-blue) when given. The canvas grows (white) to hold
    every goal, start and path point that lies off the map."""
    res = grid.resolution
    pts = [(r.goal[0], r.goal[1]) for r in records] + [(r.start[0], r.start[1]) for r in records]
    pts += [(float(x), float(y)) for r in records for x, y in r.path]
    pts += list(reference or ())
    h0, w0 = grid.costs.shape
    ox, oy = grid.origin
    xs = [ox, ox + w0 * res, *(p[0] for p in pts)]
    ys = [oy, oy + h0 * res, *(p[1] for p in pts)]
    margin = 0.5
    pad_l = max(0, math.ceil((ox - (min(xs) - margin)) / res)) if min(xs) < ox else 0
    pad_b = max(0, math.ceil((oy - (min(ys) - margin)) / res)) if min(ys) < oy else 0
    right = ox + w0 * res
    top = oy + h0 * res
    pad_r = max(0, math.ceil((max(xs) + margin - right) / res)) if max(xs) > right else 0
    pad_t = max(0, math.ceil((max(ys) + margin - top) / res)) if max(ys) > top else 0
    costs = np.pad(grid.costs, ((pad_b, pad_t), (pad_l, pad_r)), constant_values=0)
    origin = (ox - pad_l * res, oy - pad_b * res)
    h, w = costs.shape
    scale = max(1, min(8, max_px // max(h, w)))
    base = np.full((h, w, 3), 255, dtype=np.uint8)
    base[costs >= 253] = (200, 200, 200)
    base[costs == 254] = (0, 0, 0)
    base[costs == 255] = (225, 225, 225)
    img = Image.fromarray(base[::-1]).resize((w * scale, h * scale), Image.Resampling.NEAREST)
    d = ImageDraw.Draw(img)

    def px(x: float, y: float) -> tuple[float, float]:
        return (
            (x - origin[0]) / res * scale,
            (h - (y - origin[1]) / res) * scale,
        )

    rad = max(3.0, 0.1 / res * scale)
    if reference is not None and len(reference) > 1:
        d.line([px(x, y) for x, y in reference], fill=_REFERENCE, width=max(1, scale // 3))
    for r in records:
        colour = _OK_COLOURS[r.index % len(_OK_COLOURS)] if r.succeeded else _FAIL
        pts_px = [px(x, y) for x, y in r.path]
        if len(pts_px) > 1:
            d.line(pts_px, fill=colour, width=max(1, scale // 2))
    for r in records:
        gx, gy = px(r.goal[0], r.goal[1])
        tip = px(r.goal[0] + 0.25 * math.cos(r.goal[2]), r.goal[1] + 0.25 * math.sin(r.goal[2]))
        if r.succeeded:
            d.ellipse((gx - rad, gy - rad, gx + rad, gy + rad), outline=(0, 110, 0), width=2)
            d.line([(gx, gy), tip], fill=(0, 110, 0), width=2)
        else:
            d.line([(gx - rad, gy - rad), (gx + rad, gy + rad)], fill=_FAIL, width=3)
            d.line([(gx - rad, gy + rad), (gx + rad, gy - rad)], fill=_FAIL, width=3)
            d.line([(gx, gy), tip], fill=_FAIL, width=2)
            d.text((gx + rad + 2, gy - rad - 2), str(r.index + 1), fill=_FAIL)
        for x, y in r.contact_points:
            cx, cy = px(x, y)
            d.ellipse((cx - rad, cy - rad, cx + rad, cy + rad), fill=_CONTACT)
    return img
