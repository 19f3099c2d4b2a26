"""amcl: filter update speed, offline speed on intel, and the simulator acceptance runs.

    python benchmarks/amcl.py [--skip-sim] [--skip-log] [--seeds 10] [--minutes 10]

1. One filter update (motion model + likelihood-field weighting + KLD resampling) on the
   intel map, timed over many updates: 5,000 particles x 360 beams (target median
   <= 5 ms) and amcl's defaults (30 beams, KLD-adaptive count <= 5,000; <= 1 ms), one core.
2. ``roverlab amcl run`` on intel with default parameters as a ratio to real time
   (target >= 50x); the map comes from ``roverlab slam run --method graph`` (made once,
   kept in a temporary folder).
3. The simulator: mybot in the maze, amcl node with its defaults, on a map rasterised from
   the world and on a map saved from gmapping: position / yaw error against
   ``/ground_truth/state`` over a long drive; global localization from uniform particles
   over ``--seeds`` seeds; kidnapping recovery with recovery_alpha_slow 0.001 and
   recovery_alpha_fast 0.1.

The simulator harness here (:func:`drive`, :func:`maze_map`) is what
``tests/localization/amcl/test_live.py`` runs on shorter drives.
"""

from __future__ import annotations

import argparse
import math
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from roverlab.core import Context, Node
from roverlab.geometry import SE2, wrap_angle
from roverlab.localization.amcl import Amcl, AmclParams, map_for_amcl
from roverlab.localization.amcl.node import AmclNode
from roverlab.maps import load_map, save_map
from roverlab.maps.node import MapServer
from roverlab.msgs import Twist, xytheta_from_pose
from roverlab.msgs import classes as mc
from roverlab.raycast import cast_grid
from roverlab.sim.app import Simulation
from roverlab.slam.data.logs import load_log
from roverlab.slam.data.mapquality import OccupancyMapLike, align_map, ground_truth

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "radish"
FIXTURES = Path(__file__).resolve().parents[1] / "tests" / "localization" / "amcl" / "fixtures"
MAZE_CELL_M = 1.6
MAZE_CELLS = 5
RESOLUTION_M = 0.05


# --------------------------------------------------------------------------- the maze
def world_map(out_dir: Path, *, world: str = "maze") -> Path:
    """The maze rasterised at the lidar's height (5 cm cells): walls occupied, the cells
    reachable from the spawn free, the rest unknown; saved as map_server files.
    Returns the YAML path."""
    ctx = Context()
    sim = Simulation(context=ctx, world=world, robot="mybot", cameras=False)
    z = float(sim.config.lidars[0].mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=RESOLUTION_M, z_m=max(z, 0.01))
    spawn = sim.world_model.spawn
    ctx.shutdown()
    labels, _ = ndimage.label(~gt.occupied)
    row = int((spawn.y - gt.origin_xy[1]) / RESOLUTION_M)
    col = int((spawn.x - gt.origin_xy[0]) / RESOLUTION_M)
    data = np.full(gt.occupied.shape, -1, dtype=np.int8)
    data[labels == labels[row, col]] = 0
    data[gt.occupied] = 100
    out_dir.mkdir(parents=True, exist_ok=True)
    saved = save_map(out_dir / "maze_world", data, resolution=RESOLUTION_M,
                     origin=(gt.origin_xy[0], gt.origin_xy[1], 0.0))  # fmt: skip
    return saved.yaml_path


def gmapping_map() -> Path:
    """The maze's map saved from slam_gmapping after the whole tour (a fixture of the
    tests, made by :func:`make_gmapping_fixture`)."""
    return FIXTURES / "maze_gmapping.yaml"


def maze_tour(free: Callable[[float, float, float, float], bool]) -> list[tuple[float, float]]:
    """Cell centres of a depth-first tour of the 5 x 5 maze from its centre (backtracking
    included); ``free(x0, y0, x1, y1)``: the straight line between two centres is clear."""
    half = MAZE_CELLS // 2
    seen = {(0, 0)}
    tour = [(0.0, 0.0)]

    def visit(c: tuple[int, int]) -> None:
        for d in ((1, 0), (0, 1), (-1, 0), (0, -1)):
            n = (c[0] + d[0], c[1] + d[1])
            if max(abs(n[0]), abs(n[1])) > half or n in seen:
                continue
            a = (c[0] * MAZE_CELL_M, c[1] * MAZE_CELL_M)
            b = (n[0] * MAZE_CELL_M, n[1] * MAZE_CELL_M)
            if free(*a, *b):
                seen.add(n)
                tour.append(b)
                visit(n)
                tour.append(a)

    visit((0, 0))
    return tour


