"""What differential-base drivers share: wheel set-points, ramps, odometry from ticks.

The arithmetic is the one of ``arbotix_python``'s ``diff_controller`` and of
``ros_arduino_python``'s ``base_controller`` (which borrowed it):

* a ``cmd_vel`` (x m/s, th rad/s) becomes one speed per wheel,
  ``x -/+ th * wheel_track / 2``, in encoder ticks per PID frame (the firmware's PID loop
  runs at :data:`PID_RATE_HZ`, so a speed is ``ticks_per_meter * v / 30``), truncated to
  an integer as the drivers do;
* every update the sent speed moves towards that set-point by at most ``max_accel``
  ticks per frame (:func:`ramp`);
* odometry integrates encoder counts: ``d = (dl + dr) / 2``, ``dth = (dr - dl) / track``,
  the step ``(cos(dth) d, -sin(dth) d)`` rotated by the heading, heading += ``dth``
  (:class:`EncoderOdometry`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from roverlab.drivers.errors import DriverError
from roverlab.msgs import classes as mc

__all__ = [
    "PID_RATE_HZ",
    "EncoderOdometry",
    "OdometryState",
    "odometry_messages",
    "ramp",
    "wheel_setpoints",
]

PID_RATE_HZ: Final = 30.0
"""The base firmware's PID loop rate (ArbotiX and ROSArduinoBridge): speeds are in ticks
per 1/30 s."""


def wheel_setpoints(
    linear_x: float,
    angular_z: float,
    *,
    wheel_track_m: float,
    ticks_per_meter: float,
    gear_reduction: float = 1.0,
) -> tuple[int, int]:
    """Left and right wheel speeds in ticks per PID frame for a body twist.

    Raises:
        DriverError: a non-finite command (NaN or infinite).
    """
    if not (math.isfinite(linear_x) and math.isfinite(angular_z)):
        raise DriverError(f"cmd_vel is not finite: linear.x={linear_x}, angular.z={angular_z}")
    half = angular_z * wheel_track_m * gear_reduction / 2.0
    left, right = linear_x - half, linear_x + half
    return int(left * ticks_per_meter / PID_RATE_HZ), int(right * ticks_per_meter / PID_RATE_HZ)


def ramp(current: float, desired: float, max_step: float) -> float:
    """One update of the drivers' acceleration limit: ``current`` moves towards
    ``desired`` by at most ``max_step`` (exactly the drivers' if/else ladder)."""
    if current < desired:
        return min(current + max_step, desired)
    return max(current - max_step, desired)


@dataclass(frozen=True)
class OdometryState:
    """Pose in the odometry frame and the body twist of the last update."""

    x: float = 0.0
    y: float = 0.0
    th: float = 0.0
    vx: float = 0.0
    vth: float = 0.0


class EncoderOdometry:
    """Dead reckoning from two cumulative encoder counts.

    Args:
        ticks_per_meter: encoder ticks per metre of wheel travel.
        wheel_track_m: distance between the wheels' contact points.
        linear_scale: ros_arduino_bridge's ``odom_linear_scale_correction``.
        angular_scale: ros_arduino_bridge's ``odom_angular_scale_correction``.

    Raises:
        DriverError: a non-positive ticks_per_meter or track.
    """

    def __init__(
        self,
        *,
        ticks_per_meter: float,
        wheel_track_m: float,
        linear_scale: float = 1.0,
        angular_scale: float = 1.0,
    ) -> None:
        if not (math.isfinite(ticks_per_meter) and ticks_per_meter > 0):
            raise DriverError(f"ticks per meter must be > 0, got {ticks_per_meter}")
        if not (math.isfinite(wheel_track_m) and wheel_track_m > 0):
            raise DriverError(f"wheel track (base_width) must be > 0 m, got {wheel_track_m}")
        self.ticks_per_meter = float(ticks_per_meter)
        self.wheel_track_m = float(wheel_track_m)
        self.linear_scale = float(linear_scale)
        self.angular_scale = float(angular_scale)
        self._left: int | None = None
        self._right: int | None = None
        self.state = OdometryState()

    def reset(self) -> None:
        """Forget the pose and the last counts (the next update is the new origin)."""
        self._left = self._right = None
        self.state = OdometryState()

    def rebase(self) -> None:
        """Keep the pose, forget the last counts (after a reconnection the next reading is
        the new baseline: what the wheels did meanwhile is not counted)."""
        self._left = self._right = None

    def update(self, left_ticks: int, right_ticks: int, dt_s: float) -> OdometryState:
        """Integrate new cumulative counts read ``dt_s`` after the previous ones."""
        if self._left is None or self._right is None:
            d_left = d_right = 0.0
        else:
            d_left = (left_ticks - self._left) / self.ticks_per_meter
            d_right = (right_ticks - self._right) / self.ticks_per_meter
        self._left, self._right = left_ticks, right_ticks
        d = self.linear_scale * (d_left + d_right) / 2.0
        dth = self.angular_scale * (d_right - d_left) / self.wheel_track_m
        s = self.state
        x, y, th = s.x, s.y, s.th
        if d != 0.0:
            sx, sy = math.cos(dth) * d, -math.sin(dth) * d
            x += math.cos(th) * sx - math.sin(th) * sy
            y += math.sin(th) * sx + math.cos(th) * sy
        th += dth
        vx = d / dt_s if dt_s > 0 else 0.0
        vth = dth / dt_s if dt_s > 0 else 0.0
        self.state = OdometryState(x, y, th, vx, vth)
        return self.state


def odometry_messages(
    state: OdometryState,
    *,
    stamp_ns: int,
    odom_frame: str,
    base_frame: str,
    pose_covariance: list[float] | None = None,
) -> tuple[Any, Any]:
    """The ``nav_msgs/Odometry`` and the odom -> base ``TransformStamped`` of a state."""
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    header = mc.Header(mc.Time(sec, nanosec), odom_frame)
    q = mc.Quaternion(0.0, 0.0, math.sin(state.th / 2.0), math.cos(state.th / 2.0))
    cov = np.zeros(36) if pose_covariance is None else np.asarray(pose_covariance, float)
    odom = mc.Odometry(
        header,
        base_frame,
        mc.PoseWithCovariance(mc.Pose(mc.Point(state.x, state.y, 0.0), q), cov),
        mc.TwistWithCovariance(
            mc.Twist(mc.Vector3(state.vx, 0.0, 0.0), mc.Vector3(0.0, 0.0, state.vth)),
            np.zeros(36),
        ),
    )
    tf = mc.TransformStamped(header, base_frame, mc.Transform(mc.Vector3(state.x, state.y, 0.0), q))
    return odom, tf
