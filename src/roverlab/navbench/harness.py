"""The navigation benchmark: simulator + map_server + amcl (or fake_localization) +
move_base in one context on simulated time, as fast as the CPU allows, driven through
seeded random goals by a SimpleActionClient.

The simulator comes from :class:`~roverlab.sim.app.Simulation` (no cameras: nothing here
looks at images); the navigation nodes from ``robot_navigation``'s ``nav_bench.launch``
with the robot's parameter set (the files ``navigation_stack.launch`` uses). Without a
map the world is rasterised at 0.05 m in the robot's height band and saved as
``DIR/map.yaml`` (what map_server then serves).
"""

from __future__ import annotations

import dataclasses
import math
import signal
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.actionlib.status import STATUS_NAMES
from roverlab.core import Context
from roverlab.description import find_package
from roverlab.errors import RoverlabError
from roverlab.geometry import wrap_angle
from roverlab.launch import build_launch
from roverlab.maps import load_map, save_map
from roverlab.navbench.grid import BenchGrid, sample_goals
from roverlab.navbench.report import BenchReport, GoalRecord
from roverlab.navigation.costmap import make_layered_costmap
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.move_base.node import MoveBase
from roverlab.sim.app import Simulation
from roverlab.sim.node import SimulatorNode, SpawnPose
from roverlab.world import World, load_world

PLANNERS = ("dwa", "teb")
LOCALIZATIONS = ("amcl", "ground_truth")
#: robot -> robot_navigation/param/<set> (navigation_stack.launch's $BASE_TYPE)
PARAM_SETS = {"mybot": "NanoRobot"}
#: a SUCCEEDED goal counts only when the true position is this close to the goal
SUCCESS_RADIUS_M = 0.25
MAP_RESOLUTION = 0.05
_SAMPLE_PERIOD_S = 0.05  # ground-truth samples for the driven length
_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class BenchError(RoverlabError):
    """A benchmark that cannot run as asked (bad option, no parameter set, no goals)."""


@dataclass(frozen=True)
class BenchConfig:
    """What ``roverlab nav bench`` was asked.

    Args:
        world: a bundled world name or a world file (.world, .sdf, YAML, map YAML).
        out: output folder (created).
        robot: a bundled robot or a URDF/xacro file.
        map_yaml: the map for map_server and amcl (None: rasterised from the world).
        planner: the local planner, ``dwa`` or ``teb``.
        localization: ``amcl`` or ``ground_truth`` (fake_localization).
        goals: how many goals.
        seed: seeds the goals, the simulator and amcl.
        goal_timeout_s: per goal, simulated seconds (None: 60 s + 5 s per metre of the
            shortest path).
        params_dir: a folder with robot_navigation's parameter files (None: the robot's
            set in :data:`PARAM_SETS`).
    """

    world: str
    out: Path
    robot: str = "mybot"
    map_yaml: Path | None = None
    planner: str = "dwa"
    localization: str = "amcl"
    goals: int = 100
    seed: int = 0
    goal_timeout_s: float | None = None
    params_dir: Path | None = None

    def validate(self) -> Path:
        """Check the options; returns the parameter folder.

        Raises:
            BenchError: one line naming the bad option.
        """
        if self.planner not in PLANNERS:
            raise BenchError(f"unknown planner {self.planner!r}: use {' or '.join(PLANNERS)}")
        if self.localization not in LOCALIZATIONS:
            raise BenchError(
                f"unknown localization {self.localization!r}: use {' or '.join(LOCALIZATIONS)}"
            )
        if self.goals < 1:
            raise BenchError(f"--goals must be at least 1, got {self.goals}")
        if self.goal_timeout_s is not None and not self.goal_timeout_s > 0:
            raise BenchError(f"--goal-timeout must be > 0 s, got {self.goal_timeout_s}")
        if self.map_yaml is not None and not Path(self.map_yaml).is_file():
            raise BenchError(f"{self.map_yaml}: map file not found")
        if self.params_dir is not None:
            d = Path(self.params_dir)
            if not d.is_dir():
                raise BenchError(f"{d}: parameter folder not found")
            return d
        if self.robot not in PARAM_SETS:
            raise BenchError(
                f"no navigation parameters for robot {self.robot!r} (bundled: "
                f"{', '.join(sorted(PARAM_SETS))}); give a folder of robot_navigation "
                "parameter files with --params"
            )
        return find_package("robot_navigation") / "param" / PARAM_SETS[self.robot]


