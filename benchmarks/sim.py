"""Simulator benchmark: real-time factor and lidar rays/s, roverlab beside IR-SIM.

    python benchmarks/sim.py [--seconds S] [--camera-seconds S] [--profile]

mybot in the bundled ``maze`` world, driven by a constant ``/cmd_vel`` (0.2 m/s, 0.3 rad/s,
re-sent at 10 Hz; it circles, touches walls and slides along them), headless, sim
clock as fast as the CPU allows. Prints, one figure per line, after the machine line:

1. real-time factor (sim s / wall s) with lidar + IMU + odometry only (the cameras taken
   out of the robot's sensor config), an in-process subscriber counting /scan, /imu and
   /odom so every message is built and delivered; 2 s of warm-up (numba compile) are not
   timed (target >= 1000x);
   Then the same with a subscriber on /tf as well: the simulator's odometry transform
   and robot_state_publisher's wheel transforms are built only while someone reads
   /tf (in this process or another), so case 1 does not build them;
2. the same with mybot's 640x480 camera at 30 Hz and a subscriber on /image_raw too
   (target >= 50x);
3. lidar rays/s: ``cast_2d`` timed alone in a tight loop over the scan poses of run 1,
   with mybot's 360 beams and with 720 (target >= 2,000,000 rays/s);
4. the same scenario in IR-SIM (the ``ir-sim`` package, when installed): a diff-drive
   circle of radius 0.15 m with a 360-beam, 2 pi, 12 m ``lidar2d``, the maze's wall boxes
   as static polygon obstacles, rigid-body ("contact") collisions, the same constant
   command; real-time factor with step_time 1/7 s (its lidar runs every step, so at
   mybot's 7 Hz) over S sim s and 0.01 s over S/4, its lidar
   rays/s (``Lidar2D.step`` timed alone over the run's poses), and the ratios
   roverlab / IR-SIM (target >= 12 at step_time 1/7 s), per wall second and per CPU
   second (the latter steadier when other processes share the machine). Without IR-SIM
   that part is skipped with a line saying so.

``--profile`` also runs case 1 under cProfile and prints the ten functions with the most
own time.
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import dataclasses
import io
import math
import os
import platform
import pstats
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.core import Context
from roverlab.geometry import rpy_from_quat
from roverlab.msgs import Twist
from roverlab.raycast import Scene
from roverlab.raycast.lidar import cast_2d, cast_2d_many
from roverlab.sim.app import Simulation
from roverlab.sim.node import SimulatorNode
from roverlab.world import World, load_world
from roverlab.world.model import BoxShape, CylinderShape

WORLD = "maze"
ROBOT = "mybot"
WARMUP_S = 2.0
CMD_V = 0.2  # m/s
CMD_W = 0.3  # rad/s
CMD_PERIOD_S = 0.1
LIDAR_BEAMS = 360
LIDAR_RANGE_M = 12.0
LIDAR_RATE_HZ = 7.0
ROBOT_RADIUS_M = 0.15
# IR-SIM's rigid-body contacts: its robot slides along the walls and keeps going, as
# roverlab's does ("stop" would freeze it for good at its first touch, ~6 s in)
COLLISION_MODE = "contact"
REPEATS = 3


def machine_line() -> str:
    model = "unknown CPU"
    with contextlib.suppress(OSError), open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return f"machine: {os.cpu_count()} cores, {model}, Python {platform.python_version()}"


# ---------------------------------------------------------------------------- roverlab
@dataclasses.dataclass
class RoverlabRun:
    context: Context
    simulator: SimulatorNode
    counts: dict[str, int]
    scan_poses: list[tuple[float, float, float, float]]


def build_roverlab(world: World, *, cameras: bool, tf_reader: bool = False) -> RoverlabRun:
    """The simulation ``roverlab sim`` runs, with the cameras optional; ``tf_reader`` adds
    a subscriber on /tf (the odometry and wheel transforms are built only when someone
    reads them)."""
    ctx = Context()
    sim = Simulation(context=ctx, world=world, robot=ROBOT, cameras=cameras)
    simulator, config = sim.simulator, sim.config

    counts = {"/scan": 0, "/imu": 0, "/odom": 0, "/image_raw": 0}
    scan_poses: list[tuple[float, float, float, float]] = []
    lidar = config.lidars[0]
    node = ctx.create_node("counter")

    def on_scan(msg: Any) -> None:
        counts["/scan"] += 1
        # the scan was cast at this very sim time: the sensor pose now is the one it used
        x, y, z, yaw, _ = simulator.sensor_pose(lidar.mount)
        scan_poses.append((x, y, z, yaw))

    def counter(topic: str) -> Any:
        def cb(msg: Any) -> None:
            counts[topic] += 1

        return cb

    node.create_subscription("sensor_msgs/msg/LaserScan", "/scan", on_scan, 100)
    node.create_subscription("sensor_msgs/msg/Imu", "/imu", counter("/imu"), 100)
    node.create_subscription("nav_msgs/msg/Odometry", "/odom", counter("/odom"), 100)
    if cameras:
        node.create_subscription("sensor_msgs/msg/Image", "/image_raw", counter("/image_raw"), 10)
    if tf_reader:
        counts["/tf"] = 0
        node.create_subscription("tf2_msgs/msg/TFMessage", "/tf", counter("/tf"), 100)
    pub = node.create_publisher(Twist, "/cmd_vel", 10)
    cmd = Twist(linear_x=CMD_V, angular_z=CMD_W)
    node.create_timer(CMD_PERIOD_S, lambda: pub.publish(cmd))
    return RoverlabRun(ctx, simulator, counts, scan_poses)


CHUNK_S = 10.0  # sim seconds per timed slice


def time_roverlab(
    world: World,
    seconds: float,
    *,
    cameras: bool,
    tf_reader: bool = False,
    profile: cProfile.Profile | None = None,
) -> tuple[float, float, float, RoverlabRun]:
    """Real-time factors over ``seconds`` after warm-up, timed in slices of ``CHUNK_S``.

    Returns (median slice, best slice, per CPU second over the whole run). This machine is
    a VM whose host lends it CPU unevenly (steal time): the same code runs 1.6x slower
    in some minutes, so the median of slices and the best slice say more than one total.
    """
    run = build_roverlab(world, cameras=cameras, tf_reader=tf_reader)
    run.context.spin_for(WARMUP_S)
    for k in run.counts:
        run.counts[k] = 0
    run.scan_poses.clear()
    if profile is not None:
        profile.enable()
    slices: list[float] = []
    c0 = time.process_time()
    done = 0.0
    while done < seconds - 1e-9:
        chunk = min(CHUNK_S, seconds - done)
        t0 = time.perf_counter()
        run.context.spin_for(chunk)
        slices.append(chunk / (time.perf_counter() - t0))
        done += chunk
    cpu = time.process_time() - c0
    if profile is not None:
        profile.disable()
    run.context.shutdown()
    return float(np.median(slices)), max(slices), seconds / cpu, run


def fmt_counts(counts: dict[str, int], seconds: float) -> str:
    return ", ".join(f"{t} {n} ({n / seconds:.1f} Hz)" for t, n in counts.items() if n)


def path_note(poses: Sequence[Sequence[float]]) -> str:
    """How far the robot drove (from its sampled poses) and where it ended."""
    xy = np.array([p[:2] for p in poses])
    if len(xy) == 0:
        return "no poses"
    length = float(np.hypot(*np.diff(xy, axis=0).T).sum())
    return f"robot drove {length:.1f} m, ended at ({xy[-1, 0]:.2f}, {xy[-1, 1]:.2f})"


def rays_per_second(
    scene: Scene, poses: list[tuple[float, float, float, float]], beams: int
) -> float:
    """``cast_2d`` alone over ``poses`` (x, y, z, yaw), ``beams`` over 0..2 pi; best of 3."""
    rel = np.linspace(0.0, 2.0 * math.pi, beams)
    fans = [(x, y, z, rel + yaw) for x, y, z, yaw in poses]
    cast_2d(scene, *fans[0][:3], fans[0][3], LIDAR_RANGE_M)  # compiled already; be sure
    best = math.inf
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        for x, y, z, angles in fans:
            cast_2d(scene, x, y, z, angles, LIDAR_RANGE_M)
        best = min(best, time.perf_counter() - t0)
    return len(fans) * beams / best


def rays_per_second_batch(
    scene: Scene, poses: list[tuple[float, float, float, float]], beams: int
) -> float:
    """The same rays as one ``cast_2d_many`` call (no per-scan Python overhead)."""
    rel = np.linspace(0.0, 2.0 * math.pi, beams)
    arr = np.array([(x, y, yaw) for x, y, _, yaw in poses])
    z = poses[0][2]
    cast_2d_many(scene, arr[:1], z, rel, LIDAR_RANGE_M)
    best = math.inf
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        cast_2d_many(scene, arr, z, rel, LIDAR_RANGE_M)
        best = min(best, time.perf_counter() - t0)
    return len(poses) * beams / best


# ---------------------------------------------------------------------------- IR-SIM
def box_polygon(box: BoxShape) -> list[list[float]]:
    """The box's footprint on the floor, counter-clockwise, in world coordinates."""
    tx, ty, _ = box.transform.translation
    _, _, yaw = rpy_from_quat(box.transform.rotation)
    hx, hy = box.size[0] / 2, box.size[1] / 2
    c, s = math.cos(yaw), math.sin(yaw)
    return [
        [round(tx + c * px - s * py, 6), round(ty + s * px + c * py, 6)]
        for px, py in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))
    ]


