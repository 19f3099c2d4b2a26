"""Fixed start -> goal episodes, as published benchmarks run them (BARN's ``run.py``).

One episode: a world, the robot spawned at ``start``, move_base started from a launch
file (on odometry alone with costmaps from the laser, or on a map with amcl or the ground
truth), one goal. The episode's clock starts when the robot is ``start_move_m`` from its
start; it ends when the true position is within ``goal_tolerance_m`` of the goal
(succeeded), at the first contact (collided, with ``on_collision="end"``), after
``time_limit_s`` (timeout), or when move_base gives the goal up (ABORTED: nothing resends
it, so in BARN's loop the robot would sit until the limit; counted as a timeout). The
score is BARN's: ``success * optimal / clip(time, 2 optimal, 8 optimal)`` with ``optimal``
the reference path's length at 2 m/s.
"""

from __future__ import annotations

import csv
import io
import json
import math
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.actionlib.status import STATUS_NAMES
from roverlab.batch import episode_stop
from roverlab.core import ClockMode, Context, Time
from roverlab.description import find_package
from roverlab.fileio import atomic_write_bytes
from roverlab.geometry import wrap_angle
from roverlab.launch import build_launch
from roverlab.navbench.grid import BenchGrid
from roverlab.navbench.harness import BenchError, _map_for, _Timings
from roverlab.navbench.report import GoalRecord, draw
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.move_base.node import MoveBase
from roverlab.sim.app import Simulation
from roverlab.sim.config import DiffDriveConfig, PlanarMoveConfig
from roverlab.sim.node import SimulatorNode, SpawnPose
from roverlab.sim.ros_control import DiffDriveControllerConfig
from roverlab.world import load_world

__all__ = [
    "FIXED_LOCALIZATIONS",
    "FixedConfig",
    "FixedResult",
    "barn_score",
    "episode_files",
    "run_fixed",
]

FIXED_LOCALIZATIONS = ("odom", "amcl", "ground_truth")
ON_COLLISION = ("end", "continue")
_SAMPLE_PERIOD_S = 0.05
_READY_S = 30.0
#: simulated seconds of the throw-away episode that compiles a setup's kernels
_WARM_UP_S = 3.0
#: setups (planner, robot, localization, launch, parameters) this process has warmed up
_warmed: set[tuple[str, str, str, str, str]] = set()
BARN_OPTIMAL_SPEED_MPS = 2.0


def barn_score(success: bool, time_s: float, optimal_time_s: float) -> float:
    """BARN's metric: ``success * optimal / clip(time, 2 optimal, 8 optimal)`` (<= 0.5)."""
    if not success or not optimal_time_s > 0:
        return 0.0
    return optimal_time_s / float(np.clip(time_s, 2 * optimal_time_s, 8 * optimal_time_s))


def reference_score(
    success: bool, time_s: float, reference: Sequence[tuple[float, float]] | None
) -> tuple[float | None, float | None]:
    """The reference path's length (m) and BARN's score against it (at 2 m/s), or
    ``(None, None)`` without a reference."""
    if reference is None:
        return None, None
    pts = np.asarray(reference, dtype=np.float64)
    ref_m = float(np.hypot(*np.diff(pts, axis=0).T).sum())
    if not ref_m:
        return ref_m, None
    return ref_m, barn_score(success, time_s, ref_m / BARN_OPTIMAL_SPEED_MPS)


