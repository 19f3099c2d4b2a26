"""The ``explore`` node of explore_lite (m-explore): greedy frontier exploration through
move_base.

Every ``1 / planner_frequency`` s (and at once when a goal ends) it searches the frontiers
of the latest ``costmap_topic`` grid (``OccupancyGrid``, with ``costmap_updates_topic``
patches) from the robot's pose (TF: the grid's frame <- ``robot_base_frame``), takes the
cheapest one not on the blacklist and sends its centroid to ``move_base``. A frontier that
makes no progress (its distance does not shrink) for ``progress_timeout`` s, or whose goal
move_base aborts, is blacklisted (goals within 5 cells of a blacklisted one are skipped,
as explore_lite). With ``visualize`` the frontiers are published as markers on
``~frontiers`` (their cells, blue, red when blacklisted; a sphere at each, sized by cost).
When no frontier is left it cancels move_base's goals and stops ("Exploration stopped.").

Where roverlab differs from explore_lite, on purpose: a target within the blacklist's 5
cells of the goal being pursued is the same goal (explore_lite: within 1 cm). A frontier's
centroid moves by a few cells whenever the map grows; explore_lite then re-sends the goal
and restarts its progress timer, and move_base restarts its patience and oscillation
timers on the new goal, so a robot that cannot get to a frontier chases it for minutes.
And a goal that move_base reached while its frontier is still the one chosen is
blacklisted at once (explore_lite idles for ``progress_timeout`` first).

Parameters (explore_lite's names and defaults): ``robot_base_frame`` base_link,
``costmap_topic`` costmap, ``costmap_updates_topic`` costmap_updates, ``visualize`` false,
``planner_frequency`` 1.0, ``progress_timeout`` 30.0, ``potential_scale`` 1e-3,
``orientation_scale`` 0.0, ``gain_scale`` 1.0, ``transform_tolerance`` 0.3,
``min_frontier_size`` 0.5.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from roverlab.actionlib import GoalStatus, SimpleActionClient
from roverlab.core import Context, Node, QoSProfile, Time
from roverlab.msgs import Marker, MarkerArray, Point
from roverlab.msgs import classes as mc
from roverlab.navigation.explore.frontiers import Frontier, FrontierSearch, occupancy_to_costs
from roverlab.tf import Buffer, Throttle, TransformException, TransformListener

__all__ = ["Explore"]

_BLACKLIST_CELLS = 5
_LATCHED = QoSProfile(depth=1, durability="transient_local")


class Explore(Node):
    """explore_lite's ``explore`` node (see the module docstring).

    Attributes:
        exploring: False once no frontier is left (or none is reachable).
        goals_sent: goals sent to move_base.
        blacklist: the blacklisted goal positions.
        frontiers: the frontiers of the last search.
    """

    def __init__(self, context: Context, *, node_name: str = "explore", **node_kwargs: Any):
        super().__init__(node_name, context=context, **node_kwargs)
        decl = self.declare_parameter
        self.robot_base_frame = str(decl("robot_base_frame", "base_link").value).lstrip("/")
        costmap_topic = str(decl("costmap_topic", "costmap").value)
        updates_topic = str(decl("costmap_updates_topic", "costmap_updates").value)
        self.visualize = bool(decl("visualize", False).value)
        self.planner_frequency = float(decl("planner_frequency", 1.0).value)
        self.progress_timeout = float(decl("progress_timeout", 30.0).value)
        self.transform_tolerance = float(decl("transform_tolerance", 0.3).value)
        self.search = FrontierSearch(
            potential_scale=float(decl("potential_scale", 1e-3).value),
            gain_scale=float(decl("gain_scale", 1.0).value),
            orientation_scale=float(decl("orientation_scale", 0.0).value),
            min_frontier_size=float(decl("min_frontier_size", 0.5).value),
        )
        if not (self.planner_frequency > 0 and math.isfinite(self.planner_frequency)):
            raise ValueError(f"planner_frequency must be > 0, got {self.planner_frequency}")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self._throttle = Throttle(self, 2.0)
        self._grid: np.ndarray | None = None
        self._info: Any = None
        self._frame = "map"
        self.create_subscription(mc.OccupancyGrid, costmap_topic, self._on_grid, _LATCHED)
        self.create_subscription(
            "map_msgs/msg/OccupancyGridUpdate", updates_topic, self._on_update, 10
        )
        self.marker_pub = self.create_publisher(MarkerArray, "~/frontiers", 1)
        self.client = SimpleActionClient(self, "move_base", "move_base_msgs/MoveBaseAction")
        self.exploring = True
        self.goals_sent = 0
        self.blacklist: list[tuple[float, float]] = []
        self.frontiers: list[Frontier] = []
        self._prev_goal: tuple[float, float] | None = None
        self._active_goal: tuple[float, float] | None = None
        self._prev_distance = math.inf
        self._last_progress = 0.0
        self._timer = self.create_timer(1.0 / self.planner_frequency, self.make_plan)
        self._marker_ids = 0

    # ------------------------------------------------------------------ inputs
    def _on_grid(self, msg: Any) -> None:
        info = msg.info
        self._grid = occupancy_to_costs(
            np.asarray(msg.data, dtype=np.int8).reshape(int(info.height), int(info.width))
        )
        self._info = info
        self._frame = str(msg.header.frame_id).lstrip("/") or "map"

    def _on_update(self, msg: Any) -> None:
        grid = self._grid
        if grid is None:
            return
        x, y, w, h = int(msg.x), int(msg.y), int(msg.width), int(msg.height)
        if (
            x < 0
            or y < 0
            or x + w > grid.shape[1]
            or y + h > grid.shape[0]
            or w * h != len(msg.data)
        ):
            self._throttle.warning("update", "costmap update out of the grid's bounds: ignored")
            return
        patch = np.asarray(msg.data, dtype=np.int8).reshape(h, w)
        grid[y : y + h, x : x + w] = occupancy_to_costs(patch)

    def _robot_pose(self) -> tuple[float, float, float] | None:
        try:
            tf, stamp = self.tf_buffer.lookup_transform(self._frame, self.robot_base_frame, Time())
        except TransformException as err:
            self._throttle.warning("tf", f"explore: cannot get the robot's pose: {err}")
            return None
        age = (self.get_clock().now().nanoseconds - stamp.nanoseconds) / 1e9
        if age > self.transform_tolerance:
            self._throttle.warning(
                "stale",
                f"explore: the robot's pose is {age:.2f} s old (transform_tolerance "
                f"{self.transform_tolerance:.2f} s)",
            )
            return None
        se2 = tf.to_se2()
        return se2.x, se2.y, se2.theta

    # ------------------------------------------------------------------ planning
    def _now(self) -> float:
        return self.get_clock().now().nanoseconds / 1e9

    def _blacklisted(self, goal: tuple[float, float]) -> bool:
        return any(self._near(goal, b) for b in self.blacklist)

    def make_plan(self) -> None:
        """explore_lite's ``makePlan``: pick the cheapest frontier and pursue it."""
        if not self.exploring or self._grid is None:
            return
        pose = self._robot_pose()
        if pose is None:
            return
        info = self._info
        origin = (float(info.origin.position.x), float(info.origin.position.y))
        frontiers = self.search.search(
            self._grid, resolution=float(info.resolution), origin=origin, robot=pose
        )
        self.frontiers = frontiers
        if self.visualize:
            self._visualize(frontiers)
        if not frontiers:
            self.stop("no frontiers left")
            return
        frontier = next((f for f in frontiers if not self._blacklisted(f.centroid)), None)
        if frontier is None:
            self.stop("every frontier is blacklisted")
            return
        target = frontier.centroid
        # explore_lite's "same goal" (it compares points with a 1 cm tolerance; see the
        # module docstring for why roverlab uses the blacklist's)
        same_goal = self._prev_goal is not None and self._near(self._prev_goal, target)
        if not same_goal:
            self._prev_goal = target
        now = self._now()
        if not same_goal or self._prev_distance > frontier.min_distance:
            self._last_progress = now
            self._prev_distance = frontier.min_distance
        if now - self._last_progress > self.progress_timeout:
            self.blacklist.append(target)
            self.get_logger().debug("Adding current goal to black list")
            self.make_plan()
            return
        if same_goal and self._active_goal is not None:
            return  # still on its way there
        if same_goal:
            # move_base reached this goal and the frontier is still there: nothing more can
            # be seen from it (explore_lite waits progress_timeout before giving it up)
            self.blacklist.append(target)
            self.get_logger().debug("Goal reached but its frontier is left: black list")
            self._prev_goal = None
            self.make_plan()
            return
        goal = {
            "target_pose": {
                "header": {"frame_id": self._frame, "stamp": self.get_clock().now().to_msg()},
                "pose": {"position": {"x": target[0], "y": target[1]}, "orientation": {"w": 1.0}},
            }
        }
        self.goals_sent += 1
        self._active_goal = target
        self.client.send_goal(goal, done_cb=lambda state, _r: self._reached(state, target))

    def _near(self, a: tuple[float, float], b: tuple[float, float]) -> bool:
        tol = _BLACKLIST_CELLS * float(self._info.resolution)
        return abs(a[0] - b[0]) < tol and abs(a[1] - b[1]) < tol

    def _reached(self, state: int, target: tuple[float, float]) -> None:
        if self._active_goal == target:
            self._active_goal = None
        if state == GoalStatus.ABORTED:
            self.blacklist.append(target)
            self.get_logger().debug("Adding current goal to black list")
        # find the next goal at once, whatever the planning frequency (explore_lite's oneshot)
        self.context.executor.call_soon(self.make_plan)

    def stop(self, why: str = "") -> None:
        """Cancel move_base's goals and stop exploring."""
        if not self.exploring:
            return
        self.exploring = False
        self.client.cancel_all_goals()
        self._timer.cancel()
        self.get_logger().info("Exploration stopped." + (f" ({why})" if why else ""))

    # ------------------------------------------------------------------ markers
    def _visualize(self, frontiers: list[Frontier]) -> None:
        stamp = self.get_clock().now().to_msg()
        markers = []
        costs = [f.cost for f in frontiers]
        lo, hi = (min(costs), max(costs)) if costs else (0.0, 1.0)
        for i, f in enumerate(frontiers):
            black = self._blacklisted(f.centroid)
            pts = Marker(
                header={"frame_id": self._frame, "stamp": stamp},
                ns="frontiers",
                id=2 * i,
                type=Marker.POINTS,
                action=Marker.ADD,
                scale={"x": 0.1, "y": 0.1, "z": 0.1},
                color={"r": 1.0 if black else 0.0, "g": 0.0, "b": 0.0 if black else 1.0, "a": 1.0},
                points=[Point(x=float(x), y=float(y), z=0.0) for x, y in f.points],
                lifetime={"sec": 0, "nanosec": 0},
            )
            size = 0.5 - 0.4 * ((f.cost - lo) / (hi - lo) if hi > lo else 0.0)
            sphere = Marker(
                header={"frame_id": self._frame, "stamp": stamp},
                ns="frontiers",
                id=2 * i + 1,
                type=Marker.SPHERE,
                action=Marker.ADD,
                pose_position_x=f.initial[0],
                pose_position_y=f.initial[1],
                scale={"x": size, "y": size, "z": size},
                color={"r": 0.0, "g": 1.0, "b": 0.0, "a": 1.0},
            )
            markers += [pts, sphere]
        for j in range(2 * len(frontiers), self._marker_ids):
            markers.append(Marker(ns="frontiers", id=j, action=Marker.DELETE))
        self._marker_ids = 2 * len(frontiers)
        self.marker_pub.publish(MarkerArray(markers=markers))