@dataclass
class _Stop:
    signum: int | None = None

    def __call__(self, signum: int, _frame: FrameType | None) -> None:
        self.signum = signum


@contextmanager
def _signals(stop: _Stop) -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP set ``stop`` (main thread only; elsewhere a no-op)."""
    try:
        old = {s: signal.signal(s, stop) for s in _SIGNALS}
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)


@dataclass
class _Timings:
    plan_cpu: list[float] = field(default_factory=list)
    plan_wall: list[float] = field(default_factory=list)
    control_cpu: list[float] = field(default_factory=list)
    control_wall: list[float] = field(default_factory=list)
    #: failure texts of the planners since the last reset, counted
    failures: dict[str, int] = field(default_factory=dict)

    def __call__(self, kind: str, wall: float, cpu: float, error: str | None) -> None:
        if kind == "plan":
            self.plan_cpu.append(cpu)
            self.plan_wall.append(wall)
        else:
            self.control_cpu.append(cpu)
            self.control_wall.append(wall)
        if error is not None:
            key = f"{kind}: {error}"
            self.failures[key] = self.failures.get(key, 0) + 1


def _map_for(
    world: World, sim: Simulation, out: Path, points: tuple[tuple[float, float], ...] = ()
) -> Path:
    """The world rasterised in the robot's height band (collisions and lidars), saved as
    ``out/map.yaml``; the map also covers ``points`` (a start and goal off the world's
    geometry) with 1 m around them."""
    cfg = sim.config
    z_lo, z_hi = cfg.height_band
    for lidar in cfg.lidars:
        z_hi = max(z_hi, sim.simulator.sensor_pose(lidar.mount)[2])
    bounds = None
    if points:
        b = world.bounds
        xs = [b[0] - 0.5, b[2] + 0.5, *(p[0] for p in points)]
        ys = [b[1] - 0.5, b[3] + 0.5, *(p[1] for p in points)]
        res = MAP_RESOLUTION
        bounds = (
            math.floor((min(xs) - 1.0) / res) * res, math.floor((min(ys) - 1.0) / res) * res,
            max(xs) + 1.0, max(ys) + 1.0,
        )  # fmt: skip
    occ, origin = world.occupancy(MAP_RESOLUTION, z_lo, z_hi, bounds=bounds)
    saved = save_map(
        out / "map",
        np.where(occ, 100, 0).astype(np.int8),
        resolution=MAP_RESOLUTION,
        origin=(origin[0], origin[1], 0.0),
    )
    return Path(saved.yaml_path)


def _goal_msg(x: float, y: float, yaw: float) -> dict[str, Any]:
    return {
        "target_pose": {
            "header": {"frame_id": "map"},
            "pose": {
                "position": {"x": x, "y": y},
                "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)},
            },
        }
    }


def _bench_grid(move_base: MoveBase, map_yaml: Path, spawn: SpawnPose) -> BenchGrid:
    """The global costmap's grid from the map alone (its obstacle layers get no data)."""
    layered = make_layered_costmap(move_base.global_costmap.params)
    m = load_map(map_yaml)
    for layer in layered.plugins:
        if hasattr(layer, "incoming_map"):
            layer.incoming_map(
                np.asarray(m.data, dtype=np.int8),
                resolution=m.info.resolution,
                origin_x=m.info.origin[0],
                origin_y=m.info.origin[1],
            )
    layered.update_map(spawn.x, spawn.y, spawn.yaw)
    cm = layered.costmap
    return BenchGrid(cm.costs.copy(), cm.resolution, (cm.origin_x, cm.origin_y))


