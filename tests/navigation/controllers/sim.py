"""A closed loop for local planners: a world on a grid, navfn's plan, a rolling local
costmap, and a unicycle with acceleration limits (the controllers' own)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from roverlab.geometry import SE2
from roverlab.navigation.controllers import Velocity2D
from roverlab.navigation.costmap import CostmapParams, LayeredCostmap, make_layered_costmap
from roverlab.navigation.errors import ControllerError
from roverlab.navigation.planners import NavfnPlanner

RES = 0.05
ROBOT_RADIUS = 0.15
STATIC = {"name": "static_layer", "type": "costmap_2d::StaticLayer"}
INFLATION = {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"}


def field_world(seed: int, size_m: float = 6.0, boxes: int = 7) -> np.ndarray:
    """An OccupancyGrid array: a walled square with ``boxes`` random boxes (0.2..0.6 m),
    keeping the start (1, 1) and goal (size - 1, size - 1) corners free."""
    n = round(size_m / RES)
    g = np.zeros((n, n), np.int8)
    g[:2, :] = g[-2:, :] = g[:, :2] = g[:, -2:] = 100
    rng = np.random.default_rng(seed)
    placed = 0
    while placed < boxes:
        w, h = rng.uniform(0.2, 0.6, size=2)
        x, y = rng.uniform(1.0, size_m - 1.0 - w), rng.uniform(1.0, size_m - 1.0 - h)
        if min(math.hypot(x - 1, y - 1), math.hypot(x + w - size_m + 1, y + h - size_m + 1)) < 1.0:
            continue
        g[round(y / RES) : round((y + h) / RES), round(x / RES) : round((x + w) / RES)] = 100
        placed += 1
    return g


def costmaps(
    grid: np.ndarray,
    local_m: float = 3.0,
    *,
    footprint: Any = None,
    padding: float = 0.0,
    inflation_radius: float = 0.45,
) -> tuple[LayeredCostmap, LayeredCostmap]:
    common: dict[str, Any] = {"robot_radius": ROBOT_RADIUS, "footprint_padding": padding}
    if footprint is not None:
        common["footprint"] = footprint
    infl = {"inflation_radius": inflation_radius, "cost_scaling_factor": 5.0}
    g, _ = CostmapParams.from_ros(
        {**common, "plugins": [STATIC, INFLATION], "inflation_layer": infl}
    )
    glob = make_layered_costmap(g)
    lp, _ = CostmapParams.from_ros(
        {**common, "global_frame": "odom", "rolling_window": True, "width": local_m,
         "height": local_m, "resolution": RES, "plugins": [STATIC, INFLATION],
         "inflation_layer": infl}
    )  # fmt: skip
    local = make_layered_costmap(lp)
    for lc in (glob, local):
        lc.plugin("static_layer").incoming_map(  # type: ignore[attr-defined]
            grid, resolution=RES, origin_x=0.0, origin_y=0.0
        )
    glob.update_map(0.0, 0.0, 0.0)
    return glob, local


def collides(grid: np.ndarray, pose: SE2, radius: float = ROBOT_RADIUS) -> bool:
    """Whether a disc of ``radius`` at ``pose`` overlaps an occupied cell."""
    r = math.ceil(radius / RES) + 1
    cx, cy = int(pose.x / RES), int(pose.y / RES)
    ys, xs = np.mgrid[cy - r : cy + r + 1, cx - r : cx + r + 1]
    ok = (xs >= 0) & (ys >= 0) & (xs < grid.shape[1]) & (ys < grid.shape[0])
    occ = np.zeros_like(ok)
    occ[ok] = grid[ys[ok], xs[ok]] == 100
    # nearest point of each occupied cell to the disc centre
    nx = np.clip(pose.x, xs * RES, (xs + 1) * RES)
    ny = np.clip(pose.y, ys * RES, (ys + 1) * RES)
    return bool(np.any(occ & (np.hypot(nx - pose.x, ny - pose.y) < radius)))


def collides_polygon(grid: np.ndarray, pose: SE2, body: Any) -> bool:
    """Whether the polygon ``body`` at ``pose`` covers an occupied cell (outline and
    inside, sampled at a quarter cell)."""
    fp = np.asarray(body, dtype=np.float64)
    lo, hi = fp.min(axis=0), fp.max(axis=0)
    xs, ys = np.meshgrid(
        np.arange(lo[0], hi[0] + 1e-9, RES / 4), np.arange(lo[1], hi[1] + 1e-9, RES / 4)
    )
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    wx = pose.x + xs * c - ys * s
    wy = pose.y + xs * s + ys * c
    cx, cy = (wx / RES).astype(int), (wy / RES).astype(int)
    ok = (cx >= 0) & (cy >= 0) & (cx < grid.shape[1]) & (cy < grid.shape[0])
    return bool((~ok).any() or (grid[cy[ok], cx[ok]] == 100).any())


@dataclass
class Run:
    reached: bool
    collided: bool
    steps: int
    pose: SE2
    commands: list[Velocity2D] = field(default_factory=list)
    times_ms: list[float] = field(default_factory=list)
    failures: int = 0


def run(
    controller: Any,
    grid: np.ndarray,
    start: SE2,
    goal: SE2,
    *,
    acc: tuple[float, float] = (2.5, 3.2),
    dt: float = 0.1,
    max_steps: int = 1500,
    local_m: float = 3.0,
    body: Any = None,
    padding: float = 0.0,
    inflation_radius: float = 0.45,
) -> Run:
    """Drive ``controller`` from ``start`` to ``goal`` (plan by navfn on the global costmap).

    ``body``: the robot's polygon (None: a disc of :data:`ROBOT_RADIUS`), padded by
    ``padding`` in the costmaps; a collision is the body touching an occupied cell."""
    glob, local = costmaps(
        grid, local_m, footprint=body, padding=padding, inflation_radius=inflation_radius
    )
    plan = NavfnPlanner().plan(start, goal, glob.costmap)
    pose, twist = start, Velocity2D()
    out = Run(False, False, 0, pose)
    for step in range(max_steps):
        local.update_map(pose.x, pose.y, pose.theta)
        if controller.is_goal_reached(pose, twist):
            out.reached = True
            break
        t0 = time.perf_counter()
        try:
            cmd = controller.compute_velocity(pose, twist, plan, local.costmap)
        except ControllerError:
            cmd = Velocity2D()
            out.failures += 1
        out.times_ms.append((time.perf_counter() - t0) * 1000)
        out.commands.append(cmd)
        vx = twist.vx + max(-acc[0] * dt, min(acc[0] * dt, cmd.vx - twist.vx))
        wz = twist.wz + max(-acc[1] * dt, min(acc[1] * dt, cmd.wz - twist.wz))
        twist = Velocity2D(vx, 0.0, wz)
        pose = SE2(
            pose.x + vx * math.cos(pose.theta) * dt,
            pose.y + vx * math.sin(pose.theta) * dt,
            pose.theta + wz * dt,
        )
        out.collided |= collides(grid, pose) if body is None else collides_polygon(grid, pose, body)
        out.steps = step + 1
    out.pose = pose
    return out