def free_line(occupied: np.ndarray, origin: tuple[float, float]) -> Callable[..., bool]:
    def free(x0: float, y0: float, x1: float, y1: float) -> bool:
        t = np.linspace(0.0, 1.0, 64)
        nx, ny = -(y1 - y0), x1 - x0
        norm = math.hypot(nx, ny)
        for off in (-0.2, 0.0, 0.2):
            xs = x0 + t * (x1 - x0) + off * nx / norm
            ys = y0 + t * (y1 - y0) + off * ny / norm
            col = np.floor((xs - origin[0]) / RESOLUTION_M).astype(int)
            row = np.floor((ys - origin[1]) / RESOLUTION_M).astype(int)
            if occupied[row, col].any():
                return False
        return True

    return free


class GroundTruthDriver(Node):
    """Drives to ``waypoints[index]`` on ``/ground_truth/state`` (turn, then go), then to
    the next one; a subclass says when to hold still and which waypoint is current."""

    def __init__(self, name: str, context: Context, waypoints: list[tuple[float, float]]) -> None:
        super().__init__(name, context=context)
        self.waypoints = waypoints
        self.index = 0
        self.cmd = self.create_publisher(Twist, "/cmd_vel", 1)
        self.create_subscription(mc.Odometry, "/ground_truth/state", self._on_pose, 1)

    def holding(self) -> bool:
        """Whether to publish a zero Twist instead of driving."""
        return False

    def waypoint(self) -> tuple[float, float]:
        return self.waypoints[self.index]

    def _on_pose(self, msg: Any) -> None:
        if self.holding():
            self.cmd.publish(Twist())
            return
        x, y, yaw = xytheta_from_pose(msg.pose.pose)
        gx, gy = self.waypoint()
        dist = math.hypot(gx - x, gy - y)
        if dist < 0.08:
            self.index += 1
            return
        err = float(wrap_angle(math.atan2(gy - y, gx - x) - yaw))
        w = max(-0.6, min(0.6, 2.0 * err))
        v = 0.0 if abs(err) > 0.25 else min(0.3, 1.5 * dist)
        self.cmd.publish(Twist(linear_x=v, angular_z=w))


class TourDriver(GroundTruthDriver):
    """Drives the tour's waypoints forwards then back, again and again, until disabled."""

    def __init__(self, context: Context, waypoints: list[tuple[float, float]]) -> None:
        super().__init__("tour_driver", context, waypoints + waypoints[::-1])
        self.enabled = True

    def holding(self) -> bool:
        return not self.enabled

    def waypoint(self) -> tuple[float, float]:
        return self.waypoints[self.index % len(self.waypoints)]


# --------------------------------------------------------------------------- one drive
@dataclass
class Drive:
    """Errors of amcl against the ground truth, sampled at 10 Hz of simulated time.

    Attributes:
        times: ``(K,)`` simulated seconds.
        position_error: ``(K,)`` m (NaN before amcl's first pose).
        yaw_error: ``(K,)`` absolute, rad.
        particles: ``(K,)`` particle count.
        offset: ``(K, 2)`` estimate minus truth, x and y (m).
        wall_s: wall time of the run.
        kidnapped_at: simulated second of the teleport, or None.
        trace: ``(time, particles, w_slow, w_fast, injected)`` once a second.
    """

    times: np.ndarray
    position_error: np.ndarray
    yaw_error: np.ndarray
    particles: np.ndarray
    offset: np.ndarray
    wall_s: float
    kidnapped_at: float | None = None
    trace: list[tuple[float, int, float, float, int]] = field(default_factory=list)

    def converged_at(self, *, after: float = 0.0, threshold_m: float = 0.2) -> float | None:
        """First time (from ``after``) since which the error stays below ``threshold_m``
        to the end of the run; None if it never settles."""
        sel = self.times >= after
        t, e = self.times[sel], self.position_error[sel]
        bad = ~(e < threshold_m)
        if bad[-1]:
            return None
        last_bad = np.flatnonzero(bad)
        return float(t[0] if last_bad.size == 0 else t[last_bad[-1] + 1])

    def stats(self, *, after: float = 0.0) -> tuple[float, float, float]:
        """``(median position error, p95, median yaw error in degrees)`` from ``after``."""
        sel = (self.times >= after) & np.isfinite(self.position_error)
        e = self.position_error[sel]
        return (float(np.median(e)), float(np.percentile(e, 95)),
                math.degrees(float(np.median(self.yaw_error[sel]))))  # fmt: skip


