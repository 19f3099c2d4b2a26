"""The ``slam_gmapping`` node: a thin wrapper of :class:`~roverlab.mapping.gmapping.GMapping`.

What ROS 1's ``gmapping/slam_gmapping`` does, with its names:

* subscribes ``scan`` (``sensor_msgs/LaserScan``) through a TF message filter: a scan is
  processed once ``odom_frame <- scan frame`` is known at the scan's stamp (up to 5 scans
  wait; older ones are dropped with a throttled warning, as tf's MessageFilter does);
* the odometry pose is ``odom_frame -> base_frame`` at the scan's stamp, the laser's pose
  ``base_frame -> scan frame`` (an upside-down laser is handled: every beam direction is
  rotated into the base frame);
* after a scan that updated the filter, publishes ``map`` and ``map_metadata`` (latched)
  from the best particle if ``map_update_interval`` seconds of scan time have passed since
  the last map (the first map as soon as there is one), and ``~entropy``
  (``std_msgs/Float64``, the entropy of the particle weights) with it;
* broadcasts ``map_frame -> odom_frame`` every ``transform_publish_period`` seconds (0: never),
  stamped now + ``tf_delay``; the identity until the first scan is processed.

Parameters: every field of :class:`~roverlab.mapping.gmapping.GMappingParams` under its ROS
name and default (``maxUrange``, ``particles``, ``delta``, ``linearUpdate``, ...; ``maxRange``
and ``tf_delay`` are unset by default, as in ROS), plus roverlab's ``seed`` (int, default 0:
ROS seeds the filter with the wall time, which cannot be reproduced).

:class:`TfMessageFilter` (tf2_ros' MessageFilter for the single-threaded executor) is shared
with the ``hector_mapping`` node.
"""

from __future__ import annotations

import dataclasses
from collections import deque
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.core import Context, Duration, Node, QoSProfile, Time
from roverlab.geometry import SE2, Transform3, quat_rotate
from roverlab.mapping.gmapping.errors import GMappingInputError
from roverlab.mapping.gmapping.params import GMappingParams
from roverlab.mapping.gmapping.slam import GMapping
from roverlab.msgs import Float64, MapMetaData, OccupancyGrid, scan_angles
from roverlab.msgs import classes as mc
from roverlab.tf import (
    TF_MESSAGE_TYPE,
    TF_STATIC_TOPIC,
    TF_TOPIC,
    BackwardExtrapolationException,
    Buffer,
    TransformBroadcaster,
    TransformException,
    TransformListener,
    transform_to_msg,
)

__all__ = ["LaserGeometry", "SlamGMapping", "TfMessageFilter", "Throttle", "laser_geometry"]

_LATCHED = QoSProfile(depth=1, durability="transient_local")
# tf's MessageFilter queue of slam_gmapping (``new tf::MessageFilter(..., odom_frame_, 5)``)
_FILTER_QUEUE = 5
# seconds between two repetitions of the same warning (ROS_WARN_THROTTLE-like)
_WARN_PERIOD_S = 10.0


class Throttle:
    """Lets a message through at most once per ``period_s`` of the node's clock.

    Args:
        node: whose clock and logger are used.
        period_s: seconds between two messages of the same key.
    """

    def __init__(self, node: Node, period_s: float = _WARN_PERIOD_S) -> None:
        self._node = node
        self._period_ns = round(period_s * 1e9)
        self._last: dict[str, int] = {}

    def warning(self, key: str, text: str) -> bool:
        """Log ``text`` as a warning unless ``key`` was logged less than a period ago."""
        now = self._node.get_clock().now_ns()
        last = self._last.get(key)
        if last is not None and now - last < self._period_ns:
            return False
        self._last[key] = now
        self._node.get_logger().warning(text)
        return True


