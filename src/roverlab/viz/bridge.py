"""The dashboard's node: subscribes to what the displays draw, publishes what the tools make.

:class:`VizBridge` is the only part of :mod:`roverlab.viz` that touches the bus. Its
subscription callbacks run on the executor thread and only store the newest data with a
version number; the web server's threads read snapshots (``*_frame`` / :meth:`state`)
and compare versions, so each client gets only what changed.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from roverlab.core import Context, QoSProfile, Time
from roverlab.description.urdf import parse_urdf
from roverlab.geometry import Transform3, yaw_from_quat
from roverlab.msgs import (
    PointStamped,
    PoseStamped,
    PoseWithCovarianceStamped,
    image_to_array,
    occupancy_grid_to_array,
    pose_from_xytheta,
    scan_to_points,
    stamp_to_msg,
    yaw_from_quaternion,
)
from roverlab.teleop import twist_for_key
from roverlab.teleop.node import command_to_twist
from roverlab.tf import Buffer, TransformException, TransformListener
from roverlab.viz.protocol import (
    INITIALPOSE_COVARIANCE,
    VisualOutline,
    encode_image,
    encode_map,
    encode_scan,
    image_to_rgb8,
    robot_outlines,
)

__all__ = ["IMAGE_TYPE", "Versioned", "VizBridge"]

IMAGE_TYPE: Final = "sensor_msgs/msg/Image"
_LATCHED: Final = QoSProfile(depth=1, durability="transient_local")


@dataclass(frozen=True)
class Versioned:
    """A payload and the version it belongs to (versions only grow)."""

    version: int
    payload: Any


def _xyyaw(t: Transform3) -> list[float]:
    return [
        round(t.translation[0], 4),
        round(t.translation[1], 4),
        round(yaw_from_quat(t.rotation), 4),
    ]


class VizBridge:
    """Subscriptions and publishers of the dashboard in ``context``.

    Args:
        context: the context to attach to (in-process, or a :class:`Connection`'s).
        fixed_frame: frame the displays are drawn in; ``odom`` is used while it is unknown.
        speed_mps: linear speed of the drive keys (teleop_twist_keyboard's ``~speed``).
        turn_radps: angular speed of the drive keys (``~turn``).
        node_name: name of the node.
    """

    def __init__(
        self,
        *,
        context: Context,
        fixed_frame: str = "map",
        speed_mps: float = 0.3,
        turn_radps: float = 0.5,
        node_name: str = "rviz",
    ) -> None:
        self.context = context
        self.requested_fixed_frame = fixed_frame
        self.speed_mps = speed_mps
        self.turn_radps = turn_radps
        self.node = context.create_node(node_name)
        self.tf_buffer = Buffer()
        self._listener = TransformListener(self.tf_buffer, self.node)
        self._lock = threading.Lock()
        self._version = 0
        self.map_frame: Versioned | None = None
        self.map_frame_id = "map"
        self.scan_frame: Versioned | None = None
        self.outlines: Versioned | None = None
        self._odom: Any = None
        self._image_topic: str | None = None
        self._image_msg: Versioned | None = None
        self._image_jpeg: Versioned | None = None
        self._image_subs: dict[str, Any] = {}
        node = self.node
        node.create_subscription("nav_msgs/msg/OccupancyGrid", "/map", self._on_map, _LATCHED)
        node.create_subscription("sensor_msgs/msg/LaserScan", "/scan", self._on_scan, 5)
        node.create_subscription("nav_msgs/msg/Odometry", "/odom", self._on_odom, 5)
        node.create_subscription(
            "std_msgs/msg/String", "/robot_description", self._on_description, _LATCHED
        )
        self.goal_pub = node.create_publisher(
            "geometry_msgs/msg/PoseStamped", "/move_base_simple/goal", 1
        )
        self.initialpose_pub = node.create_publisher(
            "geometry_msgs/msg/PoseWithCovarianceStamped", "/initialpose", 1
        )
        self.point_pub = node.create_publisher(
            "geometry_msgs/msg/PointStamped", "/clicked_point", 1
        )
        self.cmd_vel_pub = node.create_publisher("geometry_msgs/msg/Twist", "/cmd_vel", 1)

    # ------------------------------------------------------------------ state
    def _next(self) -> int:
        with self._lock:
            self._version += 1
            return self._version

    @property
    def fixed_frame(self) -> str:
        """The requested fixed frame if TF knows it, else ``odom``."""
        if self.tf_buffer.has_frame(self.requested_fixed_frame):
            return self.requested_fixed_frame
        return "odom"

    def _lookup(self, frame: str, stamp: Any = None) -> Transform3 | None:
        fixed = self.fixed_frame
        frame = frame.lstrip("/")
        if frame == fixed:
            return Transform3()
        if stamp is not None:
            try:
                return self.tf_buffer.lookup_transform(fixed, frame, stamp)[0]
            except TransformException:
                pass
        try:
            return self.tf_buffer.lookup_transform(fixed, frame, Time(0))[0]
        except TransformException:
            return None

    # -------------------------------------------------------------- callbacks
    def _on_map(self, msg: Any) -> None:
        cells = occupancy_grid_to_array(msg)
        o = msg.info.origin
        origin = (
            float(o.position.x),
            float(o.position.y),
            yaw_from_quaternion(o.orientation),
        )
        frame = encode_map(cells, resolution_m=float(msg.info.resolution), origin=origin)
        self.map_frame_id = str(msg.header.frame_id).lstrip("/") or "map"
        self.map_frame = Versioned(self._next(), frame)

    def _on_scan(self, msg: Any) -> None:
        pts = scan_to_points(msg)
        stamp = Time(int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec))
        tf = self._lookup(str(msg.header.frame_id), stamp)
        if tf is None:
            return
        world = tf.apply(np.column_stack((pts, np.zeros(len(pts)))))[:, :2]
        self.scan_frame = Versioned(self._next(), encode_scan(world))

    def _on_odom(self, msg: Any) -> None:
        self._odom = msg

    def _on_description(self, msg: Any) -> None:
        model = parse_urdf(str(msg.data), source="/robot_description")
        self.outlines = Versioned(self._next(), robot_outlines(model))

    def _on_image(self, topic: str, msg: Any) -> None:
        if topic == self._image_topic:
            self._image_msg = Versioned(self._next(), msg)

    # ---------------------------------------------------------------- queries
    def image_topics(self) -> list[str]:
        """Topics of type ``sensor_msgs/msg/Image`` in the graph."""
        graph = self.context.graph.topics
        return sorted(name for name, t in list(graph.items()) if t.typename == IMAGE_TYPE)

    def select_image(self, topic: str) -> None:
        """Show ``topic`` in the image panel (subscribed on first use; any thread)."""
        self._image_topic = topic
        self._image_msg = None
        if topic in self._image_subs:
            return

        def subscribe() -> None:
            if self._image_subs.get(topic) is None:
                self._image_subs[topic] = self.node.create_subscription(
                    IMAGE_TYPE, topic, lambda m: self._on_image(topic, m), 1
                )

        self._image_subs[topic] = None  # claimed; the executor thread fills it in
        self.context.executor.call_soon_threadsafe(subscribe)

    def image_frame(self) -> Versioned | None:
        """The newest image of the selected topic as a JPEG frame (encoded once)."""
        msg = self._image_msg
        if msg is None:
            return None
        cached = self._image_jpeg
        if cached is not None and cached.version == msg.version:
            return cached
        rgb = image_to_rgb8(image_to_array(msg.payload), str(msg.payload.encoding))
        frame = Versioned(msg.version, encode_image(rgb))
        self._image_jpeg = frame
        return frame

    def state(self) -> dict[str, Any]:
        """Small per-tick state: fixed frame, frame axes, odometry arrow, robot outline."""
        fixed = self.fixed_frame
        frames: dict[str, list[float]] = {}
        for name in self.tf_buffer.frames():
            tf = self._lookup(name)
            if tf is not None:
                frames[name] = _xyyaw(tf)
        odom = None
        msg = self._odom
        if msg is not None:
            tf = self._lookup(str(msg.header.frame_id))
            if tf is not None:
                p, q = msg.pose.pose.position, msg.pose.pose.orientation
                pose = tf * Transform3((float(p.x), float(p.y), float(p.z)), (q.x, q.y, q.z, q.w))
                odom = _xyyaw(pose)
        robot: list[dict[str, Any]] = []
        outlines: list[VisualOutline] = self.outlines.payload if self.outlines else []
        for outline in outlines:
            tf = self._lookup(outline.link)
            if tf is None:
                continue
            poly = outline.footprint(tf)
            robot.append(
                {
                    "rgba": outline.rgba,
                    "points": [[round(x, 4), round(y, 4)] for x, y in poly],
                }
            )
        return {
            "type": "state",
            "fixed_frame": fixed,
            "map_frame": self.map_frame_id,
            "frames": frames,
            "odom": odom,
            "robot": robot,
            "image_topics": self.image_topics(),
        }

    # ------------------------------------------------------------------ tools
    def _header(self) -> dict[str, Any]:
        return {"frame_id": self.fixed_frame, "stamp": stamp_to_msg(self.context.now())}

    def publish_goal(self, x: float, y: float, yaw: float) -> None:
        """2D Nav Goal: a PoseStamped in the fixed frame on ``/move_base_simple/goal``."""
        self.goal_pub.publish(PoseStamped(header=self._header(), pose=pose_from_xytheta(x, y, yaw)))

    def publish_initialpose(self, x: float, y: float, yaw: float) -> None:
        """2D Pose Estimate: ``/initialpose`` with rviz's default covariance."""
        msg = PoseWithCovarianceStamped(
            header=self._header(),
            pose={
                "pose": pose_from_xytheta(x, y, yaw),
                "covariance": np.array(INITIALPOSE_COVARIANCE, dtype=np.float64),
            },
        )
        self.initialpose_pub.publish(msg)

    def publish_point(self, x: float, y: float) -> None:
        """Publish Point: a PointStamped in the fixed frame on ``/clicked_point``."""
        self.point_pub.publish(
            PointStamped(header=self._header(), point={"x": float(x), "y": float(y)})
        )

    def drive_key(self, key: str) -> bool:
        """A teleop key (``i j l , k`` ...): its Twist on ``/cmd_vel``. False if ignored."""
        cmd = twist_for_key(key, self.speed_mps, self.turn_radps)
        if cmd is None:
            return False
        self.cmd_vel_pub.publish(command_to_twist(cmd))
        return True