def drive(
    map_yaml: Path,
    *,
    duration_s: float,
    seed: int = 0,
    global_start: bool = False,
    kidnap_at_s: float | None = None,
    kidnap_to: tuple[float, float, float] = (-3.2, 3.2, 1.5),
    encoder_odometry: bool = False,
    params: dict[str, Any] | None = None,
    world_t_map: SE2 | None = None,
) -> Drive:
    """mybot drives the maze tour for ``duration_s`` simulated seconds with map_server and
    the amcl node (its defaults unless ``params``), everything seeded with ``seed``.

    Args:
        map_yaml: the map amcl localises in (served by map_server's ``static_map``).
        duration_s: simulated seconds.
        seed: seed of the simulator (sensor noise) and of amcl.
        global_start: call ``global_localization`` before driving.
        kidnap_at_s: teleport the robot to ``kidnap_to`` at this simulated second.
        kidnap_to: where (world frame).
        encoder_odometry: odometry from the wheel encoders (with the simulator's wheel
            slip) instead of the world pose (mybot's plugin setting): a teleport is then
            invisible to odometry, a real kidnapping.
        params: amcl parameter overrides.
        world_t_map: where the map's frame lies in the world (a SLAM map's, from
            :func:`map_alignment`); None: the map frame is the world frame.
    """
    wall = time.perf_counter()
    ctx = Context()
    sim = Simulation(context=ctx, world="maze", robot="mybot", cameras=False, seed=seed)
    if encoder_odometry and sim.simulator.drive is not None:
        sim.simulator.drive = replace(sim.simulator.drive, odometry_source="encoder")
    z = float(sim.config.lidars[0].mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=RESOLUTION_M, z_m=max(z, 0.01))
    tour = maze_tour(free_line(gt.occupied, gt.origin_xy))
    MapServer(ctx, yaml_path=map_yaml)
    overrides = {"seed": seed, **(params or {})}
    node = AmclNode(ctx, parameter_overrides=overrides)
    driver = TourDriver(ctx, tour)
    trace: list[tuple[float, int, float, float, int]] = []
    rows: list[tuple[float, float, float, int, float, float]] = []

    def sample() -> None:
        now = ctx.now().seconds
        m2o = node.map_to_odom
        pf = node.amcl.pf if node.amcl is not None else None
        count = pf.count if pf is not None else 0
        if pf is not None and len(rows) % 10 == 0:
            trace.append((now, count, pf.w_slow, pf.w_fast, pf.injected))
        if m2o is None:
            rows.append((now, math.nan, math.nan, count, math.nan, math.nan))
            return
        est = m2o.to_se2() * SE2(*sim.simulator.odometry_pose())
        if world_t_map is not None:
            est = world_t_map * est
        s = sim.simulator
        err = math.hypot(est.x - s.x, est.y - s.y)
        yaw = float(wrap_angle(est.theta - s.yaw))
        rows.append((now, err, abs(yaw), count, est.x - s.x, est.y - s.y))

    probe = ctx.create_node("amcl_probe")
    probe.create_timer(0.1, sample)
    if global_start:
        client = probe.create_client("std_srvs/srv/Empty", "global_localization")
        ctx.spin_until_condition(lambda: node.amcl is not None, timeout_sec=5.0)
        client.call(client.srv_type.Request())
    kidnapped: float | None = None
    if kidnap_at_s is not None:
        ctx.spin_for(kidnap_at_s)
        sim.simulator.teleport(*kidnap_to)
        kidnapped = ctx.now().seconds
        # the tour continues from the new place: start at its nearest waypoint
        d = [math.hypot(wx - kidnap_to[0], wy - kidnap_to[1]) for wx, wy in driver.waypoints]
        driver.index = int(np.argmin(d))
        ctx.spin_for(duration_s - kidnap_at_s)
    else:
        ctx.spin_for(duration_s)
    ctx.shutdown()
    arr = np.array(rows, dtype=np.float64).reshape(-1, 6)
    return Drive(arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3], arr[:, 4:], time.perf_counter() - wall,
                 kidnapped, trace)  # fmt: skip