@dataclass(frozen=True)
class FixedConfig:
    """One fixed-goal episode.

    Args:
        world: a world file or bundled world.
        out: folder for ``NAME.json``, ``NAME.csv`` (the driven path) and ``NAME.png``.
        start: ``(x, y, yaw)`` in the world, where the robot is spawned.
        goal: ``(x, y, yaw)`` in the world.
        name: the files' stem (default: the world's).
        robot: a bundled robot or a URDF/xacro file.
        planner: ``dwa`` or ``teb``.
        localization: ``odom`` (no map, costmaps from the laser), ``amcl`` or
            ``ground_truth`` (map_server with the world's map).
        params_dir: the launch file's parameter folder.
        launch: the launch file starting move_base (default: ``nav_bench_odom.launch`` or
            ``nav_bench.launch`` of robot_navigation).
        teb_params: TEB's parameter file for ``nav_bench_odom.launch`` (None: the
            folder's ``teb_local_planner_params.yaml``).
        max_speed: the local planner's ``max_vel_x`` (None: the file's).
        goal_tolerance_m: success radius around the goal (true position).
        time_limit_s: simulated seconds from the start of the clock.
        start_move_m: the clock starts when the robot is this far from its start.
        on_collision: ``end`` (a contact ends the episode as collided) or ``continue``.
        reference: the reference path (world points, start and goal included) whose
            length at 2 m/s is the optimal time of the score (None: no score).
        seed: seeds the simulator (and amcl).
    """

    world: str
    out: Path
    start: tuple[float, float, float]
    goal: tuple[float, float, float]
    name: str = ""
    robot: str = "jackal"
    planner: str = "dwa"
    localization: str = "odom"
    params_dir: Path | None = None
    launch: Path | None = None
    teb_params: Path | None = None
    max_speed: float | None = None
    goal_tolerance_m: float = 1.0
    time_limit_s: float = 100.0
    start_move_m: float = 0.1
    on_collision: str = "end"
    reference: tuple[tuple[float, float], ...] | None = None
    seed: int = 0

    def validate(self) -> None:
        """Raises BenchError naming the bad option."""
        if self.localization not in FIXED_LOCALIZATIONS:
            raise BenchError(
                f"unknown localization {self.localization!r}: use {', '.join(FIXED_LOCALIZATIONS)}"
            )
        if self.planner not in ("dwa", "teb"):
            raise BenchError(f"unknown planner {self.planner!r}: use dwa or teb")
        if self.on_collision not in ON_COLLISION:
            raise BenchError(f"--on-collision must be end or continue, got {self.on_collision!r}")
        for label, v in (("--goal-tolerance", self.goal_tolerance_m),
                         ("--time-limit", self.time_limit_s)):  # fmt: skip
            if not (math.isfinite(v) and v > 0):
                raise BenchError(f"{label} must be > 0, got {v}")
        if self.max_speed is not None and not (
            math.isfinite(self.max_speed) and self.max_speed > 0
        ):
            raise BenchError(f"--max-speed must be > 0, got {self.max_speed}")
        if not all(math.isfinite(v) for v in (*self.start, *self.goal)):
            raise BenchError("--start and --goal must be finite numbers")
        if self.params_dir is None:
            raise BenchError(
                "no navigation parameters for this run: give a folder of move_base "
                "parameter files with --params"
            )
        if not Path(self.params_dir).is_dir():
            raise BenchError(f"{self.params_dir}: parameter folder not found")
        if self.launch is not None and not Path(self.launch).is_file():
            raise BenchError(f"{self.launch}: launch file not found")


