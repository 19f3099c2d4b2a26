"""ros_control's ``diff_drive_controller`` under ``libgazebo_ros_control.so``, as Jackal,
Husky and many other ROS robots are driven in Gazebo.

In ROS the URDF names only the ``gazebo_ros_control`` plugin and the wheels' velocity
transmissions; the controller is configured by a YAML file on the parameter server (the
robot's ``control.yaml``: ``type: diff_drive_controller/DiffDriveController``,
``left_wheel``, ``right_wheel``, ...) and started by ``controller_manager``'s spawner.
:func:`diff_drive_controller_config` reads that YAML's parameters with the controller's
names and defaults; :class:`DiffDriveControllerPlugin` is the controller at run time:

* ``<controller>/cmd_vel`` in (a NaN or infinite component is a warning, the message is
  ignored); a command older than ``cmd_vel_timeout`` (0.5 s) brakes to zero;
* every control period (``controlPeriod`` of the Gazebo plugin, else the physics step)
  the command goes through the controller's speed limiters (``linear/x`` and
  ``angular/z``: ``has_velocity_limits``, ``min/max_velocity``, ``has_acceleration_limits``,
  ``min/max_acceleration``, ``has_jerk_limits``, ``min/max_jerk``; a missing ``min_*`` is
  ``-max_*``) and becomes wheel velocities ``(lin -+ ang * ws / 2) / r`` with the
  controller's separation and radii (``wheel_separation`` or the URDF's, times
  ``wheel_separation_multiplier``; ``wheel_radius`` or the URDF's, times
  ``wheel_radius_multiplier``, or the per-side ``left/right_wheel_radius_multiplier``).
  The velocity joint interface sets the wheels' speeds at once; the update is an event
  only while the limiter still ramps (the result is that of a tick every period);
* odometry from the wheels' turns (``open_loop``: from the limited command), integrated
  exactly along arcs, published on ``<controller>/odom`` at ``publish_rate`` (50 Hz) in
  ``odom_frame_id`` -> ``base_frame_id`` with ``pose/twist_covariance_diagonal``; the
  transform when ``enable_odom_tf`` (true).

Skid steer (two or more wheels a side, as Jackal and Husky): the wheels of a side turn
together and the body turns as the calibrated ``wheel_separation_multiplier`` says (the
multiplier is the ratio of the effective to the geometric track that a skid-steered
base shows on the ground, which the simulator's planar body does not reproduce by
itself); a two-wheeled base turns with its geometric track whatever the multiplier. The
twist in the odometry is the mean over the publish period (the controller's rolling
window over the last ``velocity_rolling_window_size`` updates is close to it at 50 Hz).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from roverlab.core import Node
from roverlab.core.node import Publisher
from roverlab.description import Cylinder, RobotModel, Sphere
from roverlab.errors import RoverlabError
from roverlab.geometry import wrap_angle
from roverlab.msgs import classes as mc
from roverlab.sim.diff_drive import DiffDriveParams
from roverlab.sim.dynamics import S_AL, S_AR, S_TL, S_TR
from roverlab.sim.odometry import publish_planar_odometry

__all__ = [
    "DIFF_DRIVE_CONTROLLER",
    "DiffDriveControllerConfig",
    "DiffDriveControllerPlugin",
    "RosControlError",
    "SpeedLimits",
    "diff_drive_controller_config",
]

DIFF_DRIVE_CONTROLLER = "diff_drive_controller/DiffDriveController"
# the controller's own parameters (ros_controllers noetic, diff_drive_controller.cpp)
_KNOWN = frozenset(
    {
        "type", "left_wheel", "right_wheel", "publish_rate", "pose_covariance_diagonal",
        "twist_covariance_diagonal", "cmd_vel_timeout", "enable_odom_tf", "odom_frame_id",
        "base_frame_id", "wheel_separation", "wheel_radius", "wheel_separation_multiplier",
        "wheel_radius_multiplier", "left_wheel_radius_multiplier",
        "right_wheel_radius_multiplier", "linear", "angular", "open_loop",
        "velocity_rolling_window_size", "allow_multiple_cmd_vel_publishers", "publish_cmd",
        "publish_wheel_joint_controller_state", "k_l", "k_r",
    }
)  # fmt: skip
_LIMIT_KEYS = frozenset(
    {
        "has_velocity_limits", "min_velocity", "max_velocity", "has_acceleration_limits",
        "min_acceleration", "max_acceleration", "has_jerk_limits", "min_jerk", "max_jerk",
    }
)  # fmt: skip


class RosControlError(RoverlabError):
    """A diff_drive_controller configuration the controller would refuse to load."""


@dataclass(frozen=True, slots=True)
class SpeedLimits:
    """One axis of the controller's ``SpeedLimiter`` (``linear/x`` or ``angular/z``)."""

    has_velocity_limits: bool = False
    min_velocity: float = 0.0
    max_velocity: float = 0.0
    has_acceleration_limits: bool = False
    min_acceleration: float = 0.0
    max_acceleration: float = 0.0
    has_jerk_limits: bool = False
    min_jerk: float = 0.0
    max_jerk: float = 0.0

    def limit(self, v: float, v0: float, v1: float, dt: float) -> float:
        """``v`` limited as ``SpeedLimiter::limit``: jerk, then acceleration (from the
        previous command ``v0``, and ``v1`` before it), then velocity."""
        if self.has_jerk_limits:
            dv, dv0 = v - v0, v0 - v1
            dt2 = 2.0 * dt * dt
            v = v0 + dv0 + min(max(dv - dv0, self.min_jerk * dt2), self.max_jerk * dt2)
        if self.has_acceleration_limits:
            dv = min(max(v - v0, self.min_acceleration * dt), self.max_acceleration * dt)
            v = v0 + dv
        if self.has_velocity_limits:
            v = min(max(v, self.min_velocity), self.max_velocity)
        return v


