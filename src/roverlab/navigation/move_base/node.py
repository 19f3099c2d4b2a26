"""The ``move_base`` node: the MoveBase action over two costmaps, a global and a local
planner and the recovery behaviours, with move_base's state machine (ROS 1 move_base.cpp).

* **Action** ``move_base`` (``move_base_msgs/MoveBaseAction``, a SimpleActionServer in
  callback mode: no thread, deterministic), feedback ``base_position``; goals also from
  ``move_base_simple/goal`` (``PoseStamped``, rviz's 2D Nav Goal), sent to the action as
  move_base does. A new goal preempts the current one; a cancel stops the robot and ends
  the goal PREEMPTED.
* **States** PLANNING, CONTROLLING, CLEARING every ``1 / controller_frequency`` s:
  plan on the global costmap (``planner_patience``, ``max_planning_retries``;
  ``planner_frequency`` replans while controlling); control with the local planner on the
  local costmap (``controller_patience``; the plan turned into the local costmap's frame
  each cycle); ``oscillation_timeout`` / ``oscillation_distance``; out-of-date sensor data
  (``expected_update_rate``) stops the base; recoveries in order, then ABORTED with
  move_base's texts ("Failed to find a valid plan. Even after executing recovery
  behaviors." ...).
* **Topics** ``cmd_vel``; ``~current_goal``; the plans on ``~<GlobalPlanner>/plan`` and
  ``~<LocalPlanner>/global_plan`` / ``local_plan``; the costmaps on
  ``~global_costmap/costmap`` and ``~local_costmap/costmap`` (+ updates, footprint).
* **Services** ``~make_plan`` (``nav_msgs/GetPlan``) and ``~clear_costmaps``
  (``std_srvs/Empty``).

Differences from ROS 1, on purpose: a goal in a frame TF cannot turn into the global
frame is aborted with that reason (ROS uses it untransformed); a goal outside a static
global costmap is aborted at once (ROS plans, fails and recovers for ``planner_patience``
plus every recovery first); the clear_costmap recoveries clear every obstacle layer
unless ``layer_names`` says otherwise (ROS 1 clears only layers named ``obstacles``); a
failed plan in the PLANNING state stops the robot (ROS 1 leaves the last velocity command
in force until ``planner_patience`` runs out, so a robot whose new goal cannot be planned
drove on blind).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any, cast

import numpy as np

from roverlab.actionlib import SimpleActionServer
from roverlab.core import Context, Node, Time
from roverlab.geometry import SE2
from roverlab.msgs import Path, PoseStamped, Twist, pose_from_xytheta, xytheta_from_pose
from roverlab.msgs import builders as build
from roverlab.msgs import classes as mc
from roverlab.navigation.controllers import Velocity2D
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.costmap.node import Costmap2DROS
from roverlab.navigation.costmap.static_layer import StaticLayer
from roverlab.navigation.errors import (
    ControllerError,
    GoalOutsideMapBoundsError,
    NavigationError,
    PlannerError,
)
from roverlab.navigation.move_base.params import GLOBAL_PLANNERS, LOCAL_PLANNERS, MoveBaseParams
from roverlab.navigation.move_base.plugins import (
    make_global_planner,
    make_local_planner,
    make_recovery,
    plugin_short_name,
    rotate_fallback,
)
from roverlab.navigation.move_base.potential import PotentialPublisher
from roverlab.navigation.move_base.recovering import Recovering
from roverlab.navigation.node_params import parameters_under
from roverlab.navigation.planners import Path2D, path_to_msg
from roverlab.navigation.planners.footprint_check import plan_clear_of_footprint
from roverlab.tf import Buffer, Throttle, TransformException, TransformListener

__all__ = ["MoveBase", "TimingHook"]

PLANNING, CONTROLLING, CLEARING = "PLANNING", "CONTROLLING", "CLEARING"
PLANNING_R, CONTROLLING_R, OSCILLATION_R = "PLANNING_R", "CONTROLLING_R", "OSCILLATION_R"
ABORT_TEXTS = {
    PLANNING_R: "Failed to find a valid plan. Even after executing recovery behaviors.",
    CONTROLLING_R: "Failed to find a valid control. Even after executing recovery behaviors.",
    OSCILLATION_R: "Robot is oscillating. Even after executing recovery behaviors.",
}
_INVALID_QUATERNION = "Aborting on goal because it was sent with an invalid quaternion"


def _quaternion_ok(q: Any) -> bool:
    """move_base's isQuaternionValid: finite, not near zero length, z axis vertical."""
    v = np.array([q.x, q.y, q.z, q.w], dtype=np.float64)
    if not np.isfinite(v).all():
        return False
    n = float(np.linalg.norm(v))
    if n < 1e-6:
        return False
    x, y = (v / n)[:2]
    # the rotated z axis' z component: 1 - 2(x^2 + y^2)
    return abs((1.0 - 2.0 * (x * x + y * y)) - 1.0) < 1e-3