class TfMessageFilter:
    """Holds stamped messages until ``target_frame <- msg.header.frame_id`` is in the buffer
    at the message's stamp, then hands them to ``callback`` in arrival order (tf2_ros
    MessageFilter, for an executor that must not block).

    Waiting messages are retried whenever ``/tf`` or ``/tf_static`` brings data. A message is
    dropped when ``queue_size`` newer ones wait behind it, when its stamp is older than the
    buffer's data (it can never be transformed), or, with ``timeout_s``, when it has waited
    that long on the node's clock; drops are counted and reported by a throttled warning.
    ``optional_frames`` are waited for too, but only up to ``timeout_s``: then the message
    is handed on without them (hector's ``waitForTransform`` before a lookup that may fail).

    Args:
        node: the node that subscribes ``/tf`` and ``/tf_static`` for the retries.
        buffer: the TF buffer (fed by a :class:`~roverlab.tf.TransformListener` created
            before this filter, so that a retry sees the data that triggered it).
        target_frames: frames every message must be transformable into.
        queue_size: how many messages may wait.
        callback: called with each message once it can be transformed.
        timeout_s: drop a message that waited this long (None: never).
        optional_frames: frames waited for at most ``timeout_s``.
        on_timeout: called with each message dropped for waiting ``timeout_s`` (instead of
            the throttled warning; it is still counted).

    Attributes:
        dropped: messages dropped so far.
        passed: messages handed on so far.
    """

    def __init__(
        self,
        node: Node,
        buffer: Buffer,
        target_frames: list[str],
        queue_size: int,
        callback: Callable[[Any], Any],
        *,
        timeout_s: float | None = None,
        optional_frames: list[str] | None = None,
        on_timeout: Callable[[Any], Any] | None = None,
    ) -> None:
        if queue_size < 1:
            raise ValueError(f"queue_size must be >= 1, got {queue_size}")
        self._node = node
        self._buffer = buffer
        self.target_frames = list(target_frames)
        self.optional_frames = list(optional_frames or [])
        self._callback = callback
        self._on_timeout = on_timeout
        self._timeout_ns = None if timeout_s is None else round(timeout_s * 1e9)
        self._queue: deque[tuple[Any, int]] = deque()
        self._queue_size = queue_size
        self._throttle = Throttle(node)
        self.dropped = 0
        self.passed = 0
        node.create_subscription(TF_MESSAGE_TYPE, TF_TOPIC, self._on_tf, 100)
        node.create_subscription(
            TF_MESSAGE_TYPE,
            TF_STATIC_TOPIC,
            self._on_tf,
            QoSProfile(depth=100, durability="transient_local"),
        )

    @property
    def waiting(self) -> int:
        """Messages waiting for their transform."""
        return len(self._queue)

    def add(self, msg: Any) -> None:
        """Queue ``msg`` and hand on every message that can now be transformed."""
        self._queue.append((msg, self._node.get_clock().now_ns()))
        self._drain()
        while len(self._queue) > self._queue_size:
            old, _ = self._queue.popleft()
            self._drop(old, "discarding message because the queue is full")

    def _on_tf(self, _msg: Any) -> None:
        if self._queue:
            self._drain()

    def _drain(self) -> None:
        now = self._node.get_clock().now_ns()
        while self._queue:
            msg, arrived = self._queue[0]
            expired = self._timeout_ns is not None and now - arrived >= self._timeout_ns
            state = self._ready(msg, self.target_frames)
            if state == "ready" and not expired:
                state = self._ready(msg, self.optional_frames)
            if state == "ready":
                self._queue.popleft()
                self.passed += 1
                self._callback(msg)
                continue
            if state == "too_old":
                self._queue.popleft()
                self._drop(msg, "the transform is older than the TF buffer's data")
                continue
            if expired:
                self._queue.popleft()
                if self._on_timeout is None:
                    self._drop(msg, "timed out waiting for the transform")
                else:
                    self.dropped += 1
                    self._on_timeout(msg)
                continue
            return

    def _ready(self, msg: Any, targets: list[str]) -> str:
        frame = str(msg.header.frame_id).lstrip("/")
        stamp = Time.from_msg(msg.header.stamp)
        for target in targets:
            try:
                self._buffer.lookup_transform(target, frame, stamp)
            except BackwardExtrapolationException:
                return "too_old"
            except TransformException:
                return "wait"
        return "ready"

    def _drop(self, msg: Any, reason: str) -> None:
        self.dropped += 1
        total = self.dropped + self.passed
        targets = ", ".join(self.target_frames)
        self._throttle.warning(
            "drop",
            f"MessageFilter [target={targets}]: dropped {100.0 * self.dropped / total:.2f}% of "
            f"messages so far (frame {str(msg.header.frame_id)!r}: {reason})",
        )


@dataclasses.dataclass(frozen=True, slots=True)
class LaserGeometry:
    """A planar laser mounted on the robot, in the robot's base frame.

    Attributes:
        offset: the laser's position in the base frame (``theta`` 0: the beam directions
            below are already rotated into the base frame).
        angles: (N,) direction of each beam in the base frame (rad).
        z_m: the laser's height in the base frame (m).
        upside_down: the laser's z axis points down (its beams sweep clockwise).
    """

    offset: SE2
    angles: NDArray[np.float64]
    z_m: float
    upside_down: bool


def laser_geometry(scan: Any, base_T_laser: Transform3) -> LaserGeometry:
    """Beam directions and laser position of ``scan`` in the base frame.

    Each beam direction ``(cos a, sin a, 0)`` of the laser frame is rotated into the base
    frame and projected on its plane, so a laser mounted upside down (gmapping's "laser is
    mounted upside down" case) or yawed needs no special case.
    """
    a = scan_angles(scan)
    q = np.asarray(base_T_laser.rotation, dtype=np.float64)
    ex = quat_rotate(q, (1.0, 0.0, 0.0))
    ey = quat_rotate(q, (0.0, 1.0, 0.0))
    ez = quat_rotate(q, (0.0, 0.0, 1.0))
    c, s = np.cos(a), np.sin(a)
    dx = c * ex[0] + s * ey[0]
    dy = c * ex[1] + s * ey[1]
    tx, ty, tz = base_T_laser.translation
    return LaserGeometry(
        offset=SE2(float(tx), float(ty), 0.0),
        angles=np.arctan2(dy, dx),
        z_m=float(tz),
        upside_down=bool(ez[2] < 0.0),
    )


