"""A small live system for the quick start: a kinematic robot in a walled room.

``DemoRobot`` integrates ``/cmd_vel`` (unicycle model), publishes ``/odom``, the
``odom -> base_footprint`` transform, the static ``base_footprint -> base_link -> laser``
transforms and a ``/scan`` ray-cast against the room's walls; ``Talker`` publishes
``/chatter``. The full simulator (robots from URDF, Gazebo worlds, sensors) replaces it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from roverlab.core import Node, QoSProfile
from roverlab.geometry import quat_from_yaw
from roverlab.msgs import (
    Header,
    LaserScan,
    Odometry,
    String,
    TFMessage,
    TransformStamped,
    Twist,
)

__all__ = ["DemoRobot", "Room", "Talker", "cast_room"]


@dataclass(frozen=True)
class Room:
    """An axis-aligned rectangular room with one round pillar."""

    half_x: float = 5.0
    half_y: float = 4.0
    pillar: tuple[float, float, float] = (2.0, 1.0, 0.5)  # x, y, radius


def cast_room(room: Room, x: float, y: float, angles: np.ndarray, max_range: float) -> np.ndarray:
    """Exact ranges from (x, y) along world ``angles`` to the walls or the pillar."""
    dx, dy = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore", invalid="ignore"):
        tx = np.where(
            dx > 0, (room.half_x - x) / dx, np.where(dx < 0, (-room.half_x - x) / dx, np.inf)
        )
        ty = np.where(
            dy > 0, (room.half_y - y) / dy, np.where(dy < 0, (-room.half_y - y) / dy, np.inf)
        )
    t = np.minimum(tx, ty)
    px, py, r = room.pillar
    ox, oy = x - px, y - py
    b = ox * dx + oy * dy
    c = ox * ox + oy * oy - r * r
    disc = b * b - c
    hit = disc >= 0
    tp = np.where(hit, -b - np.sqrt(np.where(hit, disc, 0.0)), np.inf)
    tp = np.where(tp > 0, tp, np.inf)
    return np.minimum(np.minimum(t, tp), max_range)


def _tf(parent: str, child: str, stamp: Any, x: float, y: float, z: float, yaw: float) -> Any:
    q = quat_from_yaw(yaw)
    return TransformStamped(
        header=Header(stamp=stamp, frame_id=parent),
        child_frame_id=child,
        transform={
            "translation": {"x": x, "y": y, "z": z},
            "rotation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]},
        },
    )


class DemoRobot(Node):
    """Unicycle robot: /cmd_vel in; /odom, /tf, /tf_static and /scan out."""

    def __init__(self, *, context: Any, room: Room | None = None, **kwargs: Any) -> None:
        super().__init__("demo_robot", context=context, **kwargs)
        self.room = room or Room()
        self.odom_rate = self.declare_parameter("odom_rate", 20.0).value
        self.scan_rate = self.declare_parameter("scan_rate", 10.0).value
        self.beams = self.declare_parameter("beams", 360).value
        self.max_range = self.declare_parameter("range_max", 8.0).value
        self.x, self.y, self.yaw = -2.0, -1.0, 0.0
        self.v, self.w = 0.0, 0.0
        self._last_ns = self.get_clock().now_ns()
        self.odom_pub = self.create_publisher(Odometry, "odom", 10)
        self.scan_pub = self.create_publisher(LaserScan, "scan", 10)
        self.tf_pub = self.create_publisher(TFMessage, "/tf", 100)
        static = self.create_publisher(
            TFMessage, "/tf_static", QoSProfile(depth=1, durability="transient_local")
        )
        self.create_subscription(Twist, "cmd_vel", self._on_cmd, 10)
        self.create_timer(1.0 / self.odom_rate, self._step)
        self.create_timer(1.0 / self.scan_rate, self._scan)
        stamp = self.get_clock().now().to_msg()
        static.publish(
            TFMessage(
                transforms=[
                    _tf("base_footprint", "base_link", stamp, 0.0, 0.0, 0.05, 0.0),
                    _tf("base_link", "laser", stamp, 0.0, 0.0, 0.1, 0.0),
                ]
            )
        )

    def _on_cmd(self, msg: Any) -> None:
        v, w = float(msg.linear.x), float(msg.angular.z)
        if not (math.isfinite(v) and math.isfinite(w)):
            self.get_logger().warning("ignoring /cmd_vel with a NaN or infinite velocity")
            return
        self.v = max(-1.0, min(1.0, v))
        self.w = max(-2.0, min(2.0, w))

    def _step(self) -> None:
        now_ns = self.get_clock().now_ns()
        dt = (now_ns - self._last_ns) / 1e9
        self._last_ns = now_ns
        nx = self.x + self.v * math.cos(self.yaw) * dt
        ny = self.y + self.v * math.sin(self.yaw) * dt
        margin = 0.2
        px, py, r = self.room.pillar
        inside = abs(nx) < self.room.half_x - margin and abs(ny) < self.room.half_y - margin
        if inside and math.hypot(nx - px, ny - py) > r + margin:
            self.x, self.y = nx, ny
        self.yaw = math.remainder(self.yaw + self.w * dt, 2 * math.pi)
        stamp = self.get_clock().now().to_msg()
        q = quat_from_yaw(self.yaw)
        self.odom_pub.publish(
            Odometry(
                header=Header(stamp=stamp, frame_id="odom"),
                child_frame_id="base_footprint",
                pose_pose_position_x=self.x,
                pose_pose_position_y=self.y,
                pose_pose_orientation={"z": q[2], "w": q[3]},
                twist_twist_linear_x=self.v,
                twist_twist_angular_z=self.w,
            )
        )
        self.tf_pub.publish(
            TFMessage(
                transforms=[_tf("odom", "base_footprint", stamp, self.x, self.y, 0.0, self.yaw)]
            )
        )

    def _scan(self) -> None:
        n = int(self.beams)
        inc = 2 * math.pi / n
        rel = -math.pi + inc * np.arange(n)
        ranges = cast_room(self.room, self.x, self.y, rel + self.yaw, self.max_range)
        ranges = np.where(ranges >= self.max_range, np.inf, ranges).astype(np.float32)
        self.scan_pub.publish(
            LaserScan(
                header=Header(stamp=self.get_clock().now().to_msg(), frame_id="laser"),
                angle_min=-math.pi,
                angle_max=-math.pi + inc * (n - 1),
                angle_increment=inc,
                scan_time=1.0 / self.scan_rate,
                range_min=0.1,
                range_max=self.max_range,
                ranges=ranges,
            )
        )


class Talker(Node):
    """std_msgs/String 'hello world N' on /chatter, as the ROS tutorials' talker."""

    def __init__(self, *, context: Any, **kwargs: Any) -> None:
        super().__init__("talker", context=context, **kwargs)
        self.pub = self.create_publisher(String, "chatter", 10)
        self.count = 0
        self.create_timer(self.declare_parameter("period", 1.0).value, self._tick)

    def _tick(self) -> None:
        self.pub.publish(String(data=f"hello world {self.count}"))
        self.count += 1
