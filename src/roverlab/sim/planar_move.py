"""The ROS side of ``libgazebo_ros_planar_move.so`` (ROS 1 noetic's GazeboRosPlanarMove).

The plugin sets the model's velocity every update from the last ``cmd_vel``: ``linear.x``
forward, ``linear.y`` to the left, ``angular.z`` turning, in the body frame, with no
acceleration limit. The motion itself is the holonomic drive of the compiled loop in
:mod:`roverlab.sim.dynamics` (it reads the command from the physics state); this module
is the plugin's topics:

* ``cmd_vel`` in: a NaN or infinite component is a warning and the message is ignored;
  speeds beyond :class:`~roverlab.sim.config.PlanarMoveConfig`'s guards are clamped;
* ``cmdTimeout`` (>= 0): once no command came for that long the body stops (the plugin
  zeroes its command in the first update after the deadline); one expiry event is
  pending at a time, re-armed when a later command moved the deadline;
* odometry at ``odometryRate``: the model's true pose, and the velocity as the plugin
  computes it: the pose's change since the previous message, turned into the base frame
  at the current heading (so it lags a change of command by up to one period);
* the ``odom -> robotBaseFrame`` transform with the same pose and stamp, built only
  while someone reads /tf;
* :meth:`PlanarMovePlugin.reset` after a teleport: the body is at rest, no timeout is
  pending, and the next odometry velocity is measured from the new pose (not the jump).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from roverlab.core import Node
from roverlab.core.node import Publisher
from roverlab.geometry import wrap_angle
from roverlab.msgs import builders as build
from roverlab.msgs import classes as mc
from roverlab.sim.config import PlanarMoveConfig
from roverlab.sim.dynamics import S_CVX, S_CVY, S_CW, S_TH, S_X, S_Y

__all__ = ["PlanarMovePlugin"]


def _read_only(values: np.ndarray) -> np.ndarray:
    values.flags.writeable = False
    return values


# the plugin fills the pose covariance's diagonal and leaves the twist's at zero
_POSE_COV = _read_only(np.diag([1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3]).reshape(-1))
_TWIST_COV = _read_only(np.zeros(36))


class PlanarMovePlugin:
    """cmd_vel, odometry, the odom transform and the command timeout of a holonomic base.

    Args:
        node: the simulator node (its subscriptions, publishers, timers and logger).
        config: the plugin's topics, frames, rates and guards.
        state: the physics state (updated in place by the compiled loop); the command
            is written into it.
        advance: runs the physics up to the current time.
        tf_publisher: /tf's publisher.
    """

    def __init__(
        self,
        *,
        node: Node,
        config: PlanarMoveConfig,
        state: np.ndarray,
        advance: Callable[[], None],
        tf_publisher: Publisher,
    ) -> None:
        self.config = config
        self._node = node
        self._state = state
        self._advance = advance
        self._tf_pub = tf_publisher
        self._executor = node.context.executor
        timeout = config.cmd_timeout_s
        self._timeout_ns = round(timeout * 1e9) if timeout >= 0 else -1
        self._deadline_ns: int | None = None  # when the last command times out
        self._expiry_armed = False  # one pending expiry event, whatever the command rate
        # the pose and time of the previous odometry message (at first: the spawn)
        self._last = (float(state[S_X]), float(state[S_Y]), float(state[S_TH]))
        self._last_ns = self._executor.now_ns
        node.create_subscription(mc.Twist, config.command_topic, self.on_cmd, 10)
        self.odom_pub: Publisher | None = None
        if config.odometry_rate_hz > 0:
            self.odom_pub = node.create_publisher(mc.Odometry, config.odometry_topic, 10)
            node.create_timer(1.0 / config.odometry_rate_hz, self.publish_odometry)

    def on_cmd(self, msg: Any) -> None:
        """A ``geometry_msgs/Twist``: the body's new velocity from the next step on."""
        vx, vy, wz = float(msg.linear.x), float(msg.linear.y), float(msg.angular.z)
        if not (math.isfinite(vx) and math.isfinite(vy) and math.isfinite(wz)):
            self._node.get_logger().warning("ignoring a cmd_vel with a NaN or infinite velocity")
            return
        self._advance()
        c = self.config
        speed = math.hypot(vx, vy)
        if speed > c.max_speed_mps:  # keep the direction
            k = c.max_speed_mps / speed
            vx, vy = vx * k, vy * k
        st = self._state
        st[S_CVX], st[S_CVY] = vx, vy
        st[S_CW] = max(-c.max_turn_rate_rad_s, min(c.max_turn_rate_rad_s, wz))
        if self._timeout_ns >= 0:
            self._deadline_ns = self._executor.now_ns + self._timeout_ns
            if not self._expiry_armed:
                self._expiry_armed = True
                self._executor.call_at(self._deadline_ns, self._expire)

    def _expire(self) -> None:
        deadline = self._deadline_ns
        if deadline is None:  # stopped already (a teleport)
            self._expiry_armed = False
            return
        if self._executor.now_ns < deadline:  # a later command moved the deadline
            self._executor.call_at(deadline, self._expire)
            return
        self._expiry_armed = False
        self._deadline_ns = None
        self._advance()  # the steps up to the deadline still move
        st = self._state
        st[S_CVX] = st[S_CVY] = st[S_CW] = 0.0

    def reset(self) -> None:
        """The body was put somewhere else, at rest (a teleport): the next odometry
        message measures its velocity from here, and no timeout is pending."""
        self._advance()
        st = self._state
        self._last = (float(st[S_X]), float(st[S_Y]), float(st[S_TH]))
        self._last_ns = self._executor.now_ns
        st[S_CVX] = st[S_CVY] = st[S_CW] = 0.0
        self._deadline_ns = None

    def publish_odometry(self) -> None:
        """The odometry message (and the transform, when someone reads /tf)."""
        self._advance()
        ns = self._executor.now_ns
        st = self._state
        x, y, yaw = float(st[S_X]), float(st[S_Y]), float(st[S_TH])
        lx, ly, lyaw = self._last
        dt = (ns - self._last_ns) / 1e9
        self._last, self._last_ns = (x, y, yaw), ns
        vx = vy = wz = 0.0
        if dt > 0:
            dx, dy = (x - lx) / dt, (y - ly) / dt
            c, s = math.cos(yaw), math.sin(yaw)
            vx, vy = c * dx + s * dy, c * dy - s * dx
            turn = float(st[S_CW])
            # faster than half a turn per message the heading's change aliases: the
            # plugin reports the command instead
            wz = turn if abs(turn) > math.pi / dt else float(wrap_angle(yaw - lyaw)) / dt
        sec, nsec = divmod(ns, 1_000_000_000)
        qz, qw = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
        frame, child = self.config.odometry_frame, self.config.robot_base_frame
        if self.odom_pub is not None:
            self.odom_pub.publish(
                build.odometry(
                    sec, nsec, frame, child, x, y, 0.0, 0.0, 0.0, qz, qw, _POSE_COV,
                    vx, vy, 0.0, 0.0, 0.0, wz, _TWIST_COV,
                )
            )  # fmt: skip
        if self.config.publish_odom_tf and self._tf_pub.has_listeners:
            self._tf_pub.publish(
                build.tf_message(
                    [build.transform_stamped(sec, nsec, frame, child, x, y, 0.0, 0.0, 0.0, qz, qw)]
                )
            )
