"""``roverlab demo``: the seeds' whole story in one process.

mybot in seed 003's maze (1) explores with gmapping + move_base + explore_lite, (2) saves
the map as map_saver does, (3) restarts on the saved map with map_server + amcl + move_base
(robot_navigation's navigation_stack.launch, amcl started at the robot's pose in the new
map), (4) patrols places as seed 002's slam.py does, and (5) reports. Each stage is a
method; :meth:`DemoStory.run` runs them in order and returns the :class:`DemoReport`.

The context must be spinning on another thread (``spin_in_thread``): the stages wait on
its clock and swap nodes on the executor's thread.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from roverlab.autonomy.monitor import RunMonitor
from roverlab.autonomy.stack import (
    AutonomyError,
    ExploreStack,
    set_node_params,
    start_explore_stack,
)
from roverlab.charts import write_line_chart
from roverlab.core import Context, Time
from roverlab.description import find_package
from roverlab.launch import Launch, build_launch
from roverlab.launch.xml import load_launch
from roverlab.maps import save_occupancy_grid
from roverlab.maps.plot import write_map_png
from roverlab.msgs import Twist
from roverlab.navigation.move_base.node import MoveBase
from roverlab.navigation.patrol import load_places
from roverlab.navigation.patrol_client import Patroller
from roverlab.slam.data.mapquality import MapQualityError, evaluate_map, grid_from_msg, ground_truth
from roverlab.tf import TransformException

__all__ = ["DemoReport", "DemoStory", "demo_world"]

T = TypeVar("T")


def demo_world() -> Path:
    """Seed 003's maze (bingda_tutorials/world/maze.world)."""
    return find_package("bingda_tutorials") / "world" / "maze.world"


@dataclass
class DemoReport:
    """What the story did: one entry per stage, the figures, the files."""

    stages: dict[str, str] = field(default_factory=dict)  # stage -> "ok" or what failed
    coverage: float = 0.0
    explored_m2: float = 0.0
    map_accuracy: float = math.nan
    patrol_goals: int = 0
    patrol_successes: int = 0
    distance_m: float = 0.0
    sim_s: float = 0.0
    wall_s: float = 0.0
    files: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return bool(self.stages) and all(v == "ok" for v in self.stages.values())

    def lines(self) -> list[str]:
        """The report, a few lines."""
        acc = "n/a" if math.isnan(self.map_accuracy) else f"{100 * self.map_accuracy:.1f}%"
        stages = ", ".join(f"{k} {v}" for k, v in self.stages.items())
        return [
            f"stages: {stages}",
            f"exploration: {self.explored_m2:.1f} m^2 mapped, {100 * self.coverage:.1f}% of "
            f"the reachable maze; map quality (slam mapeval): {acc} of known cells correct",
            f"patrol: {self.patrol_successes}/{self.patrol_goals} goals succeeded",
            f"robot drove {self.distance_m:.1f} m in {self.sim_s:.0f} s of simulated time "
            f"({self.wall_s:.0f} s wall)",
        ]

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["ok"] = self.ok
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in d.items()}  # fmt: skip


@contextlib.contextmanager
def _base_type(name: str) -> Iterator[None]:
    """navigation_stack.launch reads ``$(env BASE_TYPE)`` (seed 003's text): set it while
    the file is read, when the user has not."""
    old = os.environ.get("BASE_TYPE")
    if old is None:
        os.environ["BASE_TYPE"] = name
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("BASE_TYPE", None)


