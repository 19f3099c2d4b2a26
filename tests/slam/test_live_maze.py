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

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from benchmarks.amcl import MAZE_CELLS, GroundTruthDriver, free_line, maze_tour

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
    tour = maze_tour(free_line(gt.occupied, gt.origin_xy))
    assert len(set(tour)) == MAZE_CELLS**2, "the maze tour must reach every cell"
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
