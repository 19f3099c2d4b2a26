"""Navigation speed: costmap update, global planners, local planners (per call).

    python benchmarks/nav.py [--seed N] [--plans N] [--goals N]

Worlds are the bundled ones rasterised at 0.05 m (``World.occupancy``); the robot is
mybot-sized (0.15 m radius), single-threaded, after warm-up (compilation excluded).
Figures, one per line, median and p99 of the per-call wall time:

- costmap update: a 720-beam, 12 m laser scan (cast in the maze by the shared ray
  caster) into a 10 m x 10 m rolling window at 0.05 m (obstacle layer marking and
  clearing, inflation 0.5 m), along a drive through the maze;
- navfn and global_planner ``plan`` between seeded random free cells (>= 2 m apart,
  connected to the spawn) of the maze and the office, global costmap static + inflation;
- DWA and TEB ``compute_velocity`` in closed loop (a unicycle with acceleration limits)
  over seeded goals in the maze, 3 m rolling local costmap; targets p99 <= 10 ms (DWA)
  and <= 25 ms (TEB) on one core; success and collisions are printed too.

``--barn DIR --barn-worlds 1,100,250`` adds TEB's control cycle (thread CPU time) in BARN
worlds (``DIR/world_N.world``): a Jackal-sized polygon footprint padded 0.02 m, a 10 m
rolling local costmap (every lethal cell a point obstacle), from BARN's start towards its
goal at ``--barn-speed`` m/s for at most 100 s; target p99 <= 50 ms (a 20 Hz loop).
"""

from __future__ import annotations

import argparse
import math
import platform
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy import ndimage

from roverlab.geometry import SE2
from roverlab.navigation.controllers import (
    DWAParams,
    DWAPlanner,
    TebParams,
    TebPlanner,
    Velocity2D,
)
from roverlab.navigation.costmap import CostmapParams, LayeredCostmap, make_layered_costmap
from roverlab.navigation.errors import ControllerError, PlannerError
from roverlab.navigation.planners import GlobalPlanner, NavfnPlanner
from roverlab.raycast import cast_2d
from roverlab.world import load_world