def irsim_yaml(world: World, step_time: float, directory: Path) -> tuple[Path, int]:
    """An IR-SIM world file for the scenario; returns its path and the obstacle count.

    Wall boxes become static ``polygon`` obstacles (their floor footprint in world
    coordinates, obstacle state at the origin), upright cylinders static ``circle``s.
    Spheres, polylines and posters (none in the maze) are left out.
    """
    import yaml

    obstacles: list[dict[str, Any]] = []
    for shape in world.shapes:
        if isinstance(shape, BoxShape):
            geom: dict[str, Any] = {"name": "polygon", "vertices": box_polygon(shape)}
            state = [0.0, 0.0, 0.0]
        elif isinstance(shape, CylinderShape):
            geom = {"name": "circle", "radius": float(shape.radius)}
            tx, ty, _ = shape.transform.translation
            state = [float(tx), float(ty), 0.0]
        else:
            continue
        obstacles.append({"shape": geom, "state": state, "kinematics": {"name": "static"}})
    (x0, y0), (x1, y1) = world_bounds(world)
    doc = {
        "world": {
            "height": y1 - y0,
            "width": x1 - x0,
            "offset": [x0, y0],
            "step_time": step_time,
            "collision_mode": COLLISION_MODE,
        },
        "robot": [
            {
                "kinematics": {"name": "diff"},
                "shape": {"name": "circle", "radius": ROBOT_RADIUS_M},
                "state": [0.0, 0.0, 0.0],
                "vel_max": [1.0, 1.0],
                "sensors": [
                    {
                        "name": "lidar2d",
                        "range_min": 0.12,
                        "range_max": LIDAR_RANGE_M,
                        "angle_range": 2.0 * math.pi,
                        "number": LIDAR_BEAMS,
                    }
                ],
            }
        ],
        "obstacle": obstacles,
    }
    path = directory / f"maze_{step_time:.4f}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path, len(obstacles)


