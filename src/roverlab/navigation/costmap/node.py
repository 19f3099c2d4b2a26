"""costmap_2d's ROS wrapper: :class:`Costmap2DROS` and the ``costmap_2d_node`` node.

:class:`Costmap2DROS` runs inside a host node (move_base's ``global_costmap`` and
``local_costmap``, or :class:`Costmap2DNode`'s ``costmap``) with the parameters under the
host's ``NAME/`` (both ROS spellings, see :mod:`.params`; ``footprint`` and
``robot_radius`` are also looked up at the host's level, as ``searchParam``). It:

* subscribes each static layer's ``map_topic`` (latched; ``NAME_updates`` with
  ``subscribe_to_updates``; once with ``first_map_only``) and each observation source's
  ``topic`` (``LaserScan``, ``PointCloud2`` or ``PointCloud``) through a TF message filter
  to ``global_frame`` (and ``sensor_frame``);
* every ``1 / update_frequency`` s, looks the robot up (``global_frame <- robot_base_frame``,
  no older than ``transform_tolerance``), updates the layered costmap, publishes the padded
  footprint on ``~NAME/footprint`` (``geometry_msgs/PolygonStamped``) and, every
  ``1 / publish_frequency`` s, the costmap on ``~NAME/costmap`` (``OccupancyGrid``) or the
  changed window on ``~NAME/costmap_updates`` (``map_msgs/OccupancyGridUpdate``); messages
  nobody subscribes to are not built (a reader that comes later gets a whole grid first).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from roverlab.core import Context, Node, QoSProfile, Time
from roverlab.geometry import SE2, Transform3
from roverlab.msgs import OccupancyGrid, PolygonStamped, get_type, pointcloud2_to_xyz
from roverlab.msgs import classes as mc
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.costmap.footprint import transform_footprint
from roverlab.navigation.costmap.kernels import scan_points
from roverlab.navigation.costmap.layered import LayeredCostmap
from roverlab.navigation.costmap.obstacle_layer import ObstacleLayer
from roverlab.navigation.costmap.params import CostmapParams, make_layered_costmap
from roverlab.navigation.costmap.publisher import CostmapPublisherState, footprint_message
from roverlab.navigation.costmap.static_layer import StaticLayer
from roverlab.navigation.errors import CostmapError, NavigationError
from roverlab.navigation.node_params import parameters_under
from roverlab.tf import Buffer, TfMessageFilter, Throttle, TransformException, TransformListener

__all__ = ["Costmap2DNode", "Costmap2DROS"]

_LATCHED = QoSProfile(depth=1, durability="transient_local")
_UPDATE_TYPE = "map_msgs/msg/OccupancyGridUpdate"
_SENSOR_QUEUE = 50
_START_WARN_S = 5.0  # Costmap2DROS at start: quiet, then one line every 5 s until the pose


class Costmap2DROS:
    """A costmap in a node, as costmap_2d's ``Costmap2DROS``.

    Args:
        node: the host node (its parameters, topics, clock and logger).
        name: the costmap's name (``global_costmap``, ``local_costmap``, ``costmap``).
        tf_buffer: the host's TF buffer (fed by a ``TransformListener``).

    Attributes:
        params: the parsed :class:`CostmapParams`.
        layered: the :class:`LayeredCostmap` (its ``costmap`` is the master grid).
        footprint: the padded footprint polygon, robot frame.

    Raises:
        NavigationParamsError: a bad or unknown costmap parameter.
    """

    def __init__(self, node: Node, name: str, tf_buffer: Buffer) -> None:
        self.node = node
        self.name = name
        self.tf_buffer = tf_buffer
        values = parameters_under(
            node, name, searched=("footprint", "robot_radius", "footprint_padding")
        )
        self.params, warnings = CostmapParams.from_ros(values, name=name)
        for w in warnings:
            node.get_logger().warning(w)
        p = self.params
        self.layered: LayeredCostmap = make_layered_costmap(p)
        self.footprint = p.padded_footprint()
        self._throttle = Throttle(node, 1.0)
        self._pose_seen = False
        self._start_warning_ns: int | None = None
        self._stopped = False
        self._last_publish_ns: int | None = None
        self._publisher = CostmapPublisherState(always_send_full_costmap=p.always_send_full_costmap)
        self.updates = 0
        self.costmap_pub = node.create_publisher(OccupancyGrid, f"~/{name}/costmap", _LATCHED)
        self.update_pub = node.create_publisher(_UPDATE_TYPE, f"~/{name}/costmap_updates", 10)
        self.footprint_pub = node.create_publisher(
            PolygonStamped, f"~/{name}/{p.published_footprint_topic}", 1
        )
        self._map_subs: dict[str, Any] = {}
        for layer in self.layered.plugins:
            if isinstance(layer, StaticLayer):
                self._subscribe_map(layer)
            elif isinstance(layer, ObstacleLayer):
                self._subscribe_sensors(layer)
        self.timer = None
        if p.update_frequency > 0:
            self.timer = node.create_timer(1.0 / p.update_frequency, self.update_map)

    # ------------------------------------------------------------------ inputs
    def _subscribe_map(self, layer: StaticLayer) -> None:
        lp = layer.params

        def on_map(msg: Any) -> None:
            try:
                accepted = layer.incoming_map(
                    np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width),
                    resolution=float(msg.info.resolution),
                    origin_x=float(msg.info.origin.position.x),
                    origin_y=float(msg.info.origin.position.y),
                    frame_id=str(msg.header.frame_id) or "map",
                )
            except (CostmapError, ValueError) as err:
                self.node.get_logger().error(f"{self.name}/{layer.name}: map dropped: {err}")
                return
            if accepted and lp.first_map_only and layer.name in self._map_subs:
                self.node.destroy_subscription(self._map_subs.pop(layer.name))

        self._map_subs[layer.name] = self.node.create_subscription(
            OccupancyGrid, lp.map_topic, on_map, _LATCHED
        )
        if lp.subscribe_to_updates:

            def on_update(msg: Any) -> None:
                try:
                    layer.incoming_update(
                        int(msg.x), int(msg.y), int(msg.width), int(msg.height), msg.data
                    )
                except CostmapError as err:
                    self._throttle.warning("update", f"{self.name}/{layer.name}: {err}")

            self.node.create_subscription(_UPDATE_TYPE, lp.map_topic + "_updates", on_update, 10)

    def _subscribe_sensors(self, layer: ObstacleLayer) -> None:
        gf = self.params.global_frame
        for src in layer.params.observation_sources:
            frames = [gf] + ([src.sensor_frame] if src.sensor_frame else [])

            def on_msg(msg: Any, source: str = src.name) -> None:
                self._observation(layer, source, msg)

            flt = TfMessageFilter(
                self.node,
                self.tf_buffer,
                frames,
                _SENSOR_QUEUE,
                on_msg,
                timeout_s=layer.params.transform_tolerance,
            )
            mtype = {
                "LaserScan": mc.LaserScan,
                "PointCloud2": mc.PointCloud2,
                "PointCloud": get_type("sensor_msgs/msg/PointCloud"),
            }[src.data_type]
            self.node.create_subscription(mtype, src.topic_name, flt.add, _SENSOR_QUEUE)

    def _observation(self, layer: ObstacleLayer, source: str, msg: Any) -> None:
        sp = layer.buffers[source].params
        stamp = Time.from_msg(msg.header.stamp)
        frame = str(msg.header.frame_id).lstrip("/")
        gf = self.params.global_frame
        try:
            g_T_msg, _ = self.tf_buffer.lookup_transform(gf, frame, stamp)
            sensor = sp.sensor_frame.lstrip("/") or frame
            g_T_sensor = (
                g_T_msg
                if sensor == frame
                else self.tf_buffer.lookup_transform(gf, sensor, stamp)[0]
            )
        except TransformException as err:
            self._throttle.warning(
                "tf-" + source, f"{self.name}: observation of {source} dropped: {err}"
            )
            return
        data_type, inf_is_valid = sp.data_type, sp.inf_is_valid

        def points() -> np.ndarray:  # made when an update first uses the observation
            if data_type == "LaserScan":
                ranges = np.asarray(msg.ranges)
                if ranges.dtype != np.float32 and ranges.dtype != np.float64:
                    ranges = ranges.astype(np.float64)
                cos_a, sin_a = _beam_trig(
                    float(msg.angle_min), float(msg.angle_increment), len(ranges)
                )
                # project_scan then g_T_msg.apply, in one compiled pass (the same values)
                return scan_points(
                    ranges, cos_a, sin_a, float(msg.range_min), float(msg.range_max),
                    inf_is_valid, np.asarray(g_T_msg.rotation, dtype=np.float64),
                    np.asarray(g_T_msg.translation, dtype=np.float64),
                )  # fmt: skip
            if data_type == "PointCloud2":
                pts = pointcloud2_to_xyz(msg, skip_nans=True).astype(np.float64)
            else:
                pts = np.array([[p.x, p.y, p.z] for p in msg.points], dtype=np.float64)
            return _apply(g_T_msg, pts)

        try:
            origin = np.asarray(g_T_sensor.translation, dtype=np.float64)
            now = self.node.get_clock().now().nanoseconds / 1e9
            layer.add_observation(source, origin, points, stamp.nanoseconds / 1e9, now)
        except (NavigationError, ValueError) as err:
            self._throttle.warning("obs-" + source, f"{self.name}: {source} dropped: {err}")

    # ------------------------------------------------------------------ state
    @property
    def costmap(self) -> Costmap2D:
        """The master grid."""
        return self.layered.costmap

    @property
    def global_frame(self) -> str:
        return self.params.global_frame

    @property
    def robot_base_frame(self) -> str:
        return self.params.robot_base_frame

    @property
    def ready(self) -> bool:
        """Whether the master grid has been built from its inputs: updated at least once,
        with every static layer's map received (ROS's Costmap2DROS does not start before
        its static layer has a map)."""
        if self.updates == 0 or not self.layered.initialized:
            return False
        return all(
            layer.map_received for layer in self.layered.plugins if isinstance(layer, StaticLayer)
        )

    def get_robot_pose(self) -> SE2 | None:
        """The robot's pose in ``global_frame`` (None, with a throttled message, when the
        transform is missing or older than ``transform_tolerance``)."""
        p = self.params
        try:
            tf, stamp = self.tf_buffer.lookup_transform(p.global_frame, p.robot_base_frame, Time())
        except TransformException as err:
            if self._pose_seen:
                self._throttle.warning("pose", f"{self.name}: could not get robot pose: {err}")
            else:
                self._waiting_for_pose(str(err))
            return None
        now = self.node.get_clock().now()
        age = (now.nanoseconds - stamp.nanoseconds) / 1e9
        if age > p.transform_tolerance and not self._pose_seen:
            self._waiting_for_pose(f"the transform is {age:.2f} s old")
            return None
        self._pose_seen = True
        if age > p.transform_tolerance:
            self._throttle.warning(
                "stale",
                f"Costmap2DROS transform timeout. Current time: {now.nanoseconds / 1e9:.4f}, "
                f"global_pose stamp: {stamp.nanoseconds / 1e9:.4f}, tolerance: "
                f"{p.transform_tolerance:.4f}",
            )
            return None
        return tf.to_se2()

    def _waiting_for_pose(self, err: str) -> None:
        """Before the first pose, as Costmap2DROS waits for its transform at start: quiet
        for the first seconds (the TF tree fills in, and catches up, as the other nodes
        start), then one line every few seconds."""
        now = self.node.get_clock().now_ns()
        if self._start_warning_ns is None:
            self._start_warning_ns = now + round(_START_WARN_S * 1e9)
        if now < self._start_warning_ns:
            return
        self._start_warning_ns = now + round(_START_WARN_S * 1e9)
        p = self.params
        self.node.get_logger().warning(
            f"{self.name}: waiting for the transform from {p.robot_base_frame} to "
            f"{p.global_frame} to become available before running the costmap: {err}"
        )

    def oriented_footprint(self, pose: SE2) -> np.ndarray:
        """The padded footprint at ``pose`` (global frame)."""
        return transform_footprint(pose.x, pose.y, pose.theta, self.footprint)

    def is_current(self) -> bool:
        """Whether every layer's sensor data is up to date (``expected_update_rate``)."""
        return self.layered.is_current(self.node.get_clock().now().nanoseconds / 1e9)

    def update_map(self) -> None:
        """One update cycle (the timer's callback; callable directly)."""
        if self._stopped:
            return
        pose = self.get_robot_pose()
        if pose is None:
            return
        for layer in self.layered.plugins:
            if isinstance(layer, StaticLayer) and self.layered.rolling_window and layer.map_frame:
                try:
                    tf, _ = self.tf_buffer.lookup_transform(
                        self.params.global_frame, layer.map_frame, Time()
                    )
                    layer.map_to_global = tf.to_se2()
                except TransformException as err:
                    self._throttle.warning("map-tf", f"{self.name}/{layer.name}: {err}")
        now = self.node.get_clock().now()
        self.layered.update_map(pose.x, pose.y, pose.theta, now.nanoseconds / 1e9)
        self.updates += 1
        for layer in self.layered.plugins:
            if isinstance(layer, ObstacleLayer) and layer.sensor_warnings:
                self._throttle.warning("sensor", f"{self.name}: {layer.sensor_warnings[-1]}")
                layer.sensor_warnings.clear()
        if self.footprint_pub.has_listeners:  # a message each update: only for a reader
            gf = self.params.global_frame
            self.footprint_pub.publish(footprint_message(self.oriented_footprint(pose), gf, now))
        p = self.params
        if p.publish_frequency > 0 and self.layered.initialized:
            x0, xn, y0, yn = self.layered.bounds_cells
            self._publisher.update_bounds(x0, xn, y0, yn)
            period = round(1e9 / p.publish_frequency)
            if self._last_publish_ns is None or now.nanoseconds - self._last_publish_ns > period:
                self.publish()
                self._last_publish_ns = now.nanoseconds

    def publish(self) -> None:
        """Publish the costmap (whole, or the window changed since the last time). With no
        reader of either topic nothing is built, and the next message is a whole grid."""
        if not (self.costmap_pub.has_listeners or self.update_pub.has_listeners):
            self._publisher.force_full()
            return
        now = self.node.get_clock().now()
        kind, msg = self._publisher.next_message(self.costmap, self.params.global_frame, now)
        if kind == "full":
            self.costmap_pub.publish(msg)
        elif kind == "update":
            self.update_pub.publish(msg)

    # ------------------------------------------------------------------ control
    def reset_layers(self) -> None:
        """Clear the master grid and every layer (move_base's ``clear_costmaps``)."""
        self.layered.reset()

    def stop(self) -> None:
        """Stop updating (move_base's ``shutdown_costmaps``)."""
        self._stopped = True

    def start(self) -> None:
        """Resume updating."""
        self._stopped = False


@functools.lru_cache(maxsize=16)
def _beam_trig(angle_min: float, increment: float, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Cosine and sine of each beam's angle (``scan_angles``), computed once per scan
    geometry (read-only)."""
    angles = angle_min + np.arange(count, dtype=np.float64) * increment
    cos_a, sin_a = np.cos(angles), np.sin(angles)
    cos_a.flags.writeable = sin_a.flags.writeable = False
    return cos_a, sin_a


def _apply(tf: Transform3, pts: np.ndarray) -> np.ndarray:
    if len(pts) == 0:
        return pts.reshape(0, 3)
    return np.asarray(tf.apply(pts), dtype=np.float64)


class Costmap2DNode(Node):
    """``costmap_2d/costmap_2d_node``: a standalone costmap named ``costmap``.

    Args:
        context: the context the node joins.
        node_name: defaults to ``costmap_2d_node``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Attributes:
        costmap_ros: the :class:`Costmap2DROS`.

    Raises:
        NavigationParamsError: a bad costmap parameter.
    """

    def __init__(
        self, context: Context, *, node_name: str = "costmap_2d_node", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.costmap_ros = Costmap2DROS(self, "costmap", self.tf_buffer)