class _Bench:
    """One benchmark run (see :func:`run_bench`)."""

    def __init__(self, config: BenchConfig, params_dir: Path, log: Callable[[str], None]):
        self.config = config
        self.log = log
        self.ctx = Context()
        self.world = load_world(config.world)
        spawn = self.world.spawn
        self.spawn = SpawnPose(spawn.x, spawn.y, spawn.theta)
        self.sim = Simulation(
            self.ctx, world=self.world, robot=config.robot, spawn=self.spawn,
            seed=config.seed, cameras=False,
        )  # fmt: skip
        out = Path(config.out)
        out.mkdir(parents=True, exist_ok=True)
        self.map_yaml = (
            Path(config.map_yaml) if config.map_yaml else _map_for(self.world, self.sim, out)
        )
        launch = build_launch(
            find_package("robot_navigation") / "launch" / "nav_bench.launch",
            {
                "map_file": str(self.map_yaml.resolve()),
                "param_dir": str(params_dir.resolve()),
                "planner": config.planner,
                "localization": config.localization,
                "base_frame": self.sim.config.drive.robot_base_frame
                if self.sim.config.drive
                else "base_link",
                "initial_pose_x": repr(self.spawn.x),
                "initial_pose_y": repr(self.spawn.y),
                "initial_pose_a": repr(self.spawn.yaw),
                "seed": str(config.seed),
            },
            context=self.ctx,
            seed=config.seed,
        )
        for w in launch.warnings:
            self.log(f"warning: {w}")
        (self.move_base,) = [n for n in launch.nodes if isinstance(n, MoveBase)]
        self.timings = _Timings()
        self.move_base.timing_hook = self.timings
        self.simulator: SimulatorNode = self.sim.simulator
        node = self.ctx.create_node("nav_bench")
        self.client = SimpleActionClient(node, "move_base", "move_base_msgs/MoveBaseAction")
        self._trace: list[tuple[float, float, float]] = []
        self._contact_points: list[tuple[float, float]] = []
        self._contacts = 0
        self._mb_state = ""
        self._recoveries = 0
        node.create_timer(_SAMPLE_PERIOD_S, self._sample)
        self.grid = _bench_grid(self.move_base, self.map_yaml, self.spawn)
        fp = self.move_base.global_costmap.footprint
        self.robot_radius = footprint_radii(fp)[1]

    def _sample(self) -> None:
        s = self.simulator
        self._trace.append((s.x, s.y, s.yaw))
        state = self.move_base.state
        if state == "CLEARING" and self._mb_state != "CLEARING":
            self._recoveries += 1
        self._mb_state = state
        c = s.contacts
        if c != self._contacts:
            self._contacts = c
            self._contact_points.append((s.x, s.y))

    def _wait(self, cond: Callable[[], bool], timeout_s: float, stop: _Stop) -> bool:
        self.ctx.wait_for(lambda: cond() or stop.signum is not None, timeout_s)
        return cond()

    def ready(self, stop: _Stop) -> None:
        """Wait for the action server, the map in the global costmap and a localized
        robot pose.

        Raises:
            BenchError: not within 60 simulated seconds.
        """
        mb = self.move_base
        ok = self._wait(
            lambda: mb.global_costmap.ready and mb.global_costmap.get_robot_pose() is not None,
            60.0,
            stop,
        )
        if not ok and stop.signum is None:
            raise BenchError("move_base did not get its map and a robot pose within 60 s")
        if not self.client.wait_for_server(10.0) and stop.signum is None:
            raise BenchError("move_base's action server did not come up")

    def run_goal(self, index: int, goal: np.ndarray, stop: _Stop) -> GoalRecord | None:
        """Drive to ``goal``; None when interrupted."""
        s = self.simulator
        start = (s.x, s.y, s.yaw)
        shortest = self.grid.shortest_path(start[:2], (goal[0], goal[1]))
        timeout = self.config.goal_timeout_s or 60.0 + 5.0 * (
            shortest if math.isfinite(shortest) else 0.0
        )
        self._trace = [start]
        self._contact_points = []
        self._recoveries = 0
        c0 = s.contacts
        self._contacts = c0
        n_plan, n_ctrl = len(self.timings.plan_cpu), len(self.timings.control_cpu)
        self.timings.failures = {}
        t0 = self.ctx.now().nanoseconds
        self.client.send_goal(_goal_msg(*map(float, goal)))
        done = self._wait(self._done, timeout, stop)
        if stop.signum is not None and not done:
            self.client.cancel_goal()
            self._wait(self._done, 5.0, _Stop())
            return None
        status = "TIMEOUT"
        if done:
            status = STATUS_NAMES[self.client.get_state()]
        else:
            self.client.cancel_goal()
            self._wait(self._done, 10.0, _Stop())
        elapsed = (self.ctx.now().nanoseconds - t0) / 1e9
        self._sample()
        trace = np.array(self._trace)
        driven = float(np.hypot(*np.diff(trace[:, :2], axis=0).T).sum()) if len(trace) > 1 else 0.0
        end = (s.x, s.y, s.yaw)
        err = math.hypot(end[0] - goal[0], end[1] - goal[1])
        ok = status == "SUCCEEDED" and err <= SUCCESS_RADIUS_M
        return GoalRecord(
            index=index,
            start=start,
            goal=(float(goal[0]), float(goal[1]), float(goal[2])),
            status=status,
            text=self.client.get_goal_status_text() if done else "goal timeout: canceled",
            succeeded=ok,
            time_s=elapsed,
            driven_m=driven,
            shortest_m=shortest,
            end=end,
            error_m=err,
            yaw_error=abs(float(wrap_angle(end[2] - float(goal[2])))),
            contacts=s.contacts - c0,
            contact_points=list(self._contact_points),
            planner_calls=len(self.timings.plan_cpu) - n_plan,
            controller_calls=len(self.timings.control_cpu) - n_ctrl,
            failures=dict(self.timings.failures),
            recoveries=self._recoveries,
            path=trace[:, :2],
        )

    def _done(self) -> bool:
        st = self.client.get_state()
        return st not in (GoalStatus.PENDING, GoalStatus.ACTIVE)