@dataclass(frozen=True)
class DiffDriveControllerConfig:
    """A diff_drive_controller as the simulator runs it (see the module's doc).

    ``params`` is the planar body the physics moves (its effective track, the wheels'
    true diameter, speeds set at once); ``wheel_separation_m`` and the radii are the
    controller's (multipliers applied).
    """

    name: str
    params: DiffDriveParams
    left_wheels: tuple[str, ...]
    right_wheels: tuple[str, ...]
    wheel_separation_m: float
    left_wheel_radius_m: float
    right_wheel_radius_m: float
    command_topic: str
    odometry_topic: str
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_link"
    publish_rate_hz: float = 50.0
    cmd_vel_timeout_s: float = 0.5
    publish_odom_tf: bool = True
    open_loop: bool = False
    control_period_s: float = 0.0
    linear: SpeedLimits = field(default_factory=SpeedLimits)
    angular: SpeedLimits = field(default_factory=SpeedLimits)
    pose_covariance: tuple[float, ...] = (0.0,) * 6
    twist_covariance: tuple[float, ...] = (0.0,) * 6
    warnings: tuple[str, ...] = ()


def _limits(tree: Any, where: str) -> SpeedLimits:
    if tree is None:
        return SpeedLimits()
    if not isinstance(tree, Mapping):
        raise RosControlError(f"{where}: expected a mapping, got {tree!r}")
    unknown = sorted(set(tree) - _LIMIT_KEYS)
    if unknown:
        raise RosControlError(f"{where}: unknown parameter {unknown[0]!r}")

    def num(key: str, default: float) -> float:
        v = tree.get(key, default)
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise RosControlError(f"{where}/{key}: expected a number, got {v!r}")
        return float(v)

    out: dict[str, Any] = {}
    for kind in ("velocity", "acceleration", "jerk"):
        out[f"has_{kind}_limits"] = bool(tree.get(f"has_{kind}_limits", False))
        hi = num(f"max_{kind}", 0.0)
        out[f"max_{kind}"] = hi
        out[f"min_{kind}"] = num(f"min_{kind}", -hi)
    return SpeedLimits(**out)


def _wheels(value: Any, key: str, where: str) -> tuple[str, ...]:
    names = [value] if isinstance(value, str) else value
    if (
        not isinstance(names, list | tuple)
        or not names
        or not all(isinstance(n, str) for n in names)
    ):
        raise RosControlError(f"{where}/{key}: expected a joint name or a list of them")
    return tuple(names)