def crop_map(yaml_path: Path, prefix: Path, margin_cells: int = 20) -> Path:
    """Save the map cropped to its known cells plus a margin (slam_gmapping's map is
    200 m wide by default); the origin moves with the crop, the cells keep their place."""
    m = load_map(yaml_path)
    rows, cols = np.nonzero(m.data >= 0)
    r0, c0 = max(0, rows.min() - margin_cells), max(0, cols.min() - margin_cells)
    r1 = min(m.height, rows.max() + margin_cells + 1)
    c1 = min(m.width, cols.max() + margin_cells + 1)
    res = m.info.resolution
    ox, oy, yaw = m.info.origin
    prefix.parent.mkdir(parents=True, exist_ok=True)
    saved = save_map(prefix, m.data[r0:r1, c0:c1], resolution=res,
                     origin=(ox + c0 * res, oy + r0 * res, yaw))  # fmt: skip
    return saved.yaml_path


def map_alignment(map_yaml: Path) -> SE2:
    """``world_T_map`` of a SLAM map of the maze: the rigid fit of its cells to the world's
    ground truth (:func:`roverlab.slam.data.mapquality.align_map`); amcl localises in the map's
    frame, so its poses are compared with the ground truth through this."""
    ctx = Context()
    sim = Simulation(context=ctx, world="maze", robot="mybot", cameras=False)
    z = float(sim.config.lidars[0].mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=RESOLUTION_M, z_m=max(z, 0.01))
    ctx.shutdown()
    m = load_map(map_yaml)
    grid = OccupancyMapLike(data=m.data, origin_xy=m.info.origin[:2], resolution=m.info.resolution)
    return align_map(grid, gt)


def make_gmapping_fixture() -> Path:
    """Map the maze with slam_gmapping over the whole tour and save it (map_saver's
    files) as the tests' fixture. Run once; the result is committed."""
    from roverlab.maps.node import MapSaver
    from roverlab.slam.gmapping.node import SlamGMapping

    ctx = Context()
    sim = Simulation(context=ctx, world="maze", robot="mybot", cameras=False, seed=0)
    z = float(sim.config.lidars[0].mount.translation[2])
    gt = ground_truth(sim.world_model, resolution=RESOLUTION_M, z_m=max(z, 0.01))
    tour = maze_tour(free_line(gt.occupied, gt.origin_xy))
    SlamGMapping(ctx, parameter_overrides={"base_frame": "base_footprint"})
    driver = TourDriver(ctx, tour)
    ctx.spin_until_condition(lambda: driver.index >= len(tour), timeout_sec=900.0)
    driver.enabled = False
    ctx.spin_for(6.0)
    with tempfile.TemporaryDirectory() as tmp:
        saver = MapSaver(ctx, path_prefix=Path(tmp) / "map")
        ctx.spin_until_condition(lambda: saver.finished, timeout_sec=10.0)
        ctx.shutdown()
        crop_map(Path(tmp) / "map.yaml", FIXTURES / "maze_gmapping")
    return gmapping_map()


# --------------------------------------------------------------------------- speed
def update_speed(map_yaml: Path, *, beams: int, fixed_particles: int | None,
                 updates: int = 300) -> tuple[float, float, int]:  # fmt: skip
    """Median and p90 wall time (ms) of one filter update (motion + weighting +
    resampling) along intel's graph-SLAM trajectory on its map, and the median particle
    count. ``beams`` 360: scans of 360 beams over a full turn ray cast in the map (intel's
    own scans have 180); otherwise intel's scans with ``laser_max_beams`` = ``beams``."""
    log = load_log(DATA / "intel.clf.bz2")[:3000]
    occ = load_map(map_yaml)
    kw: dict[str, Any] = {"laser_max_beams": beams}
    if fixed_particles is not None:
        kw.update(min_particles=fixed_particles, max_particles=fixed_particles)
    params = AmclParams.from_ros(kw)
    truth = np.loadtxt(map_yaml.parent / "trajectory.tum", usecols=(1, 2, 6, 7))[:3000]
    yaws = 2.0 * np.arctan2(truth[:, 2], truth[:, 3])
    amcl = Amcl(params, map_for_amcl(occ, params), rng=np.random.default_rng(0),
                initial_pose=SE2(truth[0, 0], truth[0, 1], yaws[0]))  # fmt: skip
    full = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    ox, oy, _ = occ.info.origin
    times: list[float] = []
    counts: list[int] = []
    k = 0
    while len(times) < updates:
        i = k % len(log)
        rec = log[i]
        if beams == 360:
            ranges = cast_grid(occ.data, occ.info.resolution, (ox, oy), truth[i, 0], truth[i, 1],
                               full + yaws[i], 30.0)  # fmt: skip
            bearings = full
        else:
            ranges, bearings = rec.ranges, rec.angles()
        amcl.request_nomotion_update()
        t0 = time.perf_counter()
        amcl.process_scan(odom_pose=rec.odom_pose, ranges=ranges, bearings=bearings,
                          range_min=rec.range_min, range_max=rec.range_max)  # fmt: skip
        t = time.perf_counter() - t0
        if k >= 20:  # compiled, cache warm
            times.append(t * 1e3)
            counts.append(amcl.pf.count)
        k += 1
    return (statistics.median(times), float(np.percentile(times, 90)),
            int(statistics.median(counts)))  # fmt: skip