def world_bounds(world: World) -> tuple[tuple[float, float], tuple[float, float]]:
    """The xy extent of the world's walls plus a 1 m margin."""
    pts = np.array([p for s in world.shapes if isinstance(s, BoxShape) for p in box_polygon(s)])
    lo = np.floor(pts.min(axis=0)) - 1.0
    hi = np.ceil(pts.max(axis=0)) + 1.0
    return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))


def time_irsim(
    irsim: Any, world: World, step_time: float, seconds: float, directory: Path
) -> tuple[float, float, float, int, list[np.ndarray]]:
    """Real-time factors (per wall s, per CPU s), lidar rays/s, obstacle count, poses."""
    path, n_obstacles = irsim_yaml(world, step_time, directory)
    env = irsim.make(str(path), headless=True, log_level="ERROR", seed=0)
    action = np.array([[CMD_V], [CMD_W]])
    warm = max(1, round(WARMUP_S / step_time))
    for _ in range(warm):
        env.step(action)
    steps = max(1, round(seconds / step_time))
    robot = env.robot
    states: list[np.ndarray] = []
    t0, c0 = time.perf_counter(), time.process_time()
    for _ in range(steps):
        env.step(action)
        states.append(robot.state[0:3].copy())
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    sim_s = steps * step_time
    irsim_rays = irsim_lidar_rays_per_second(robot.sensors[0], states)
    env.end(0)
    return sim_s / wall, sim_s / cpu, irsim_rays, n_obstacles, states