class SlamGMapping(Node):
    """``slam_gmapping``: laser SLAM with a Rao-Blackwellised particle filter, live.

    Args:
        context: the context the node joins.
        node_name: defaults to ``slam_gmapping``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (the launch file's private
            ``<param>``s), ``remappings`` of :class:`~roverlab.core.Node`.

    Attributes:
        params: the validated :class:`GMappingParams`.
        slam: the filter (:class:`GMapping`).
        map_msg: the last ``nav_msgs/OccupancyGrid`` published, or None.
        scans_processed: scans that updated the filter.
        scans_received: scans handed over by the TF filter.

    Raises:
        GMappingParamsError: a parameter of the wrong type or out of range.
        ParameterError: a parameter override that does not fit its declared type.
    """

    def __init__(
        self, context: Context, *, node_name: str = "slam_gmapping", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        values: dict[str, Any] = {}
        for f in dataclasses.fields(GMappingParams):
            value = self.declare_parameter(f.name, f.default).value
            if value is not None:
                values[f.name] = value
        self.params = GMappingParams.from_ros(values)
        self.seed = int(self.declare_parameter("seed", 0).value)
        p = self.params
        self.slam = GMapping(p, np.random.default_rng(self.seed))
        self.map_msg: Any = None
        self.scans_processed = 0
        self.scans_received = 0
        self._map_to_odom = Transform3()
        self._last_map_ns: int | None = None
        self._initialised = False
        self._throttle = Throttle(self)
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.map_publisher = self.create_publisher(OccupancyGrid, "map", _LATCHED)
        self.metadata_publisher = self.create_publisher(MapMetaData, "map_metadata", _LATCHED)
        self.entropy_publisher = self.create_publisher(Float64, "~entropy", 10)
        self.scan_filter = TfMessageFilter(
            self, self.tf_buffer, [p.odom_frame], _FILTER_QUEUE, self._on_scan
        )
        self.create_subscription(mc.LaserScan, "scan", self.scan_filter.add, _FILTER_QUEUE)
        self._tf_delay = p.tf_delay if p.tf_delay is not None else p.transform_publish_period
        if p.transform_publish_period > 0.0:
            self.create_timer(p.transform_publish_period, self._publish_transform)

    # ------------------------------------------------------------------ scans
    def _on_scan(self, scan: Any) -> None:
        p = self.params
        self.scans_received += 1
        stamp = Time.from_msg(scan.header.stamp)
        frame = str(scan.header.frame_id).lstrip("/")
        try:
            base_laser, _ = self.tf_buffer.lookup_transform(p.base_frame, frame, stamp)
            odom_base, _ = self.tf_buffer.lookup_transform(p.odom_frame, p.base_frame, stamp)
        except TransformException as err:
            self._throttle.warning("odom", f"Failed to compute odom pose, skipping scan ({err})")
            return
        laser = laser_geometry(scan, base_laser)
        if not self._initialised:
            self._initialised = True
            if laser.upside_down:
                self.get_logger().info("Laser is mounted upside down.")
            else:
                self.get_logger().info("Laser is mounted upwards.")
        odom = odom_base.to_se2()
        try:
            updated = self.slam.process(
                np.asarray(scan.ranges, dtype=np.float64),
                laser.angles,
                odom,
                stamp.nanoseconds / 1e9,
                range_min=float(scan.range_min),
                range_max=float(scan.range_max),
                laser_offset=laser.offset,
            )
        except GMappingInputError as err:
            self._throttle.warning("input", f"scan dropped: {err}")
            return
        if not updated:
            return
        self.scans_processed += 1
        self._map_to_odom = Transform3.from_se2(self.slam.map_to_odom())
        interval_ns = round(p.map_update_interval * 1e9)
        if self._last_map_ns is None or stamp.nanoseconds - self._last_map_ns > interval_ns:
            self._update_map()
            self._last_map_ns = stamp.nanoseconds

    def _update_map(self) -> None:
        grid = self.slam.occupancy()
        stamp = self.get_clock().now()
        msg = grid.to_msg(frame_id=self.params.map_frame, stamp=stamp)
        self.map_msg = msg
        self.entropy_publisher.publish(Float64(data=self.entropy()))
        self.map_publisher.publish(msg)
        self.metadata_publisher.publish(msg.info)

    def entropy(self) -> float:
        """Entropy of the normalised particle weights (slam_gmapping's ``~entropy``)."""
        w = self.slam.weights()
        w = w[w > 0.0]
        return float(-np.sum(w * np.log(w)))

    # ------------------------------------------------------------------ TF
    @property
    def map_to_odom(self) -> Transform3:
        """The ``map -> odom`` transform being broadcast."""
        return self._map_to_odom

    def _publish_transform(self) -> None:
        p = self.params
        stamp = self.get_clock().now() + Duration.from_seconds(self._tf_delay)
        self.tf_broadcaster.send_transform(
            transform_to_msg(p.map_frame, p.odom_frame, stamp, self._map_to_odom)
        )