#: ``hook(kind, wall_s, cpu_s, error)``: see ``MoveBase.timing_hook``
TimingHook = Callable[[str, float, float, str | None], None]


class _Timed:
    """Times a block (wall and this thread's CPU time) for ``MoveBase.timing_hook``."""

    __slots__ = ("cpu", "hook", "kind", "wall")

    def __init__(self, hook: TimingHook | None, kind: str) -> None:
        self.hook, self.kind = hook, kind
        self.wall = self.cpu = 0.0

    def __enter__(self) -> None:
        if self.hook is not None:
            self.wall, self.cpu = time.perf_counter(), time.thread_time()

    def __exit__(self, _type: object, exc: BaseException | None, _tb: object) -> None:
        if self.hook is not None:
            wall, cpu = time.perf_counter() - self.wall, time.thread_time() - self.cpu
            self.hook(self.kind, wall, cpu, None if exc is None else str(exc))


class MoveBase(Node):
    """``move_base``: see the module docstring.

    Args:
        context: the context the node joins.
        node_name: defaults to ``move_base``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (the launch file's private
            parameters, costmap and planner ones under their names), ``remappings``.

    Raises:
        NavigationParamsError: an unknown plugin or a bad parameter, named.
    """

    def __init__(self, context: Context, *, node_name: str = "move_base", **node_kwargs: Any):
        super().__init__(node_name, context=context, **node_kwargs)
        top = {
            k: self.declare_parameter(k, None).value
            for k in self.unused_parameter_overrides()
            if "/" not in k and "." not in k
        }
        self.params, mb_warnings = MoveBaseParams.from_ros(top)
        p = self.params
        log = self.get_logger()
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.global_costmap = Costmap2DROS(self, "global_costmap", self.tf_buffer)
        self.local_costmap = Costmap2DROS(self, "local_costmap", self.tf_buffer)
        self.global_frame = self.global_costmap.global_frame
        gname = plugin_short_name(p.base_global_planner)
        self.planner, warnings = make_global_planner(
            p.base_global_planner, parameters_under(self, gname)
        )
        lname = plugin_short_name(p.base_local_planner)
        lvalues = parameters_under(self, lname)
        body = self.local_costmap.params.unpadded_footprint()
        self.controller, limits, w2 = make_local_planner(
            p.base_local_planner,
            lvalues,
            footprint=self.local_costmap.footprint,
            body_footprint=body,
            controller_frequency=p.controller_frequency,
        )
        for w in (*mb_warnings, *warnings, *w2):
            log.warning(w)
        _inscribed, circumscribed = footprint_radii(self.global_costmap.footprint)
        tp = parameters_under(self, "TrajectoryPlannerROS")
        made = [
            make_recovery(
                r.name,
                r.type,
                parameters_under(self, r.name),
                default_reset_distance=(
                    4.0 * circumscribed
                    if r.name == "aggressive_reset"
                    else p.conservative_reset_dist
                ),
                limits=limits,
                trajectory_planner=tp,
                footprint=self.local_costmap.footprint,
                body_footprint=body,
            )
            for r in p.recoveries
        ]
        self.recoveries = [rec for rec, _ in made]
        for _, rw in made:
            for w in rw:
                log.warning(w)
        # parameters of the planners not in use (a launch file loads both dwa and teb files,
        # as seed 003's does): ROS keeps them on the parameter server unread; so do we
        idle = {plugin_short_name(n) for n in (*GLOBAL_PLANNERS, *LOCAL_PLANNERS)} - {gname, lname}
        self.discard_parameter_overrides(
            k for k in self.unused_parameter_overrides() if k.split("/")[0].split(".")[0] in idle
        )
        self._throttle = Throttle(self, 1.0)
        self.cmd_pub = self.create_publisher(Twist, "cmd_vel", 1)
        self.goal_pub = self.create_publisher(PoseStamped, "~/current_goal", 1)
        self.plan_pub = self.create_publisher(Path, f"~/{gname}/plan", 1)
        self.potential_pub = PotentialPublisher(self, gname, self.planner)
        self.local_global_plan_pub = self.create_publisher(Path, f"~/{lname}/global_plan", 1)
        self.local_plan_pub = self.create_publisher(Path, f"~/{lname}/local_plan", 1)
        self.server = SimpleActionServer(self, "move_base", "move_base_msgs/MoveBaseAction")
        self.server.register_goal_callback(self._on_goal)
        self.server.register_preempt_callback(self._on_preempt)
        self._simple_goal_pub = self.create_publisher(
            self.server.spec.ActionGoal, "move_base/goal", 1
        )
        self._simple_goals = 0
        self.create_subscription(PoseStamped, "move_base_simple/goal", self._on_simple_goal, 1)
        self._twist = Velocity2D()
        # the local planner's odom_topic (base_local_planner's OdometryHelperRos)
        odom_topic = str(lvalues.get("odom_topic", "odom"))
        self.create_subscription(mc.Odometry, odom_topic, self._on_odom, 1)
        self.create_service("nav_msgs/GetPlan", "~/make_plan", self._on_make_plan)
        self.create_service("std_srvs/Empty", "~/clear_costmaps", self._on_clear_costmaps)
        self.create_timer(1.0 / p.controller_frequency, self._cycle)
        # per-goal state
        self.goal: SE2 | None = None
        self.plan: np.ndarray | None = None
        self.state = PLANNING
        self.recovery_trigger = PLANNING_R
        self.recovery_index = 0
        self.recovering = Recovering(
            self, rotate_fallback(limits, self.local_costmap.footprint, body)
        )
        self._last_valid_plan = 0.0
        self._last_valid_control = 0.0
        self._last_oscillation_reset = 0.0
        self._last_plan_time = 0.0
        self._oscillation_pose: SE2 | None = None
        self._planning_retries = 0
        self.goals_succeeded = 0
        self.goals_aborted = 0
        self.last_result_text = ""
        #: called as ``timing_hook(kind, wall_s, cpu_s, error)`` after every global
        #: planner call (``"plan"``) and local planner call (``"control"``) of the action,
        #: with its wall and CPU time; ``error`` is the failure's text (no plan, no valid
        #: command) or None
        self.timing_hook: TimingHook | None = None
        if p.shutdown_costmaps:
            self.global_costmap.stop()
            self.local_costmap.stop()

    # ------------------------------------------------------------------ helpers
    def _now(self) -> float:
        return self.get_clock().now().nanoseconds / 1e9

    def publish_zero_velocity(self) -> None:
        self.cmd_pub.publish(Twist())

    def _on_odom(self, msg: Any) -> None:
        t = msg.twist.twist
        self._twist = Velocity2D(float(t.linear.x), float(t.linear.y), float(t.angular.z))

    def _to_global(self, target: Any) -> SE2:
        """A PoseStamped goal in the global frame (the latest transform, as move_base)."""
        frame = str(target.header.frame_id).lstrip("/") or self.global_frame
        pose = SE2(*xytheta_from_pose(target.pose))
        if frame == self.global_frame:
            return pose
        tf, _ = self.tf_buffer.lookup_transform(self.global_frame, frame, Time())
        return tf.to_se2() * pose

    def _plan_in_local_frame(self) -> np.ndarray:
        """The global plan turned into the local costmap's frame (transformGlobalPlan)."""
        assert self.plan is not None
        lf = self.local_costmap.global_frame
        if lf == self.global_frame:
            return self.plan
        tf, _ = self.tf_buffer.lookup_transform(lf, self.global_frame, Time())
        t = tf.to_se2()
        xy = t.apply(self.plan[:, :2])
        yaw = np.arctan2(np.sin(self.plan[:, 2] + t.theta), np.cos(self.plan[:, 2] + t.theta))
        return np.column_stack([xy, yaw])

    def _publish_path(self, pub: Any, path: np.ndarray, frame: str) -> None:
        if not pub.has_listeners:  # a Path of every pose each cycle: only for a reader
            return
        pub.publish(path_to_msg(path, frame, self.get_clock().now()))

    # ------------------------------------------------------------------ goals
    def _on_simple_goal(self, msg: Any) -> None:
        """rviz's 2D Nav Goal: wrapped into an action goal, as move_base does."""
        self._simple_goals += 1
        now = self.get_clock().now()
        ag = self.server.spec.ActionGoal()
        ag.header.stamp = now.to_msg()
        ag.goal_id.stamp = now.to_msg()
        ag.goal_id.id = f"{self.get_fully_qualified_name()}-simple-{self._simple_goals}"
        ag.goal.target_pose = msg
        self._simple_goal_pub.publish(ag)

    def _on_goal(self) -> None:
        goal = self.server.accept_new_goal()
        if goal is None:
            return
        target = goal.target_pose
        if not _quaternion_ok(target.pose.orientation):
            self._abort(_INVALID_QUATERNION)
            return
        try:
            pose = self._to_global(target)
        except TransformException as err:
            frame = str(target.header.frame_id) or "(empty)"
            self._abort(
                f"Aborting on goal because it was sent in frame '{frame}', which TF cannot "
                f"transform into '{self.global_frame}': {err}"
            )
            return
        if self.params.shutdown_costmaps:
            self.global_costmap.start()
            self.local_costmap.start()
        self.goal = pose
        now = self._now()
        self.plan = None
        self.state = PLANNING
        self.recovery_index = 0
        self.recovery_trigger = PLANNING_R
        self.recovering.running = None
        self._last_valid_plan = self._last_valid_control = now
        self._last_oscillation_reset = now
        self._oscillation_pose = None
        self._planning_retries = 0
        cur = PoseStamped(
            header_frame_id=self.global_frame, pose=pose_from_xytheta(*pose.as_array())
        )
        cur.header.stamp = self.get_clock().now().to_msg()
        self.goal_pub.publish(cur)

    def _on_preempt(self) -> None:
        return None  # handled at the next control cycle, as move_base's loop does

    def _reset_state(self) -> None:
        """move_base's resetState: stop the robot (and the costmaps if asked)."""
        self.state = PLANNING
        self.recovery_index = 0
        self.recovery_trigger = PLANNING_R
        self.recovering.running = None
        self.goal = None
        self.plan = None
        self.publish_zero_velocity()
        if self.params.shutdown_costmaps:
            self.global_costmap.stop()
            self.local_costmap.stop()

    def _abort(self, text: str) -> None:
        self._reset_state()
        self.goals_aborted += 1
        self.last_result_text = text
        self.get_logger().error(text)
        self.server.set_aborted(None, text)

    # ------------------------------------------------------------------ the cycle
    def _cycle(self) -> None:
        srv = self.server
        if not srv.is_active():
            return
        if srv.is_preempt_requested():
            self._reset_state()
            self.last_result_text = ""
            srv.set_preempted()
            return
        if self.goal is None:
            return
        now = self._now()
        gpose = self.global_costmap.get_robot_pose()
        if gpose is not None:
            sec, nsec = divmod(self.get_clock().now_ns(), 1_000_000_000)
            half = 0.5 * float(gpose.theta)  # pose_from_xytheta, in one builder call
            fb = build.pose_stamped(
                sec, nsec, self.global_frame, float(gpose.x), float(gpose.y), 0.0,
                0.0, 0.0, math.sin(half), math.cos(half),
            )  # fmt: skip
            srv.publish_feedback(srv.spec.Feedback.cls(base_position=fb))
            op = self._oscillation_pose
            if (
                op is None
                or math.hypot(gpose.x - op.x, gpose.y - op.y) >= self.params.oscillation_distance
            ):
                self._last_oscillation_reset = now
                self._oscillation_pose = gpose
                if self.recovery_trigger == OSCILLATION_R:
                    self.recovery_index = 0
        if not self.local_costmap.is_current():
            self._throttle.warning(
                "stale",
                "Sensor data is out of date, we're not going to allow commanding of the base "
                "for safety",
            )
            self.publish_zero_velocity()
            return
        if self.state == PLANNING:
            self._plan_step(now, gpose)
        elif self.state == CONTROLLING:
            self._control_step(now)
        else:
            self.recovering.clear_step(now)

    def _plan_step(self, now: float, gpose: SE2 | None) -> None:
        assert self.goal is not None
        if self._make_plan(gpose, now):
            self.state = CONTROLLING
            return
        if not self.server.is_active():
            return
        # no plan: the robot must not go on with the last command (a new goal preempting a
        # moving robot; ROS 1 assumes "the robot isn't moving" here and lets it drive on)
        self.publish_zero_velocity()
        p = self.params
        too_long = now > self._last_valid_plan + p.planner_patience
        too_many = 0 <= p.max_planning_retries < self._planning_retries
        if self.state == PLANNING and (too_long or too_many):
            self.state = CLEARING
            self.recovery_trigger = PLANNING_R
            self.publish_zero_velocity()

    def _global_plan(self, planner: Any, start: SE2, goal: SE2) -> Path2D:
        """The global planner's plan, kept clear of the footprint unless
        ``plan_footprint_check`` is off."""
        cm = self.global_costmap.costmap
        if not self.params.plan_footprint_check:
            return cast(Path2D, planner.plan(start, goal, cm))
        return plan_clear_of_footprint(
            planner, start, goal, cm, self.global_costmap.footprint, walls=self._walls(cm)
        )

    def _walls(self, cm: Costmap2D) -> Costmap2D | None:
        """The static layer's map when it covers the global costmap cell for cell: the
        footprint check looks at the walls, not at the sensors' marks (a door's jambs
        marked a cell wider by the laser must not shut it from one plan to the next)."""
        for layer in self.global_costmap.layered.plugins:
            grid = getattr(layer, "grid", None)
            if (
                isinstance(layer, StaticLayer)
                and layer.enabled
                and layer.map_received
                and grid is not None
                and (grid.size_x, grid.size_y, grid.resolution, grid.origin_x, grid.origin_y)
                == (cm.size_x, cm.size_y, cm.resolution, cm.origin_x, cm.origin_y)
            ):
                return cast(Costmap2D, grid)
        return None

    def _make_plan(self, gpose: SE2 | None, now: float) -> bool:
        """Plan from the robot to the goal; True on success (the plan is then in use)."""
        assert self.goal is not None
        if not self.global_costmap.ready:
            # no plan on a costmap that has not got its map yet (an empty grid has no
            # walls); patience starts once it has
            self._throttle.warning(
                "ready", "Waiting for the global costmap (its map) before planning"
            )
            self._last_valid_plan = now
            return False
        if gpose is None:
            self._throttle.warning(
                "start", "Unable to get starting pose of robot, unable to create global plan"
            )
            self._planning_retries += 1
            return False
        try:
            with _Timed(self.timing_hook, "plan"):
                path = self._global_plan(self.planner, gpose, self.goal)
        except GoalOutsideMapBoundsError as err:
            if not self.global_costmap.layered.rolling_window:
                self._abort(f"Aborting on goal because it is outside the global costmap: {err}")
                return False
            self._throttle.warning("plan", str(err))
            self._planning_retries += 1
            return False
        except PlannerError as err:
            self._throttle.warning("plan", f"Failed to get a plan: {err}")
            self._planning_retries += 1
            return False
        self.plan = np.asarray(path, dtype=np.float64)
        self._last_valid_plan = self._last_plan_time = now
        self._planning_retries = 0
        if self.recovery_trigger == PLANNING_R:
            self.recovery_index = 0
        self._publish_path(self.plan_pub, self.plan, self.global_frame)
        self.potential_pub.publish(gpose, self.global_frame, self.global_costmap.costmap.resolution)
        try:
            self.controller.set_plan(self._plan_in_local_frame())
        except (TransformException, NavigationError) as err:
            self._throttle.warning(
                "setplan", f"Failed to pass global plan to the controller: {err}"
            )
            return False
        return True

    def _control_step(self, now: float) -> None:
        p = self.params
        if p.planner_frequency > 0 and now - self._last_plan_time >= 1.0 / p.planner_frequency:
            self._make_plan(self.global_costmap.get_robot_pose(), now)
            if not self.server.is_active():
                return
        lpose = self.local_costmap.get_robot_pose()
        if lpose is not None and self.controller.is_goal_reached(lpose, self._twist):
            self._reset_state()
            self.goals_succeeded += 1
            self.last_result_text = "Goal reached."
            self.server.set_succeeded(None, "Goal reached.")
            return
        if p.oscillation_timeout > 0 and now > self._last_oscillation_reset + p.oscillation_timeout:
            self.publish_zero_velocity()
            self.state = CLEARING
            self.recovery_trigger = OSCILLATION_R
            return
        try:
            if lpose is None:
                raise ControllerError("no robot pose in the local costmap's frame")
            local_plan = self._plan_in_local_frame()
            with _Timed(self.timing_hook, "control"):
                cmd = self.controller.compute_velocity(
                    lpose, self._twist, local_plan, self.local_costmap.costmap
                )
        except (ControllerError, NavigationError, TransformException) as err:
            self._throttle.warning(
                "control", f"The local planner could not find a valid plan: {err}"
            )
            if now > self._last_valid_control + p.controller_patience:
                self.publish_zero_velocity()
                self.state = CLEARING
                self.recovery_trigger = CONTROLLING_R
            else:
                self._last_valid_plan = now
                self._planning_retries = 0
                self.state = PLANNING
                self.publish_zero_velocity()
            return
        self._last_valid_control = now
        if self.recovery_trigger == CONTROLLING_R:
            self.recovery_index = 0
        cmd = self.recovering.limited(cmd, lpose)
        self.cmd_pub.publish(
            build.twist(float(cmd.vx), float(cmd.vy), 0.0, 0.0, 0.0, float(cmd.wz))
        )
        trajectory = getattr(self.controller, "trajectory", None)
        if trajectory is not None and len(trajectory):
            self._publish_path(
                self.local_plan_pub, np.asarray(trajectory), self.local_costmap.global_frame
            )
        self._publish_path(self.local_global_plan_pub, local_plan, self.local_costmap.global_frame)

    def abort_text(self) -> str:
        """move_base's text for an ABORT after the recoveries."""
        return ABORT_TEXTS[self.recovery_trigger]

    # ------------------------------------------------------------------ services
    def _on_make_plan(self, request: Any, response: Any) -> Any:
        """``~make_plan``: a plan on the global costmap (empty when none is found)."""
        start_msg = request.start
        try:
            start = (
                self._to_global(start_msg)
                if str(start_msg.header.frame_id)
                else self.global_costmap.get_robot_pose()
            )
            goal = self._to_global(request.goal)
        except TransformException as err:
            raise NavigationError(f"make_plan: {err}") from err
        if start is None:
            raise NavigationError("make_plan: the robot's pose is not known")
        if self.params.make_plan_clear_costmap:
            self.recovering.clear_around_robot(self._clearing_radius())
        planner: Any = self.planner
        tol = float(request.tolerance)
        if tol > 0 and hasattr(planner, "params"):  # the request's tolerance, for this plan
            planner = type(planner)(dataclasses.replace(planner.params, default_tolerance=tol))
        try:
            path = self._global_plan(planner, start, goal)
        except PlannerError as err:
            self.get_logger().warning(f"make_plan: {err}")
            response.plan = Path(header_frame_id=self.global_frame)
            return response
        if self.params.make_plan_add_unreachable_goal and len(path):
            end = np.asarray(path)[-1]
            if math.hypot(end[0] - goal.x, end[1] - goal.y) > 1e-6:
                # the goal itself, in case the local planner can get the robot there
                path = np.vstack([path, goal.as_array()])
        response.plan = path_to_msg(path, self.global_frame, self.get_clock().now())
        return response

    def _clearing_radius(self) -> float:
        """move_base's ``clearing_radius`` (default: the circumscribed radius)."""
        r = self.params.clearing_radius
        return footprint_radii(self.global_costmap.footprint)[1] if r is None else r

    def _on_clear_costmaps(self, _request: Any, response: Any) -> Any:
        """``~clear_costmaps``: reset both costmaps' layers."""
        self.global_costmap.reset_layers()
        self.local_costmap.reset_layers()
        return response