def paired_ratio(
    irsim: Any, world: World, seconds: float, directory: Path
) -> tuple[float, float, float]:
    """roverlab / IR-SIM real-time factor over slices taken in turn, pair by pair.

    The host lends this VM its CPU unevenly, and the sections above run one after the other
    (a minute apart), so their ratio carries the host's drift. Here case 1 and IR-SIM (step
    1/7 s) are built once each and advanced ``CHUNK_S`` sim seconds at a time alternately,
    the order swapped every round; each pair's ratio is taken within a fraction of a
    second. Returns (median, first quartile, third quartile) of the pair ratios.
    """
    run = build_roverlab(world, cameras=False)
    run.context.spin_for(WARMUP_S)
    path, _ = irsim_yaml(world, 1.0 / LIDAR_RATE_HZ, directory)
    env = irsim.make(str(path), headless=True, log_level="ERROR", seed=0)
    action = np.array([[CMD_V], [CMD_W]])
    steps = round(CHUNK_S * LIDAR_RATE_HZ)
    for _ in range(round(WARMUP_S * LIDAR_RATE_HZ)):
        env.step(action)

    def rover() -> float:
        t0 = time.perf_counter()
        run.context.spin_for(CHUNK_S)
        return CHUNK_S / (time.perf_counter() - t0)

    def ir() -> float:
        t0 = time.perf_counter()
        for _ in range(steps):
            env.step(action)
        return steps / LIDAR_RATE_HZ / (time.perf_counter() - t0)

    ratios = []
    for k in range(max(1, round(seconds / CHUNK_S))):
        if k % 2:
            b = ir()
            a = rover()
        else:
            a = rover()
            b = ir()
        ratios.append(a / b)
    run.context.shutdown()
    env.end(0)
    q1, med, q3 = np.percentile(ratios, [25, 50, 75])
    return float(med), float(q1), float(q3)


def irsim_lidar_rays_per_second(lidar: Any, states: list[np.ndarray]) -> float:
    """``Lidar2D.step`` alone (broad phase, ray cast, beam geometry) over ``states``."""
    best = math.inf
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        for st in states:
            lidar.step(st)
        best = min(best, time.perf_counter() - t0)
    return len(states) * lidar.number / best


def import_irsim() -> Any:
    """``irsim``, imported quietly (it reports its matplotlib backend probing on stdout)."""
    import matplotlib

    matplotlib.use("Agg")
    with contextlib.redirect_stdout(io.StringIO()):
        import irsim
    return irsim