@dataclass
class FixedResult:
    """How one episode ended (``record`` holds the path, contacts, failures...)."""

    name: str
    status: str  # succeeded, collided, timeout (interrupted: stopped by Ctrl-C)
    record: GoalRecord
    time_s: float
    reference_m: float | None
    score: float | None
    control_ms_p99: float
    control_wall_ms_p99: float
    planner_ms_p99: float
    sim_time_s: float
    cpu_s: float
    wall_s: float
    warnings: list[str] = field(default_factory=list)
    trace: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4)))

    @property
    def rtf_per_cpu_s(self) -> float:
        """Simulated seconds per CPU second of the whole stack (simulator + move_base)."""
        return self.sim_time_s / self.cpu_s if self.cpu_s > 0 else math.nan

    def to_json(self) -> dict[str, Any]:
        def r(v: float | None, nd: int = 4) -> float | None:
            return round(v, nd) if v is not None and math.isfinite(v) else None

        rec = self.record.to_json()
        rec.pop("index")
        return {
            "world": self.name,
            "status": self.status,
            "succeeded": self.status == "succeeded",
            "collided": self.status == "collided",
            "move_base_status": rec.pop("status"),
            "time_s": r(self.time_s, 3),
            "reference_m": r(self.reference_m),
            "optimal_time_s": r(self.reference_m / BARN_OPTIMAL_SPEED_MPS, 3)
            if self.reference_m
            else None,
            "score": r(self.score),
            "control_ms_p99": r(self.control_ms_p99, 3),
            "control_wall_ms_p99": r(self.control_wall_ms_p99, 3),
            "planner_ms_p99": r(self.planner_ms_p99, 3),
            "sim_time_s": r(self.sim_time_s, 2),
            "cpu_s": r(self.cpu_s, 3),
            "wall_s": r(self.wall_s, 3),
            "rtf_per_cpu_s": r(self.rtf_per_cpu_s, 2),
            **rec,
            "warnings": self.warnings,
        }


def _p99_ms(values: list[float]) -> float:
    return float(np.percentile(values, 99) * 1000.0) if values else math.nan


def _drive_topics(sim: Simulation) -> tuple[str, str]:
    d = sim.config.drive
    if isinstance(d, DiffDriveConfig | PlanarMoveConfig | DiffDriveControllerConfig):
        return d.command_topic, d.odometry_topic
    raise BenchError(f"robot {sim.robot_model.name!r} has no drive that moves it on cmd_vel")


def _odom_origin(sim: SimulatorNode) -> tuple[float, float, float]:
    """The odometry frame's pose in the world: the true pose composed with the inverse of
    the odometry pose the drive reports now (its odometry starts at zero, or is the world
    pose for Gazebo's ``odometrySource world``)."""
    ctrl = sim.controller
    ox, oy, oth = ctrl.pose if ctrl is not None else sim.odometry_pose()
    th = sim.yaw - oth
    c, s = math.cos(th), math.sin(th)
    return sim.x - (c * ox - s * oy), sim.y - (s * ox + c * oy), th


def _in_frame(
    origin: tuple[float, float, float], p: tuple[float, float, float]
) -> tuple[float, float, float]:
    ox, oy, oth = origin
    c, s = math.cos(oth), math.sin(oth)
    dx, dy = p[0] - ox, p[1] - oy
    return c * dx + s * dy, -s * dx + c * dy, float(wrap_angle(p[2] - oth))


def _draw_grid(sim: Simulation, points: NDArray[np.float64], inscribed: float) -> BenchGrid:
    """The world rasterised at 0.05 m over its own bounds and ``points`` (start, goal,
    path) with 1 m around: lethal where solid, inscribed cost within ``inscribed``."""
    res = 0.05
    occ0, origin0 = sim.world_model.occupancy(res, *sim.config.height_band)
    h0, w0 = occ0.shape
    xs = np.concatenate([[origin0[0], origin0[0] + w0 * res], points[:, 0]])
    ys = np.concatenate([[origin0[1], origin0[1] + h0 * res], points[:, 1]])
    bounds = (
        math.floor((xs.min() - 1.0) / res) * res, math.floor((ys.min() - 1.0) / res) * res,
        xs.max() + 1.0, ys.max() + 1.0,
    )  # fmt: skip
    occ, origin = sim.world_model.occupancy(res, *sim.config.height_band, bounds=bounds)
    costs = np.zeros(occ.shape, dtype=np.uint8)
    near = ndimage.distance_transform_edt(~occ) * res <= inscribed
    costs[near] = 253
    costs[occ] = 254
    return BenchGrid(costs, res, (float(origin[0]), float(origin[1])))


def _goal_msg(frame: str, p: tuple[float, float, float]) -> dict[str, Any]:
    return {
        "target_pose": {
            "header": {"frame_id": frame},
            "pose": {
                "position": {"x": p[0], "y": p[1]},
                "orientation": {"z": math.sin(p[2] / 2), "w": math.cos(p[2] / 2)},
            },
        }
    }