RES = 0.05
RADIUS = 0.15
STATIC = {"name": "static_layer", "type": "costmap_2d::StaticLayer"}
OBSTACLE = {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"}
INFLATION = {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"}
INFL = {"inflation_radius": 0.5, "cost_scaling_factor": 5.0}
DWA = {
    "max_vel_x": 0.26, "min_vel_x": 0.0, "max_vel_y": 0.0, "min_vel_y": 0.0,
    "max_vel_trans": 0.26, "min_vel_trans": 0.05, "max_vel_theta": 1.5, "min_vel_theta": 0.4,
    "acc_lim_x": 2.5, "acc_lim_y": 0.0, "acc_lim_theta": 3.2, "xy_goal_tolerance": 0.1,
    "yaw_goal_tolerance": 0.17, "sim_time": 1.5, "vx_samples": 20, "vy_samples": 1,
    "vth_samples": 40, "controller_frequency": 10.0, "occdist_scale": 0.02,
    "goal_distance_bias": 20.0,
}  # fmt: skip
TEB = {
    "max_vel_x": 0.26, "max_vel_x_backwards": 0.1, "max_vel_theta": 1.5, "acc_lim_x": 2.5,
    "acc_lim_theta": 3.2, "min_obstacle_dist": 0.1, "inflation_dist": 0.3,
    "footprint_model": {"type": "circular", "radius": RADIUS}, "xy_goal_tolerance": 0.1,
    "yaw_goal_tolerance": 0.17, "weight_kinematics_forward_drive": 10.0,
}  # fmt: skip


def stats(ms: list[float]) -> str:
    a = np.asarray(ms)
    return f"median {np.median(a):.2f} ms, p99 {np.percentile(a, 99):.2f} ms ({len(a)} calls)"


def world_grid(name: str) -> tuple[np.ndarray, tuple[float, float], Any]:
    world = load_world(name)
    occ, origin = world.occupancy(RES, 0.0, 2.0)
    return np.where(occ, 100, 0).astype(np.int8), origin, world


def layered(
    values: dict[str, Any], grid: np.ndarray, origin: tuple[float, float]
) -> LayeredCostmap:
    p, _ = CostmapParams.from_ros({"robot_radius": RADIUS, "footprint_padding": 0.0, **values})
    lc = make_layered_costmap(p)
    for layer in lc.plugins:
        if layer.name == "static_layer":
            layer.incoming_map(grid, resolution=RES, origin_x=origin[0], origin_y=origin[1])  # type: ignore[attr-defined]
    return lc


def free_cells(lc: LayeredCostmap, rng: np.random.Generator, n: int) -> list[SE2]:
    """``n`` random poses on zero-cost cells connected to the spawn (0, 0)."""
    cm = lc.costmap
    labels, _ = ndimage.label(cm.costs == 0)
    spawn = cm.world_to_map(0.0, 0.0)
    assert spawn is not None
    ys, xs = np.nonzero(labels == labels[spawn[1], spawn[0]])
    out = []
    while len(out) < n:
        k = int(rng.integers(len(xs)))
        x, y = cm.map_to_world(int(xs[k]), int(ys[k]))
        out.append(SE2(x, y, float(rng.uniform(-math.pi, math.pi))))
    return out


def bench_costmap(seed: int) -> None:
    grid, origin, world = world_grid("maze")
    scene = world.to_scene()
    lc = layered(
        {"global_frame": "odom", "rolling_window": True, "width": 10.0, "height": 10.0,
         "resolution": RES, "plugins": [OBSTACLE, INFLATION], "inflation_layer": INFL,
         "obstacle_layer": {"observation_sources": "scan",
                            "scan": {"data_type": "LaserScan", "marking": True,
                                     "clearing": True, "obstacle_range": 5.0,
                                     "raytrace_range": 6.0}}},
        grid, origin,
    )  # fmt: skip
    glob = layered({"plugins": [STATIC, INFLATION], "inflation_layer": INFL}, grid, origin)
    glob.update_map(0.0, 0.0, 0.0)
    rng = np.random.default_rng(seed)
    goals = free_cells(glob, rng, 4)
    poses: list[SE2] = []
    start = SE2(0.0, 0.0, 0.0)
    for g in goals:
        try:
            path = NavfnPlanner().plan(start, g, glob.costmap)
        except PlannerError:
            continue
        for i in range(0, len(path) - 2, 3):
            yaw = math.atan2(path[i + 2, 1] - path[i, 1], path[i + 2, 0] - path[i, 0])
            poses.append(SE2(float(path[i, 0]), float(path[i, 1]), yaw))
        start = g
    angles = np.linspace(0.0, 2 * math.pi, 720, endpoint=False)
    obstacle = lc.plugin("obstacle_layer")
    ms = []
    for k, pose in enumerate(poses):
        ranges = cast_2d(scene, pose.x, pose.y, 0.1, angles + pose.theta, 12.0)
        keep = np.isfinite(ranges) & (ranges < 12.0)
        r = np.where(keep, ranges, 12.0 - 1e-4)
        a = angles + pose.theta
        pts = np.column_stack(
            [pose.x + r * np.cos(a), pose.y + r * np.sin(a), np.full(len(r), 0.1)]
        )
        t0 = time.perf_counter()
        obstacle.add_observation("scan", [pose.x, pose.y, 0.1], pts, k * 0.1, k * 0.1)  # type: ignore[attr-defined]
        lc.update_map(pose.x, pose.y, pose.theta, k * 0.1)
        if k > 0:
            ms.append((time.perf_counter() - t0) * 1000)
    print(f"costmap update, 720-beam scan into a 10 m rolling window + inflation: {stats(ms)}")


def bench_planners(seed: int, n: int) -> None:
    for name in ("maze", "office"):
        grid, origin, _ = world_grid(name)
        glob = layered({"plugins": [STATIC, INFLATION], "inflation_layer": INFL}, grid, origin)
        glob.update_map(0.0, 0.0, 0.0)
        rng = np.random.default_rng(seed)
        pairs = []
        while len(pairs) < n:
            a, b = free_cells(glob, rng, 2)
            if math.hypot(a.x - b.x, a.y - b.y) >= 2.0:
                pairs.append((a, b))
        cm = glob.costmap
        for label, planner in (("navfn", NavfnPlanner()), ("global_planner", GlobalPlanner())):
            ms, failed = [], 0
            planner.plan(pairs[0][0], pairs[0][1], cm)
            for a, b in pairs:
                t0 = time.perf_counter()
                try:
                    planner.plan(a, b, cm)
                except PlannerError:
                    failed += 1
                ms.append((time.perf_counter() - t0) * 1000)
            print(
                f"{label} plan, {name} {cm.size_x}x{cm.size_y} cells: {stats(ms)}, "
                f"{failed} without a path"
            )


def drive(make: Callable[[], Any], seed: int, goals: int) -> tuple[list[float], int, int, int]:
    grid, origin, world = world_grid("maze")
    glob = layered({"plugins": [STATIC, INFLATION], "inflation_layer": INFL}, grid, origin)
    glob.update_map(0.0, 0.0, 0.0)
    local = layered(
        {"global_frame": "odom", "rolling_window": True, "width": 3.0, "height": 3.0,
         "resolution": RES, "plugins": [STATIC, INFLATION], "inflation_layer": INFL},
        grid, origin,
    )  # fmt: skip
    rng = np.random.default_rng(seed)
    pose, twist, dt = SE2(0.0, 0.0, 0.0), Velocity2D(), 0.1
    ms: list[float] = []
    reached = collisions = 0
    for goal in free_cells(glob, rng, goals):
        try:
            plan = NavfnPlanner().plan(pose, goal, glob.costmap)
        except PlannerError:
            continue
        ctrl = make()
        for _ in range(4000):
            local.update_map(pose.x, pose.y, pose.theta)
            if ctrl.is_goal_reached(pose, twist):
                reached += 1
                break
            t0 = time.perf_counter()
            try:
                cmd = ctrl.compute_velocity(pose, twist, plan, local.costmap)
            except ControllerError:
                cmd = Velocity2D()
            ms.append((time.perf_counter() - t0) * 1000)
            vx = twist.vx + max(-0.25, min(0.25, cmd.vx - twist.vx))
            wz = twist.wz + max(-0.32, min(0.32, cmd.wz - twist.wz))
            twist = Velocity2D(vx, 0.0, wz)
            pose = SE2(pose.x + vx * math.cos(pose.theta) * dt,
                       pose.y + vx * math.sin(pose.theta) * dt, pose.theta + wz * dt)  # fmt: skip
            if world.footprint_collides(pose.x, pose.y, pose.theta, RADIUS, z_max=0.3):
                collisions += 1
                break
    return ms[1:], reached, goals, collisions


def bench_controllers(seed: int, goals: int) -> None:
    dwa_p = DWAParams.from_ros(DWA)[0]
    teb_p = TebParams.from_ros(TEB)[0]
    from roverlab.navigation.costmap import footprint_from_radius

    foot = footprint_from_radius(RADIUS)
    for label, make, target in (
        ("DWA", lambda: DWAPlanner(dwa_p, footprint=foot), 10.0),
        ("TEB", lambda: TebPlanner(teb_p, footprint=foot), 25.0),
    ):
        ms, reached, n, collisions = drive(make, seed, goals)
        p99 = float(np.percentile(ms, 99))
        print(
            f"{label} compute_velocity, maze, 3 m local costmap: {stats(ms)} "
            f"[target p99 <= {target:g} ms: {'met' if p99 <= target else 'NOT met'}]; "
            f"{reached}/{n} goals reached, {collisions} collisions"
        )


JACKAL = [[-0.21, -0.165], [-0.21, 0.165], [0.21, 0.165], [0.21, -0.165]]


def bench_teb_barn(folder: str, worlds: str, speed: float) -> None:
    teb_p, _ = TebParams.from_ros(
        {"max_vel_x": speed, "max_vel_x_backwards": 0.2, "max_vel_theta": 1.57,
         "acc_lim_x": 2.0, "acc_lim_theta": 3.0, "min_obstacle_dist": 0.25,
         "inflation_dist": 0.55, "footprint_model": {"type": "polygon", "vertices": JACKAL},
         "xy_goal_tolerance": 0.3, "yaw_goal_tolerance": 3.0, "free_goal_vel": True,
         "enable_homotopy_class_planning": False}
    )  # fmt: skip
    common = {"footprint": JACKAL, "footprint_padding": 0.02}
    infl = {"inflation_radius": 0.3, "cost_scaling_factor": 10.0}
    worst = 0.0
    for n in worlds.split(","):
        world = load_world(f"{folder}/world_{n}.world")
        occ, origin = world.occupancy(RES, 0.05, 0.5, bounds=(-7.0, 0.0, 3.0, 16.0), padding=0.0)
        grid = np.where(occ, 100, 0).astype(np.int8)
        glob = layered({**common, "plugins": [STATIC, INFLATION], "inflation_layer": infl},
                       grid, origin)  # fmt: skip
        glob.update_map(0.0, 0.0, 0.0)
        local = layered(
            {**common, "global_frame": "odom", "rolling_window": True, "width": 10.0,
             "height": 10.0, "resolution": RES, "plugins": [STATIC, INFLATION],
             "inflation_layer": infl},
            grid, origin,
        )  # fmt: skip
        start, goal = SE2(-2.25, 3.0, 1.57), SE2(-2.25, 13.0, 1.57)
        plan = NavfnPlanner().plan(start, goal, glob.costmap)
        teb = TebPlanner(teb_p, footprint=local.footprint)
        pose, twist, dt, ms = start, Velocity2D(), 0.05, []
        for _ in range(2000):
            local.update_map(pose.x, pose.y, pose.theta)
            if math.hypot(pose.x - goal.x, pose.y - goal.y) < 1.0:
                break
            t0 = time.thread_time()
            try:
                twist = teb.compute_velocity(pose, twist, plan, local.costmap)
            except ControllerError:
                twist = Velocity2D()
            ms.append((time.thread_time() - t0) * 1000)
            pose = SE2(pose.x + twist.vx * math.cos(pose.theta) * dt,
                       pose.y + twist.vx * math.sin(pose.theta) * dt,
                       pose.theta + twist.wz * dt)  # fmt: skip
        p99 = float(np.percentile(ms[5:], 99))
        worst = max(worst, p99)
        reached = math.hypot(pose.x - goal.x, pose.y - goal.y) < 1.0
        print(f"TEB cycle, BARN world_{n} at {speed:g} m/s: {stats(ms[5:])} (CPU), "
              f"goal {'reached' if reached else 'not reached'}")  # fmt: skip
    print(f"TEB cycle, BARN: worst p99 {worst:.1f} ms [target <= 50 ms: "
          f"{'met' if worst <= 50 else 'NOT met'}]")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--plans", type=int, default=30)
    ap.add_argument("--goals", type=int, default=4)
    ap.add_argument("--barn", default=None, help="a folder of BARN's world_N.world files")
    ap.add_argument("--barn-worlds", default="1,100,250")
    ap.add_argument("--barn-speed", type=float, default=0.5)
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}")
    if args.barn:
        bench_teb_barn(args.barn, args.barn_worlds, args.barn_speed)
        return
    bench_costmap(args.seed)
    bench_planners(args.seed, args.plans)
    bench_controllers(args.seed, args.goals)


if __name__ == "__main__":
    main()