#: summary keys that are measured compute times (or describe the machine): everything else
#: in a run's results is a function of the configuration and the seed
TIMING_KEYS = (
    "planner_ms_p99",
    "controller_ms_p99",
    "planner_wall_ms_p99",
    "controller_wall_ms_p99",
    "wall_time_s",
    "machine",
)


def run_bench(
    config: BenchConfig,
    *,
    log: Callable[[str], None] = lambda _line: None,
) -> BenchReport:
    """Run the benchmark; writes ``bench.json`` after every goal and ``bench.png`` at the
    end (both replaced atomically) into ``config.out``. SIGINT, SIGTERM and SIGHUP end it
    after writing the goals done so far (``report.interrupted`` names the signal).

    Everything but the :data:`TIMING_KEYS` is the same for the same configuration and
    seed: the simulator, amcl and the goals draw from generators seeded by
    ``config.seed`` and every node runs on the simulated clock.

    Raises:
        BenchError, WorldError, SimulationError, MapError, LaunchError, GoalSamplingError:
            bad input, as one line.
    """
    params_dir = config.validate()
    wall0 = time.perf_counter()
    stop = _Stop()
    out = Path(config.out)
    with _signals(stop):
        bench = _Bench(config, params_dir, log)
        try:
            report = BenchReport(
                config=config,
                map_yaml=bench.map_yaml,
                grid=bench.grid,
                local_planner=bench.move_base.params.base_local_planner,
            )
            spawn = (bench.spawn.x, bench.spawn.y)
            clearance = bench.robot_radius + 0.1
            goals = sample_goals(
                bench.grid, spawn, config.goals, np.random.default_rng(config.seed),
                clearance=clearance,
            )  # fmt: skip

            def totals() -> None:
                report.set_totals(
                    timings=bench.timings,
                    collisions=bench.simulator.contacts,
                    sim_time_s=bench.ctx.now().nanoseconds / 1e9,
                    wall_time_s=time.perf_counter() - wall0,
                )

            bench.ready(stop)
            for i, goal in enumerate(goals):
                if stop.signum is not None:
                    break
                rec = bench.run_goal(i, goal, stop)
                if rec is None:
                    break
                report.add(rec)
                totals()
                report.write_json(out / "bench.json")
                log(rec.progress_line(len(goals)))
            if stop.signum is not None:
                report.interrupted = signal.Signals(stop.signum).name
            totals()
            report.write_json(out / "bench.json")
            report.write_png(out / "bench.png")
        finally:
            bench.ctx.shutdown()
    return report


def run_episode(
    config: BenchConfig,
    seed: int,
    *,
    log: Callable[[str], None] = lambda _line: None,
) -> dict[str, Any]:
    """One episode of a multi-episode benchmark: :func:`run_bench` with ``config``'s seed
    replaced by ``seed``, writing into ``config.out / f"seed-{seed:04d}"``; returns what
    ``bench.json`` holds (the summary and one record per goal).

    A plain function of picklable arguments, one context per call (a worker process can
    run it as a task); the result is the same for the same ``config`` and ``seed`` but for
    the :data:`TIMING_KEYS`.
    """
    cfg = dataclasses.replace(config, seed=seed, out=Path(config.out) / f"seed-{seed:04d}")
    return run_bench(cfg, log=log).to_dict()
