"""Live mapping in the simulator: mybot driven through the bundled maze under each SLAM node.

The simulator, the SLAM node and a scripted driver run in one context on the sim executor
(as fast as the CPU allows, seeded). The driver follows a depth-first tour of the maze's
cells using the ground-truth pose, so every method sees the same drive; at the end the last
``/map`` is scored against the world's ground truth (:mod:`roverlab.slam.data.mapquality`).

Adding a SLAM method is one entry in :data:`METHODS`: a name and a function starting its
node in a context (here the seed 000 launch files, run through the launch registry).

The default run drives the first part of the tour (a CI-sized run); the whole tour is
``slow``. Overlay PNGs go to ``tmp_path``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from benchmarks.amcl import GroundTruthDriver

from roverlab.core import Context
from roverlab.geometry import SE2
from roverlab.launch import build_launch
from roverlab.msgs import classes as mc
from roverlab.sim.app import Simulation
from roverlab.slam.data.mapquality import (
    GroundTruth,
    MapQuality,
    evaluate_map,
    grid_from_msg,
    ground_truth,
    write_overlay_png,
)
from roverlab.slam.graph.node import SlamToolbox

FIXTURES = Path(__file__).parent / "fixtures"
MAZE_CELL_M = 1.6  # the maze's cell pitch: 5 x 5 cells centred on the spawn
MAZE_CELLS = 5


@dataclass(frozen=True)
class Method:
    """A SLAM method under test: how to start its node(s) in a context."""

    name: str
    start: Callable[[Context], object]


def _seed_launch(name: str) -> Callable[[Context], object]:
    """Start the seed's launch file ``name`` (through the launch registry, as
    ``roverlab launch`` does: unsupported parameters are warned about and dropped)."""
    return lambda ctx: build_launch(FIXTURES / name, context=ctx)


METHODS: dict[str, Method] = {
    m.name: m
    for m in (
        Method("gmapping", _seed_launch("gmapping.launch")),
        Method("hector", _seed_launch("hector.launch")),
        Method("graph", lambda ctx: SlamToolbox(ctx)),  # slam_toolbox's defaults
    )
}


# --------------------------------------------------------------------------- the route
def maze_tour(
    gt: GroundTruth, start: tuple[float, float] = (0.0, 0.0)
) -> list[tuple[float, float]]:
    """Cell centres of a depth-first tour of the maze from ``start`` (backtracking included).

    Two neighbouring cells are connected when the ground truth is free along the straight
    line between their centres, with 0.2 m of clearance either side.
    """
    half = MAZE_CELLS // 2
    cells = [(i, j) for i in range(-half, half + 1) for j in range(-half, half + 1)]

    def centre(c: tuple[int, int]) -> tuple[float, float]:
        return start[0] + c[0] * MAZE_CELL_M, start[1] + c[1] * MAZE_CELL_M

    def free(a: tuple[int, int], b: tuple[int, int]) -> bool:
        (x0, y0), (x1, y1) = centre(a), centre(b)
        t = np.linspace(0.0, 1.0, 64)
        nx, ny = -(y1 - y0), x1 - x0
        norm = math.hypot(nx, ny)
        for off in (-0.2, 0.0, 0.2):
            xs = x0 + t * (x1 - x0) + off * nx / norm
            ys = y0 + t * (y1 - y0) + off * ny / norm
            col = np.floor((xs - gt.origin_xy[0]) / gt.resolution).astype(int)
            row = np.floor((ys - gt.origin_xy[1]) / gt.resolution).astype(int)
            if gt.occupied[row, col].any():
                return False
        return True

    seen = {(0, 0)}
    tour = [centre((0, 0))]

    def visit(c: tuple[int, int]) -> None:
        for d in ((1, 0), (0, 1), (-1, 0), (0, -1)):
            n = (c[0] + d[0], c[1] + d[1])
            if n in cells and n not in seen and free(c, n):
                seen.add(n)
                tour.append(centre(n))
                visit(n)
                tour.append(centre(c))

    visit((0, 0))
    assert len(seen) == len(cells), "the maze tour must reach every cell"
    return tour


class WaypointDriver(GroundTruthDriver):
    """Drives to each waypoint in turn on the ground-truth pose (turn, then go), after
    standing still for ``start_s`` (the SLAM map frame is the pose at its first scan)."""

    def __init__(
        self, context: Context, waypoints: list[tuple[float, float]], start_s: float = 1.0
    ) -> None:
        super().__init__("waypoint_driver", context, list(waypoints))
        self.start_ns = round(start_s * 1e9)

    @property
    def done(self) -> bool:
        return self.index >= len(self.waypoints)

    def holding(self) -> bool:
        return self.done or self.get_clock().now_ns() < self.start_ns


# --------------------------------------------------------------------------- one run
@dataclass
class LiveRun:
    quality: MapQuality
    gt: GroundTruth
    map_msg: Any
    waypoints_reached: int
    sim_seconds: float
    wall_seconds: float


def run_live(
    method: Method, *, waypoints: int | None, seed: int = 0, limit_s: float = 900.0
) -> LiveRun:
    """Drive the maze tour (its first ``waypoints`` cells, or all) under ``method``."""
    wall = time.perf_counter()
    ctx = Context()
    sim = Simulation(context=ctx, world="maze", robot="mybot", cameras=False, seed=seed)
    lidar = sim.config.lidars[0]
    z = float(lidar.mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=0.05, z_m=max(z, 0.01))
    tour = maze_tour(gt)
    if waypoints is not None:
        tour = tour[:waypoints]
    method.start(ctx)
    maps: list[Any] = []
    ctx.create_node("map_listener").create_subscription(mc.OccupancyGrid, "/map", maps.append, 1)
    driver = WaypointDriver(ctx, tour)
    ctx.spin_until_condition(lambda: driver.done, timeout_sec=limit_s)
    ctx.spin_for(6.0)  # let the last map out (map_update_interval 5 s, map_pub_period 2 s)
    sim_s = ctx.now().seconds
    assert maps, f"{method.name}: no /map published"
    spawn = sim.world_model.spawn
    quality = evaluate_map(grid_from_msg(maps[-1]), gt, prior=SE2(spawn.x, spawn.y, spawn.theta))
    ctx.shutdown()
    return LiveRun(quality, gt, maps[-1], driver.index, sim_s, time.perf_counter() - wall)


def _check(run: LiveRun, name: str, tmp_path: Path) -> None:
    q = run.quality
    png = write_overlay_png(
        tmp_path / f"{name}.png", grid_from_msg(run.map_msg), run.gt, q.alignment
    )
    print(
        f"\n{name}: {q.summary()}; {run.waypoints_reached} waypoints, {run.sim_seconds:.0f} sim s "
        f"in {run.wall_seconds:.1f} s; overlay {png}"
    )
    assert q.accuracy >= 0.95, q.summary()
    assert q.wall_distance_p95 <= 1.0, q.summary()
    assert q.known_cells > 3000


@pytest.mark.parametrize("name", sorted(METHODS))
def test_short_maze_drive_maps_the_walls(name: str, tmp_path: Path) -> None:
    run = run_live(METHODS[name], waypoints=8)
    _check(run, name, tmp_path)
    assert run.quality.coverage > 0.25


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(METHODS))
def test_whole_maze_tour_maps_the_maze(name: str, tmp_path: Path) -> None:
    run = run_live(METHODS[name], waypoints=None)
    _check(run, name, tmp_path)
    assert run.quality.coverage > 0.9