class DemoStory:
    """The demo's stages in ``context`` (see the module docstring).

    Args:
        context: a context spinning on another thread.
        out: the output folder.
        places: how many places to patrol.
        seed: seed of the simulation and the patrol order.
        explore_limit_s: simulated seconds exploration may take.
        goal_timeout_s: simulated seconds per patrol goal.
        log: called with each progress line.
        stop: set to end the story early (the report is still written).
    """

    def __init__(
        self,
        context: Context,
        out: Path,
        *,
        places: int = 4,
        seed: int = 0,
        explore_limit_s: float = 400.0,
        goal_timeout_s: float = 120.0,
        log: Callable[[str], Any] = print,
        stop: threading.Event | None = None,
    ) -> None:
        self.context = context
        self.out = out
        self.places = places
        self.seed = seed
        self.explore_limit_s = explore_limit_s
        self.goal_timeout_s = goal_timeout_s
        self.log = log
        self.stop = stop or threading.Event()
        self.report = DemoReport()
        self.stack: ExploreStack | None = None
        self.monitor: RunMonitor | None = None
        self.navigation: Launch | None = None
        self.map_msg: Any = None
        self._started = time.perf_counter()

    # ------------------------------------------------------------------ helpers
    def on_executor(self, fn: Callable[[], T]) -> T:
        """Run ``fn`` on the executor's thread (node creation and teardown) and wait."""
        done = threading.Event()
        box: list[Any] = []

        def call() -> None:
            try:
                box.append((True, fn()))
            except BaseException as err:  # handed to the caller
                box.append((False, err))
            finally:
                done.set()

        self.context.executor.call_soon_threadsafe(call)
        while not done.wait(0.5):
            if self.context.executor.stopped:
                raise AutonomyError("the demo's context stopped")
        ok, value = box[0]
        if not ok:
            raise value
        return value

    def _stage(self, name: str, fn: Callable[[], bool]) -> bool:
        if self.stop.is_set():
            self.report.stages[name] = "skipped"
            return False
        self.log(f"[{name}] ...")
        try:
            ok = fn()
        except Exception as err:  # one line in the report, the rest of the story is skipped
            self.report.stages[name] = f"failed: {err}"
            self.log(f"[{name}] failed: {err}")
            return False
        if self.stop.is_set() and not ok:
            self.report.stages[name] = "interrupted"
            return False
        self.report.stages[name] = "ok" if ok else "failed"
        return ok

    # ------------------------------------------------------------------ stages
    def start(self) -> None:
        """Start the simulator and the exploring robot (call before spinning)."""
        self.stack = start_explore_stack(
            self.context, world=demo_world(), robot="mybot", slam="gmapping", seed=self.seed
        )
        self.monitor = RunMonitor(self.context, self.stack.simulation)

    def explore(self) -> bool:
        assert self.stack is not None and self.monitor is not None
        explore, monitor = self.stack.explore, self.monitor
        self.context.wait_for(
            lambda: self.stop.is_set() or not explore.exploring, self.explore_limit_s
        )
        done = not explore.exploring
        fraction = monitor.coverage[-1].fraction if monitor.coverage else 0.0
        self.log(
            f"[explore] {'no frontier left' if done else 'stopped'} after "
            f"{self.context.now().seconds:.0f} s: {100 * fraction:.1f}% of the maze known, "
            f"{explore.goals_sent} frontier goals"
        )
        return done and fraction >= 0.9

    def save_map(self) -> bool:
        assert self.monitor is not None
        self.map_msg = self.monitor.map_msg
        if self.map_msg is None:
            raise AutonomyError("gmapping published no map")
        saved = save_occupancy_grid(self.out / "map", self.map_msg)
        self.report.files += [str(saved.yaml_path), str(saved.image_path)]
        self.log(f"[save_map] wrote {saved.yaml_path} and {saved.image_path} (as map_saver)")
        return True

    def _pose_in_map(self) -> tuple[float, float, float]:
        assert self.stack is not None
        tf, _ = self.stack.explore.tf_buffer.lookup_transform("map", "base_footprint", Time())
        p = tf.to_se2()
        return p.x, p.y, p.theta

    def restart(self) -> bool:
        assert self.stack is not None
        stack = self.stack
        try:
            x, y, a = self.on_executor(self._pose_in_map)
        except TransformException as err:
            raise AutonomyError(f"no robot pose in the map frame: {err}") from err
        self.on_executor(stack.destroy_navigation)
        self.on_executor(lambda: self.context.create_node("demo_stop").create_publisher(
            Twist, "/cmd_vel", 1).publish(Twist()))  # fmt: skip
        with _base_type("NanoRobot"):
            spec = load_launch(
                find_package("robot_navigation") / "launch" / "navigation_stack.launch",
                {"simulation": "true", "map_file": str(self.out / "map.yaml")},
            )
        set_node_params(
            spec, "amcl", {"initial_pose_x": x, "initial_pose_y": y, "initial_pose_a": a}
        )
        self.navigation = self.on_executor(
            lambda: build_launch(spec, context=self.context, seed=self.seed)
        )
        (move_base,) = [n for n in self.navigation.nodes if isinstance(n, MoveBase)]
        ready = self.context.wait_for(
            lambda: self.stop.is_set() or move_base.global_costmap.ready, 30.0
        )
        self.log(
            f"[restart] map_server + amcl (at x {x:.2f}, y {y:.2f}, yaw {math.degrees(a):.0f} "
            f"deg) + move_base on the saved map"
        )
        return ready and move_base.global_costmap.ready

    def patrol(self) -> bool:
        frame, places = load_places(find_package("robot_navigation") / "config" / "patrol.yaml")
        node = self.on_executor(lambda: self.context.create_node("patrol"))
        cmd = node.create_publisher(Twist, "/cmd_vel", 1)
        patroller = Patroller(
            node, places, frame, rng=np.random.default_rng(self.seed), rest_time=1.0,
            timeout=self.goal_timeout_s, log=lambda s: self.log(f"[patrol] {s}"),
        )  # fmt: skip
        patroller.stop = self.stop
        try:
            patroller.wait_for_server(30.0)
            if not self.stop.is_set():
                patroller.run(self.places)
        finally:
            patroller.shutdown(lambda: cmd.publish(Twist()))
        stats = patroller.stats
        self.report.patrol_goals, self.report.patrol_successes = stats.goals, stats.successes
        stats_path = self.out / "patrol.json"
        _write_json(stats_path, {
            "goals": stats.goals, "successes": stats.successes,
            "distance_m": round(stats.distance_m, 3), "places": [p.name for p in places],
        })  # fmt: skip
        self.report.files.append(str(stats_path))
        return stats.goals == self.places and stats.successes == stats.goals

    # ------------------------------------------------------------------ report
    def finish(self) -> DemoReport:
        """Score the map, draw the pictures, write report.json (also after a failure)."""
        r, monitor = self.report, self.monitor
        r.sim_s = round(self.context.now().seconds, 1)
        r.wall_s = round(time.perf_counter() - self._started, 1)
        if monitor is None or self.stack is None:
            return r
        monitor.sample()
        r.distance_m = round(monitor.distance_m, 2)
        msg = self.map_msg if self.map_msg is not None else monitor.map_msg
        if msg is not None:
            grid = grid_from_msg(msg)
            area = monitor.reachable(grid.resolution)
            r.coverage = round(area.known_fraction(grid), 4)
            r.explored_m2 = round(float(np.count_nonzero(np.asarray(grid.data) >= 0))
                                  * grid.resolution**2, 2)  # fmt: skip
            gt = ground_truth(self.stack.simulation.world_model, resolution=grid.resolution,
                              z_m=monitor.lidar_z_m)  # fmt: skip
            with contextlib.suppress(MapQualityError):
                r.map_accuracy = round(evaluate_map(grid, gt, prior=monitor.spawn).accuracy, 4)
            write_map_png(self.out / "map.png", np.asarray(grid.data), grid.resolution,
                          grid.origin_xy, monitor.map_path)  # fmt: skip
            r.files.append(str(self.out / "map.png"))
        samples = monitor.coverage
        write_line_chart(
            self.out / "coverage.png",
            [([s.t for s in samples], [100 * s.fraction for s in samples], (30, 90, 200),
              "gmapping: known share of the reachable maze")],
            title="roverlab demo: exploration", xlabel="simulated time (s)",
            ylabel="% known", y_range=(0.0, 100.0), hline=(95.0, "95%"),
        )  # fmt: skip
        r.files.append(str(self.out / "coverage.png"))
        report_path = self.out / "report.json"
        r.files.append(str(report_path))
        _write_json(report_path, r.to_dict())
        return r

    def run(self) -> DemoReport:
        """Every stage in order (a failed stage skips the rest), then :meth:`finish`."""
        self.out.mkdir(parents=True, exist_ok=True)
        failed = False
        for name, fn in (
            ("explore", self.explore),
            ("save_map", self.save_map),
            ("restart", self.restart),
            ("patrol", self.patrol),
        ):
            if failed:
                self.report.stages[name] = "skipped"
            elif not self._stage(name, fn):
                failed = True
        return self.finish()


def _write_json(path: Path, data: Any) -> None:
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(path)