class _Episode:
    def __init__(self, cfg: FixedConfig, log: Callable[[str], None]) -> None:
        self.cfg = cfg
        # the rasterised map of a map-based run: per episode (parallel episodes share out)
        self._tmp = tempfile.TemporaryDirectory(prefix="roverlab-fixed-")
        self.ctx = Context()
        world = load_world(cfg.world)
        self.sim = Simulation(
            self.ctx, world=world, robot=cfg.robot, spawn=SpawnPose(*cfg.start),
            seed=cfg.seed, cameras=False,
        )  # fmt: skip
        self.simulator = self.sim.simulator
        cmd, odom = _drive_topics(self.sim)
        pkg = find_package("robot_navigation") / "launch"
        params = Path(cfg.params_dir or ".").resolve()
        args: dict[str, str] = {"param_dir": str(params), "planner": cfg.planner}
        if cfg.localization == "odom":
            launch = cfg.launch or pkg / "nav_bench_odom.launch"
            args |= {"odom_topic": odom, "cmd_vel_topic": cmd}
            args["max_speed"] = "" if cfg.max_speed is None else repr(cfg.max_speed)
            if cfg.teb_params is not None:
                args["teb_params"] = str(Path(cfg.teb_params).resolve())
            self.frame = "odom"
        else:
            launch = cfg.launch or pkg / "nav_bench.launch"
            drive = self.sim.config.drive
            args |= {
                "map_file": str(
                    _map_for(
                        world, self.sim, Path(cfg.out), (cfg.start[:2], cfg.goal[:2])
                    ).resolve()
                ),
                "localization": cfg.localization,
                "base_frame": drive.robot_base_frame if drive else "base_link",
                "initial_pose_x": repr(cfg.start[0]),
                "initial_pose_y": repr(cfg.start[1]),
                "initial_pose_a": repr(cfg.start[2]),
                "seed": str(cfg.seed),
            }
            self.frame = "map"
        built = build_launch(launch, args, context=self.ctx, seed=cfg.seed)
        self.warnings = list(built.warnings)
        for w in self.warnings:
            log(f"warning: {w}")
        movers = [n for n in built.nodes if isinstance(n, MoveBase)]
        if not movers:
            raise BenchError(f"{launch}: starts no move_base")
        self.move_base = movers[0]
        self.timings = _Timings()
        self.move_base.timing_hook = self.timings
        node = self.ctx.create_node("nav_bench")
        self.client = SimpleActionClient(node, "move_base", "move_base_msgs/MoveBaseAction")
        self.trace: list[tuple[float, float, float, float]] = []
        self.contact_points: list[tuple[float, float]] = []
        self.t_start: float | None = None
        self.outcome: str | None = None
        self._t_sent: float | None = None  # the outcome is judged once the goal is out
        self.recoveries = 0
        self._mb_state = ""
        self._contacts = 0
        # the episode's spin ends when _sample decides (executor.stop() after that event,
        # where a stop_when() checked before every event would stop too: the executor's
        # plain loop runs meanwhile, with no Python call between two events)
        self._halt: Callable[[], None] | None = None
        node.create_timer(_SAMPLE_PERIOD_S, self._sample)
        fp = self.move_base.global_costmap.footprint
        self.inscribed = footprint_radii(fp)[0]

    def _now(self) -> float:
        return self.ctx.now().nanoseconds / 1e9

    def _sample(self) -> None:
        s = self.simulator
        t = self._now()
        self.trace.append((t, s.x, s.y, s.yaw))
        state = self.move_base.state
        if state == "CLEARING" and self._mb_state != "CLEARING":
            self.recoveries += 1
        self._mb_state = state
        if self.outcome is not None or self._t_sent is None:
            return
        self._judge(t, self._t_sent)
        if self._halt is not None and (self.outcome is not None or episode_stop().is_set()):
            self._halt()

    def _judge(self, t: float, t_sent: float) -> None:
        """Set the outcome once the episode is decided (``_sample`` at time ``t``, the
        goal sent at ``t_sent``)."""
        s, cfg = self.simulator, self.cfg
        if self.t_start is None and math.hypot(s.x - cfg.start[0], s.y - cfg.start[1]) >= (
            cfg.start_move_m
        ):
            self.t_start = t
        c = s.contacts
        if c != self._contacts:
            self._contacts = c
            self.contact_points.append((s.x, s.y))
            if cfg.on_collision == "end":
                self.outcome = "collided"
                return
        if math.hypot(s.x - cfg.goal[0], s.y - cfg.goal[1]) <= cfg.goal_tolerance_m:
            self.outcome = "succeeded"
        elif t - (self.t_start if self.t_start is not None else t_sent) >= (cfg.time_limit_s):
            self.outcome = "timeout"
        elif self.client.get_state() not in (GoalStatus.PENDING, GoalStatus.ACTIVE):
            self.outcome = "timeout"  # given up (or "reached" short of the tolerance)

    def _spin_until_decided(self, timeout_s: float) -> None:
        """Spin until ``_sample`` has an outcome (or Ctrl-C), at most ``timeout_s`` of sim
        time: what ``ctx.wait_for(lambda: outcome is not None or stop.is_set(), timeout_s)``
        does, ending after the same event, without a condition called before every event."""
        ex = self.ctx.executor
        if ex.mode is not ClockMode.SIM or ex.stopped:
            stop = episode_stop()
            self.ctx.wait_for(lambda: self.outcome is not None or stop.is_set(), timeout_s)
            return
        halted = False

        def halt() -> None:
            nonlocal halted
            halted = True
            ex.stop()

        self._halt = halt
        try:
            self.ctx.spin_until(Time(ex.now_ns + round(timeout_s * 1e9)))
        finally:
            self._halt = None
            if halted:
                ex.reset_stop()

    def run(self) -> FixedResult:
        cfg, s = self.cfg, self.simulator
        wall0, cpu0 = time.perf_counter(), time.process_time()
        mb = self.move_base
        ok = self.ctx.wait_for(lambda: mb.global_costmap.get_robot_pose() is not None, _READY_S)
        if not ok or not self.client.wait_for_server(10.0):
            raise BenchError(f"move_base did not come up within {_READY_S:g} s (no robot pose)")
        goal = cfg.goal
        if self.frame == "odom":
            goal = _in_frame(_odom_origin(s), cfg.goal)
        start = (s.x, s.y, s.yaw)
        self._t_sent = self._now()
        self.trace = [(self._t_sent, *start)]
        self._contacts = c0 = s.contacts
        self.client.send_goal(_goal_msg(self.frame, goal))
        stop = episode_stop()  # Ctrl-C in a serial batch: end here, reported as interrupted
        self._spin_until_decided(cfg.time_limit_s * 3 + 60.0)
        outcome = self.outcome or ("interrupted" if stop.is_set() else "timeout")
        t_end = self._now()
        state = self.client.get_state()
        done = state not in (GoalStatus.PENDING, GoalStatus.ACTIVE)
        text = self.client.get_goal_status_text() if done else ""
        mb_status = STATUS_NAMES[state] if done else "ACTIVE"
        if not done:
            self.client.cancel_goal()
            self.ctx.wait_for(lambda: self.client.get_state() != GoalStatus.ACTIVE, 5.0)
        trace = np.array(self.trace)
        xy = trace[:, 1:3]
        driven = float(np.hypot(*np.diff(xy, axis=0).T).sum()) if len(xy) > 1 else 0.0
        end = (s.x, s.y, s.yaw)
        elapsed = t_end - (self.t_start if self.t_start is not None else self._t_sent)
        ref, score = reference_score(outcome == "succeeded", elapsed, cfg.reference)
        rec = GoalRecord(
            index=0, start=start, goal=cfg.goal, status=mb_status, text=text,
            succeeded=outcome == "succeeded", time_s=elapsed, driven_m=driven,
            shortest_m=ref if ref is not None else math.nan, end=end,
            error_m=math.hypot(end[0] - cfg.goal[0], end[1] - cfg.goal[1]),
            yaw_error=abs(float(wrap_angle(end[2] - cfg.goal[2]))),
            contacts=s.contacts - c0,
            contact_points=list(self.contact_points), planner_calls=len(self.timings.plan_cpu),
            controller_calls=len(self.timings.control_cpu), failures=dict(self.timings.failures),
            recoveries=self.recoveries, path=xy,
        )  # fmt: skip
        return FixedResult(
            name=cfg.name or Path(cfg.world).stem,
            status=outcome,
            record=rec,
            time_s=elapsed,
            reference_m=ref,
            score=score,
            control_ms_p99=_p99_ms(self.timings.control_cpu),
            control_wall_ms_p99=_p99_ms(self.timings.control_wall),
            planner_ms_p99=_p99_ms(self.timings.plan_cpu),
            sim_time_s=t_end,
            cpu_s=time.process_time() - cpu0,
            wall_s=time.perf_counter() - wall0,
            warnings=self.warnings,
            trace=trace,
        )