# ---------------------------------------------------------------------------- main
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=120.0, help="sim seconds of run 1")
    ap.add_argument(
        "--camera-seconds", type=float, default=30.0, help="sim seconds of the camera run"
    )
    ap.add_argument("--profile", action="store_true", help="cProfile case 1 (top 10 tottime)")
    args = ap.parse_args()
    seconds = args.seconds
    print(machine_line(), flush=True)
    world = load_world(WORLD)

    # 1. lidar + IMU + odometry
    rtf_lidar, best_lidar, cpu_lidar, run1 = time_roverlab(world, seconds, cameras=False)
    print(
        f"roverlab RTF, {ROBOT} in {WORLD}, lidar+IMU+odometry (no camera), "
        f"{seconds:g} sim s: median {rtf_lidar:.0f}x, best {best_lidar:.0f}x of "
        f"{CHUNK_S:g} s slices (target >= 1000x; per CPU second {cpu_lidar:.0f}x); "
        f"received {fmt_counts(run1.counts, seconds)}; "
        f"{path_note(run1.scan_poses)}",
        flush=True,
    )
    # 1b. the same with a /tf reader (nobody reads /tf in case 1, so no transform is built)
    tf_s = seconds / 2
    rtf_tf, best_tf, cpu_tf, run1b = time_roverlab(world, tf_s, cameras=False, tf_reader=True)
    print(
        f"roverlab RTF, case 1 with a /tf subscriber too, {tf_s:g} sim s: median "
        f"{rtf_tf:.0f}x, best {best_tf:.0f}x (per CPU second {cpu_tf:.0f}x); "
        f"received {fmt_counts(run1b.counts, tf_s)}",
        flush=True,
    )

    # 2. with the 640x480 camera
    cam_s = args.camera_seconds
    rtf_cam, best_cam, cpu_cam, run2 = time_roverlab(world, cam_s, cameras=True)
    print(
        f"roverlab RTF, {ROBOT} in {WORLD}, with the 640x480 30 Hz camera, "
        f"{cam_s:g} sim s: median {rtf_cam:.1f}x, best {best_cam:.1f}x "
        f"(target >= 50x; per CPU second {cpu_cam:.1f}x); "
        f"received {fmt_counts(run2.counts, cam_s)}",
        flush=True,
    )

    # 3. lidar rays/s over run 1's scan poses
    scene = run1.simulator.scene
    poses = run1.scan_poses
    rays: dict[int, float] = {}
    for beams in (LIDAR_BEAMS, 720):
        rays[beams] = rays_per_second(scene, poses, beams)
        batch = rays_per_second_batch(scene, poses, beams)
        print(
            f"roverlab cast_2d rays/s, {beams} beams x {len(poses)} scan poses of run 1: "
            f"{rays[beams]:,.0f} (target >= 2,000,000); as one cast_2d_many call: {batch:,.0f}",
            flush=True,
        )

    # 4. IR-SIM
    try:
        irsim = import_irsim()
    except Exception as exc:  # ImportError, or an import-time failure of its own
        print(
            f"IR-SIM: not importable ({exc}); `pip install -e '.[bench]'` (make bench does) "
            "to compare. Skipped."
        )
    else:
        version = getattr(irsim, "__version__", "?")
        with tempfile.TemporaryDirectory(prefix="roverlab-bench-irsim-") as tmp:
            for step_time, sim_s in ((1.0 / LIDAR_RATE_HZ, seconds), (0.01, seconds / 4)):
                rtf_i, cpu_i, rays_i, n_obs, states = time_irsim(
                    irsim, world, step_time, sim_s, Path(tmp)
                )
                label = "1/7" if step_time > 0.1 else f"{step_time:g}"
                xy = [(float(st[0, 0]), float(st[1, 0])) for st in states]
                print(
                    f"IR-SIM {version} RTF, diff-drive circle r={ROBOT_RADIUS_M} m + "
                    f"{LIDAR_BEAMS}-beam lidar2d, {n_obs} maze wall polygons, {COLLISION_MODE} "
                    f"collisions, step_time {label} s ({1 / step_time:g} Hz lidar and "
                    f"kinematics), {sim_s:g} sim s: {rtf_i:.1f}x (per CPU second {cpu_i:.1f}x); "
                    f"roverlab/IR-SIM RTF ratio (lidar+odometry case): {rtf_lidar / rtf_i:.1f}"
                    f"{' (target >= 12)' if step_time > 0.1 else ''}, per CPU second "
                    f"{cpu_lidar / cpu_i:.1f}; "
                    f"{path_note(xy)}",
                    flush=True,
                )
                print(
                    f"IR-SIM {version} lidar2d rays/s ({LIDAR_BEAMS} beams, Lidar2D.step "
                    f"alone over {len(states)} poses, step_time {label} s): {rays_i:,.0f}; "
                    f"roverlab/IR-SIM rays/s ratio: {rays[LIDAR_BEAMS] / rays_i:.0f}",
                    flush=True,
                )
            med, q1, q3 = paired_ratio(irsim, world, seconds, Path(tmp))
            print(
                f"roverlab/IR-SIM RTF ratio, case 1 and step_time 1/7 s in alternate "
                f"{CHUNK_S:g} s slices ({seconds:g} sim s each): median {med:.1f} "
                f"(quartiles {q1:.1f}-{q3:.1f}; target >= 12)",
                flush=True,
            )

    if args.profile:
        prof = cProfile.Profile()
        time_roverlab(world, seconds, cameras=False, profile=prof)
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("tottime").print_stats(10)
        print(f"cProfile of case 1 ({seconds:g} sim s), top 10 by tottime:")
        print(out.getvalue().rstrip())


if __name__ == "__main__":
    main()
