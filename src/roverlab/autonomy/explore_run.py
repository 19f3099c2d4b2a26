"""One exploration episode, headless: the robot maps a world on its own, then the map is
scored against the world (``roverlab explore``).

The simulator, the SLAM node, move_base and explore run in one private context on the
simulated clock, as fast as the CPU allows (or paced at ``rate`` x real time). The episode
ends when explore finds no frontier left, at ``duration_s`` of simulated time, or when
``stop`` is set (Ctrl-C); the outputs are written in every case.
"""

from __future__ import annotations

import json
import math
import threading
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.autonomy.monitor import RunMonitor
from roverlab.autonomy.stack import ExploreStack, start_explore_stack
from roverlab.charts import write_line_chart
from roverlab.core import Context
from roverlab.maps import save_map
from roverlab.maps.plot import write_map_png
from roverlab.sim.node import SpawnPose
from roverlab.slam.data.mapquality import MapQualityError, evaluate_map, grid_from_msg, ground_truth

__all__ = ["ExploreResult", "run_explore", "write_explore_outputs"]


@dataclass(frozen=True)
class ExploreResult:
    """The figures of one episode (JSON-ready: plain numbers and strings)."""

    world: str
    robot: str
    slam: str
    seed: int
    finished: bool  # explore found no frontier left
    reason: str  # "no frontier left", "time limit", "interrupted"
    sim_s: float
    wall_s: float
    explored_m2: float  # known area of the final map
    reachable_m2: float  # the world's free area reachable from the spawn
    coverage: float  # share of the reachable area the final map knows
    accuracy: float  # slam mapeval: share of known cells correct (nan: no map)
    wall_distance_p95: float  # cells
    distance_m: float
    contacts: int
    goals_sent: int
    time_to_95_s: float  # sim time when 95% of the reachable area was known (inf: never)

    def summary(self) -> str:
        """The summary line."""
        t95 = f"{self.time_to_95_s:.0f} s" if math.isfinite(self.time_to_95_s) else "never"
        return (
            f"explore {self.world} / {self.robot} / {self.slam} (seed {self.seed}): "
            f"{self.reason}; explored {self.explored_m2:.1f} m^2, {100 * self.coverage:.1f}% "
            f"of the reachable free area ({self.reachable_m2:.1f} m^2; 95% at {t95}); map "
            f"{100 * self.accuracy:.1f}% of known cells correct; {self.distance_m:.1f} m "
            f"driven, {self.contacts} contact(s), {self.goals_sent} goals; {self.sim_s:.0f} s "
            f"sim in {self.wall_s:.1f} s wall ({self.sim_s / max(self.wall_s, 1e-9):.1f}x)"
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain values; non-finite numbers as None (JSON has no inf)."""
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in asdict(self).items()}  # fmt: skip


@dataclass
class ExploreEpisode:
    """A finished episode: the figures and what the outputs are drawn from."""

    result: ExploreResult
    monitor: RunMonitor
    map_msg: Any


def run_explore(
    *,
    world: str | Path = "maze",
    robot: str | Path = "mybot",
    slam: str = "gmapping",
    seed: int = 0,
    duration_s: float = 900.0,
    rate: float = math.inf,
    spawn: SpawnPose | None = None,
    stop: threading.Event | None = None,
    context: Context | None = None,
    explore_params: dict[str, Any] | None = None,
) -> ExploreEpisode:
    """Run one exploration episode (see the module docstring).

    ``context``: run in this one (the caller shuts it down; e.g. with a dashboard
    attached); default a private context on the simulated clock, shut down at the end.
    """
    own = context is None
    if context is None:
        context = Context(clock="sim") if math.isinf(rate) else Context(clock="paced", rate=rate)
    stop = stop or threading.Event()
    started = time.perf_counter()
    try:
        stack = start_explore_stack(
            context, world=world, robot=robot, slam=slam, seed=seed, spawn=spawn,
            explore_params=explore_params,
        )  # fmt: skip
        monitor = RunMonitor(context, stack.simulation)
        explore = stack.explore
        start_s = context.now().seconds
        context.wait_for(
            lambda: stop.is_set() or not explore.exploring,
            max(0.0, start_s + duration_s - context.now().seconds),
        )
        monitor.sample()
        if not explore.exploring:
            reason = "no frontier left"
        elif stop.is_set():
            reason = "interrupted"
        else:
            reason = "time limit"
        result = _score(stack, monitor, world, robot, slam, seed, reason, started)
        return ExploreEpisode(result=result, monitor=monitor, map_msg=monitor.map_msg)
    finally:
        if own:
            context.shutdown()


def _score(
    stack: ExploreStack,
    monitor: RunMonitor,
    world: str | Path,
    robot: str | Path,
    slam: str,
    seed: int,
    reason: str,
    started: float,
) -> ExploreResult:
    msg = monitor.map_msg
    explored = coverage = reachable = 0.0
    accuracy = p95 = math.nan
    if msg is not None:
        grid = grid_from_msg(msg)
        explored = float(np.count_nonzero(np.asarray(grid.data) >= 0)) * grid.resolution**2
        area = monitor.reachable(grid.resolution)
        reachable = area.area_m2
        coverage = area.known_fraction(grid)
        gt = ground_truth(
            stack.simulation.world_model, resolution=grid.resolution, z_m=monitor.lidar_z_m
        )
        try:
            quality = evaluate_map(grid, gt, prior=monitor.spawn)
            accuracy, p95 = quality.accuracy, quality.wall_distance_p95
        except MapQualityError:
            pass
    return ExploreResult(
        world=str(world),
        robot=str(robot),
        slam=slam,
        seed=seed,
        finished=reason == "no frontier left",
        reason=reason,
        sim_s=round(monitor.get_clock().now_ns() / 1e9, 3),
        wall_s=round(time.perf_counter() - started, 3),
        explored_m2=round(explored, 3),
        reachable_m2=round(reachable, 3),
        coverage=round(coverage, 5),
        accuracy=round(accuracy, 5),
        wall_distance_p95=round(p95, 3),
        distance_m=round(monitor.distance_m, 3),
        contacts=monitor.contacts,
        goals_sent=stack.explore.goals_sent,
        time_to_95_s=round(monitor.time_to(0.95), 3),
    )


def write_explore_outputs(episode: ExploreEpisode, out: Path) -> list[Path]:
    """``out``/map.yaml + map.pgm (as map_saver), map.png (with the true path), coverage.png
    (known share of the reachable area over time), summary.json. The written files."""
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    msg, monitor = episode.map_msg, episode.monitor
    if msg is not None:
        grid = grid_from_msg(msg)
        data = np.asarray(grid.data)
        saved = save_map(
            out / "map", data, resolution=grid.resolution,
            origin=(grid.origin_xy[0], grid.origin_xy[1], 0.0),
        )  # fmt: skip
        written += [saved.yaml_path, saved.image_path]
        write_map_png(out / "map.png", data, grid.resolution, grid.origin_xy, monitor.map_path)
        written.append(out / "map.png")
    samples = monitor.coverage
    write_line_chart(
        out / "coverage.png",
        [(
            [s.t for s in samples], [100.0 * s.fraction for s in samples], (30, 90, 200),
            f"{episode.result.slam}: known share of the reachable free area",
        )],
        title=f"exploration of {Path(episode.result.world).stem} ({episode.result.robot})",
        xlabel="simulated time (s)", ylabel="% known", y_range=(0.0, 100.0),
        hline=(95.0, "95%"),
    )  # fmt: skip
    written.append(out / "coverage.png")
    summary = dict(episode.result.to_dict())
    summary["coverage_series"] = [[s.t, s.known_m2, s.fraction] for s in samples]
    tmp = out / "summary.json.part"
    tmp.write_text(json.dumps(summary, indent=1) + "\n")
    tmp.replace(out / "summary.json")
    written.append(out / "summary.json")
    return written