def episode_files(
    result: FixedResult,
    grid: BenchGrid,
    reference: tuple[tuple[float, float], ...] | None = None,
) -> dict[str, bytes]:
    """``NAME.json``, ``NAME.csv`` (the driven path: t, x, y, yaw) and ``NAME.png`` (the
    world, the reference path, the driven path, the goal even off the world)."""
    name = result.name
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["t_s", "x", "y", "yaw"])
    for row in result.trace:
        w.writerow([f"{v:.3f}" if i == 0 else f"{v:.4f}" for i, v in enumerate(row)])
    img = draw(grid, [result.record], reference=reference)
    png = io.BytesIO()
    img.save(png, format="PNG")
    return {
        f"{name}.json": (json.dumps(result.to_json(), indent=1) + "\n").encode(),
        f"{name}.csv": buf.getvalue().encode(),
        f"{name}.png": png.getvalue(),
    }


def run_fixed(
    cfg: FixedConfig, *, log: Callable[[str], None] = lambda _l: None, write: bool = True
) -> tuple[FixedResult, dict[str, bytes]]:
    """Run one episode; returns its result and files (written into ``cfg.out`` too when
    ``write``, each replaced atomically).

    Raises:
        BenchError, WorldError, SimulationError, LaunchError, ...: bad input, one line.
    """
    cfg.validate()
    _warm_up(cfg)
    ep = _Episode(cfg, log)
    try:
        result = ep.run()
    finally:
        ep.ctx.shutdown()
        ep._tmp.cleanup()
    pts = [cfg.start[:2], cfg.goal[:2]]
    if cfg.reference is not None:
        pts += list(cfg.reference)
    grid = _draw_grid(
        ep.sim, np.vstack([np.asarray(pts, dtype=np.float64), result.record.path]), ep.inscribed
    )
    files = episode_files(result, grid, cfg.reference)
    if write:
        out = Path(cfg.out)
        out.mkdir(parents=True, exist_ok=True)
        for fname, data in files.items():
            atomic_write_bytes(out / fname, data)
    return result, files


def _warm_up(cfg: FixedConfig) -> None:
    """Run a short throw-away episode of ``cfg``'s setup once per process, so numba's
    compilation of the planners' and costmaps' kernels (about a second, cached on disk
    after the first run) is not counted in the first world's control-cycle timings."""
    key = (cfg.planner, cfg.robot, cfg.localization, str(cfg.launch), str(cfg.params_dir))
    if key in _warmed:
        return
    _warmed.add(key)
    ep = _Episode(replace(cfg, time_limit_s=_WARM_UP_S), lambda _line: None)
    try:
        ep.run()
    finally:
        ep.ctx.shutdown()
        ep._tmp.cleanup()