def _joint_name(model: RobotModel, name: str, where: str) -> str:
    """The URDF joint a transmission's joint name means (Jackal's ``front_left_wheel``
    transmits ``front_left_wheel`` or, in older descriptions, ``front_left_wheel_joint``)."""
    for candidate in (name, f"{name}_joint"):
        if candidate in model.joints:
            return candidate
    raise RosControlError(f"{where}: wheel joint {name!r} is not a joint of the robot")


def _urdf_wheel(model: RobotModel, joint: str) -> tuple[np.ndarray, float | None]:
    """A wheel joint's position in the robot's root frame and its wheel's collision
    radius (a cylinder's or a sphere's; None for another shape)."""
    poses = model.link_transforms()
    j = model.joints[joint]
    pos = np.asarray((poses[j.parent] * j.origin).translation, dtype=np.float64)
    radius = None
    for c in model.links[j.child].collisions:
        if isinstance(c.geometry, Cylinder | Sphere):
            radius = float(c.geometry.radius)
            break
    return pos, radius


def _num(tree: Mapping[str, Any], key: str, default: float, where: str) -> float:
    v = tree.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise RosControlError(f"{where}/{key}: expected a number, got {v!r}")
    return float(v)


def _covariance(tree: Mapping[str, Any], key: str, where: str) -> tuple[float, ...]:
    v = tree.get(key, [0.0] * 6)
    if not isinstance(v, list | tuple) or len(v) != 6:
        raise RosControlError(f"{where}/{key}: expected a list of 6 numbers, got {v!r}")
    return tuple(_num({"v": x}, "v", 0.0, f"{where}/{key}") for x in v)


def diff_drive_controller_config(
    model: RobotModel,
    name: str,
    tree: Mapping[str, Any],
    *,
    namespace: str = "/",
    control_period_s: float = 0.0,
    source: str = "<parameters>",
) -> DiffDriveControllerConfig:
    """The controller ``name``'s parameters ``tree`` (its YAML namespace) on ``model``.

    The wheel separation and radius come from the URDF when the YAML leaves them out,
    as the controller does: the distance between the first left and first right wheel
    joints, and the first left wheel's collision cylinder (or sphere) radius.

    Raises:
        RosControlError: a missing or unknown wheel joint, a malformed value, a
            separation or radius that is neither given nor in the URDF. One line naming
            ``source`` and the parameter.
    """
    where = f"{source}: {name}"
    for key in ("left_wheel", "right_wheel"):
        if key not in tree:
            raise RosControlError(f"{where}: missing {key}")
    left = tuple(
        _joint_name(model, n, where) for n in _wheels(tree["left_wheel"], "left_wheel", where)
    )
    right = tuple(
        _joint_name(model, n, where) for n in _wheels(tree["right_wheel"], "right_wheel", where)
    )
    lpos, lrad = _urdf_wheel(model, left[0])
    rpos, _ = _urdf_wheel(model, right[0])
    geometric = float(np.linalg.norm(lpos - rpos))
    sep = _num(tree, "wheel_separation", geometric, where)
    radius = _num(tree, "wheel_radius", lrad if lrad is not None else math.nan, where)
    if not (math.isfinite(radius) and radius > 0 and sep > 0):
        raise RosControlError(
            f"{where}: wheel_radius and wheel_separation must be > 0 (given, or from the "
            f"URDF's wheels): got {radius} and {sep}"
        )
    mult_sep = _num(tree, "wheel_separation_multiplier", 1.0, where)
    mult_r = _num(tree, "wheel_radius_multiplier", 1.0, where)
    ws = sep * mult_sep
    skid = len(left) > 1 or len(right) > 1
    ns = namespace.rstrip("/")
    rate = _num(tree, "publish_rate", 50.0, where)
    if not rate > 0:
        raise RosControlError(f"{where}/publish_rate: must be > 0, got {rate}")
    unknown = sorted(set(tree) - _KNOWN)
    linear = tree.get("linear", {}) or {}
    angular = tree.get("angular", {}) or {}
    return DiffDriveControllerConfig(
        name=name,
        params=DiffDriveParams(
            wheel_separation_m=ws if skid else geometric,
            wheel_diameter_m=2.0 * (lrad if lrad is not None else radius),
        ),
        left_wheels=left,
        right_wheels=right,
        wheel_separation_m=ws,
        left_wheel_radius_m=radius * _num(tree, "left_wheel_radius_multiplier", mult_r, where),
        right_wheel_radius_m=radius * _num(tree, "right_wheel_radius_multiplier", mult_r, where),
        command_topic=f"{ns}/{name}/cmd_vel",
        odometry_topic=f"{ns}/{name}/odom",
        odometry_frame=str(tree.get("odom_frame_id", "odom")),
        robot_base_frame=str(tree.get("base_frame_id", "base_link")),
        publish_rate_hz=rate,
        cmd_vel_timeout_s=_num(tree, "cmd_vel_timeout", 0.5, where),
        publish_odom_tf=bool(tree.get("enable_odom_tf", True)),
        open_loop=bool(tree.get("open_loop", False)),
        control_period_s=control_period_s,
        linear=_limits(
            linear.get("x") if isinstance(linear, Mapping) else linear, f"{where}/linear/x"
        ),
        angular=_limits(
            angular.get("z") if isinstance(angular, Mapping) else angular, f"{where}/angular/z"
        ),
        pose_covariance=_covariance(tree, "pose_covariance_diagonal", where),
        twist_covariance=_covariance(tree, "twist_covariance_diagonal", where),
        warnings=tuple(f"{where}: unknown parameter {k!r} (ignored)" for k in unknown),
    )