def graph_map(work: Path, log: str = "intel") -> Path:
    """``roverlab slam run LOG --method graph`` once; returns its map.yaml."""
    out = work / f"graph_{log}"
    if not (out / "map.yaml").is_file():
        subprocess.run([sys.executable, "-m", "roverlab.cli", "slam", "run",
                        str(DATA / f"{log}.clf.bz2"), "--method", "graph", "--out", str(out)],
                       check=True, capture_output=True)  # fmt: skip
    return out / "map.yaml"


def amcl_run_ratio(map_yaml: Path, work: Path) -> tuple[float, float]:
    """``roverlab amcl run`` on intel (default parameters): (wall s, real-time factor)."""
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "roverlab.cli", "amcl", "run",
                    str(DATA / "intel.clf.bz2"), "--map", str(map_yaml), "--out",
                    str(work / "amcl_intel")], check=True, capture_output=True)  # fmt: skip
    wall = time.perf_counter() - t0
    return wall, 2691.0 / wall


# --------------------------------------------------------------------------- main
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skip-sim", action="store_true")
    ap.add_argument("--skip-log", action="store_true")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--minutes", type=float, default=10.0)
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}")
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        if not args.skip_log and (DATA / "intel.clf.bz2").is_file():
            intel = graph_map(work)
            for beams, fixed, target in ((360, 5000, 5.0), (30, None, 1.0), (30, 5000, 1.0)):
                med, p90, n = update_speed(intel, beams=beams, fixed_particles=fixed)
                label = f"{n} particles x {beams} beams" + ("" if fixed else " (defaults: KLD)")
                print(f"filter update, {label}: median {med:.2f} ms, p90 {p90:.2f} ms "
                      f"(target <= {target} ms)")  # fmt: skip
            wall, ratio = amcl_run_ratio(intel, work)
            print(f"amcl run intel: {wall:.1f} s for 2,691 s of data: {ratio:.0f}x real time "
                  "(target >= 50x)")  # fmt: skip
        if args.skip_sim:
            return
        maps = {"world map": world_map(work), "gmapping map": gmapping_map()}
        frames = {"world map": None, "gmapping map": map_alignment(maps["gmapping map"])}
        duration = 60.0 * args.minutes
        for name, yaml_path in maps.items():
            d = drive(yaml_path, duration_s=duration, world_t_map=frames[name])
            med, p95, yaw = d.stats(after=5.0)
            print(f"tracking, {name}, {args.minutes:g} min: position error median "
                  f"{100 * med:.2f} cm, p95 {100 * p95:.2f} cm, yaw median {yaw:.2f} deg "
                  f"(targets 3 cm, 8 cm, 1 deg); {d.wall_s:.0f} s wall")  # fmt: skip
        times: list[float | None] = []
        for seed in range(args.seeds):
            d = drive(maps["world map"], duration_s=90.0, seed=seed, global_start=True)
            times.append(d.converged_at())
        ok = [t for t in times if t is not None and t <= 60.0]
        shown = ", ".join("-" if t is None else f"{t:.0f}" for t in times)
        print(f"global localization: converged within 60 s in {len(ok)} of {args.seeds} seeds "
              f"(target >= 9 of 10); seconds: {shown}")  # fmt: skip
        recovery = {"recovery_alpha_slow": 0.001, "recovery_alpha_fast": 0.1}
        rec_times: list[float | None] = []
        for seed in range(max(1, args.seeds // 2)):
            d = drive(maps["world map"], duration_s=130.0, seed=seed, kidnap_at_s=40.0,
                      encoder_odometry=True, params=recovery)  # fmt: skip
            t = d.converged_at(after=40.0)
            rec_times.append(None if t is None else t - 40.0)
        shown = ", ".join("-" if t is None else f"{t:.0f}" for t in rec_times)
        good = sum(t is not None and t <= 60.0 for t in rec_times)
        print(f"kidnapping: recovered within 60 s in {good} of {len(rec_times)} seeds; "
              f"seconds after the teleport: {shown}")  # fmt: skip


if __name__ == "__main__":
    main()