def _diag(values: tuple[float, ...]) -> np.ndarray:
    cov = np.zeros(36)
    cov[[0, 7, 14, 21, 28, 35]] = values
    cov.flags.writeable = False
    return cov


class DiffDriveControllerPlugin:
    """The controller at run time in the simulator node (see the module's doc).

    Args:
        node: the simulator node (subscriptions, publishers, timers, logger).
        config: the controller.
        state: the physics state; the wheels' target speeds are written into it.
        advance: runs the physics up to the current time.
        tf_publisher: /tf's publisher.
        physics_period_s: the control period when the Gazebo plugin sets none.
    """

    def __init__(
        self,
        *,
        node: Node,
        config: DiffDriveControllerConfig,
        state: np.ndarray,
        advance: Callable[[], None],
        tf_publisher: Publisher,
        physics_period_s: float,
    ) -> None:
        self.config = c = config
        self._node = node
        self._state = state
        self._advance = advance
        self._tf_pub = tf_publisher
        self._executor = node.context.executor
        self._period_ns = round((c.control_period_s or physics_period_s) * 1e9)
        self._timeout_ns = round(c.cmd_vel_timeout_s * 1e9)
        self._cmd = (0.0, 0.0)
        self._stamp_ns = -(1 << 62)  # no command yet: braking
        self._last0 = (0.0, 0.0)
        self._last1 = (0.0, 0.0)
        self._armed = False  # an update event is pending
        self._timeout_armed = False  # one pending brake check, re-armed as commands come
        self._half_r = 0.5 * c.params.wheel_diameter_m
        # odometry: the pose, the wheels' angles when it was last integrated
        self.pose = [0.0, 0.0, 0.0]
        self._angles = (float(state[S_AL]), float(state[S_AR]))
        self._odom_ns = self._executor.now_ns
        self._travel = (0.0, 0.0)  # since the last message: linear, angular
        self._published_ns = self._odom_ns
        self._pose_cov = _diag(c.pose_covariance)
        self._twist_cov = _diag(c.twist_covariance)
        for w in c.warnings:
            node.get_logger().warning(w)
        node.create_subscription(mc.Twist, c.command_topic, self.on_cmd, 10)
        self.odom_pub = node.create_publisher(mc.Odometry, c.odometry_topic, 10)
        node.create_timer(1.0 / c.publish_rate_hz, self.publish_odometry)

    # ---------------------------------------------------------------- commands
    def on_cmd(self, msg: Any) -> None:
        lin, ang = float(msg.linear.x), float(msg.angular.z)
        if not (math.isfinite(lin) and math.isfinite(ang)):
            self._node.get_logger().warning("Received NaN in velocity command. Ignoring.")
            return
        self._cmd = (lin, ang)
        self._stamp_ns = self._executor.now_ns
        self._arm(self._executor.now_ns)
        if not self._timeout_armed:  # the brake once the command is stale
            self._timeout_armed = True
            self._executor.call_at(self._stamp_ns + self._timeout_ns + 1, self._on_timeout)

    def _on_timeout(self) -> None:
        deadline = self._stamp_ns + self._timeout_ns + 1
        if self._executor.now_ns < deadline:  # a later command moved it
            self._executor.call_at(deadline, self._on_timeout)
            return
        self._timeout_armed = False
        self._arm(self._executor.now_ns)

    def _arm(self, at_ns: int) -> None:
        if not self._armed:
            self._armed = True
            self._executor.call_at(at_ns, self._update)

    def _update(self) -> None:
        """One controller update: the command (or zero once stale), limited, to the
        wheels; another update one period later while the limiter still ramps."""
        self._armed = False
        c = self.config
        now = self._executor.now_ns
        self._advance()
        self._integrate(now)
        lin, ang = self._cmd
        if now - self._stamp_ns > self._timeout_ns:
            lin = ang = 0.0
        want = (lin, ang)
        dt = self._period_ns / 1e9
        lin = c.linear.limit(lin, self._last0[0], self._last1[0], dt)
        ang = c.angular.limit(ang, self._last0[1], self._last1[1], dt)
        self._last1, self._last0 = self._last0, (lin, ang)
        half = 0.5 * c.wheel_separation_m * ang
        # wheel angular speeds (the controller's radii), as surface speeds of the true wheel
        self._state[S_TL] = (lin - half) / c.left_wheel_radius_m * self._half_r
        self._state[S_TR] = (lin + half) / c.right_wheel_radius_m * self._half_r
        if self._last0 != self._last1 or (lin, ang) != want:  # still ramping
            self._arm(now + self._period_ns)

    # ---------------------------------------------------------------- odometry
    def _integrate(self, now: int) -> None:
        """Odometry up to ``now``: the wheels' turns since the last call (or the limited
        command, ``open_loop``), integrated along an arc (``Odometry::integrateExact``)."""
        c = self.config
        st = self._state
        al, ar = float(st[S_AL]), float(st[S_AR])
        if c.open_loop:
            dt = (now - self._odom_ns) / 1e9
            lin, ang = self._last0[0] * dt, self._last0[1] * dt
        else:
            dl = float(wrap_angle(al - self._angles[0])) * c.left_wheel_radius_m
            dr = float(wrap_angle(ar - self._angles[1])) * c.right_wheel_radius_m
            lin, ang = 0.5 * (dl + dr), (dr - dl) / c.wheel_separation_m
        self._angles = (al, ar)
        self._odom_ns = now
        x, y, th = self.pose
        if abs(ang) < 1e-6:  # Runge-Kutta 2, as the controller for small turns
            mid = th + 0.5 * ang
            x, y = x + lin * math.cos(mid), y + lin * math.sin(mid)
        else:
            r = lin / ang
            th2 = th + ang
            x, y = x + r * (math.sin(th2) - math.sin(th)), y - r * (math.cos(th2) - math.cos(th))
        self.pose = [x, y, float(wrap_angle(th + ang))]
        t_lin, t_ang = self._travel
        self._travel = (t_lin + lin, t_ang + ang)

    def publish_odometry(self) -> None:
        """``nav_msgs/Odometry`` (and the odom transform with ``enable_odom_tf``)."""
        c = self.config
        now = self._executor.now_ns
        self._advance()
        last = self._published_ns
        self._integrate(now)
        dt = (now - last) / 1e9
        lin, ang = self._travel
        self._travel = (0.0, 0.0)
        self._published_ns = now
        v, w = (lin / dt, ang / dt) if dt > 0 else (0.0, 0.0)
        publish_planar_odometry(
            self.odom_pub, self._tf_pub if c.publish_odom_tf else None, now,
            c.odometry_frame, c.robot_base_frame, (self.pose[0], self.pose[1], self.pose[2]),
            (v, 0.0, w), self._pose_cov, self._twist_cov,
        )  # fmt: skip

    def reset(self) -> None:
        """A teleport: the body is at rest, the command is dropped."""
        self._cmd = (0.0, 0.0)
        self._last0 = self._last1 = (0.0, 0.0)
        self._angles = (float(self._state[S_AL]), float(self._state[S_AR]))
