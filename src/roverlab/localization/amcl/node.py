"""The ``amcl`` node: a thin wrapper of :class:`~roverlab.localization.amcl.Amcl`.

What ROS 1's ``amcl/amcl`` does, with its names:

* the map comes from the ``static_map`` service (``nav_msgs/GetMap``, retried every
  0.5 s until it answers) or, with ``use_map_topic``, from the latched ``map`` topic
  (``first_map_only`` keeps the first); every new map restarts the filter from
  ``initial_pose_*`` / ``initial_cov_*``;
* ``scan`` (``sensor_msgs/LaserScan``) passes a TF message filter (target
  ``odom_frame_id``, 100 scans); the odometry pose is ``odom_frame_id <- base_frame_id``
  at the scan's stamp, the laser's bearings are turned into the base frame as amcl does
  (so an upside-down laser works);
* ``initialpose`` (``geometry_msgs/PoseWithCovarianceStamped`` in ``global_frame_id``,
  moved by the odometry since its stamp) re-initialises the particles;
* publishes ``amcl_pose`` (``PoseWithCovarianceStamped``: the heaviest cluster's mean
  with the whole set's covariance) and ``particlecloud`` (``PoseArray``; at most
  ``gui_publish_rate`` per second when that is positive), both latched, and broadcasts
  ``global_frame_id -> odom_frame_id`` stamped ``scan stamp + transform_tolerance``
  (``tf_broadcast``); the last pose is written back to the node's ``initial_pose_*`` /
  ``initial_cov_*`` parameters every ``1 / save_pose_rate`` seconds, as amcl writes the
  parameter server;
* services ``global_localization`` and ``request_nomotion_update`` (``std_srvs/Empty``)
  and ``set_map`` (``nav_msgs/SetMap``);
* warns when no scan was processed for 15 s, naming the laser frame TF lacks.

Parameters: every field of :class:`~roverlab.localization.amcl.AmclParams` under its ROS
name and default, plus roverlab's ``seed`` (int, default 0: ROS seeds with the time).
Bad input (a map without free cells, an initial pose off the map, a scan without a usable
reading, a laser frame missing from TF) is logged as a warning or error naming the cause;
the node keeps running.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Final

import numpy as np

from roverlab.core import Context, Duration, Node, QoSProfile, Time
from roverlab.core.errors import ServiceError
from roverlab.geometry import SE2, Transform3, quat_from_yaw, quat_multiply, yaw_from_quat
from roverlab.localization.amcl.amcl import Amcl, PoseEstimate
from roverlab.localization.amcl.errors import AmclError
from roverlab.localization.amcl.field import AmclMap
from roverlab.localization.amcl.params import AmclParams
from roverlab.msgs import (
    PoseArray,
    PoseWithCovarianceStamped,
    occupancy_grid_to_array,
    pose_from_xytheta,
    poses_from_xytheta,
    stamp_to_msg,
    xytheta_from_pose,
)
from roverlab.msgs import classes as mc
from roverlab.tf import (
    Buffer,
    TfMessageFilter,
    Throttle,
    TransformBroadcaster,
    TransformException,
    TransformListener,
    transform_to_msg,
)

__all__ = ["AmclNode"]

_LATCHED_2 = QoSProfile(depth=2, durability="transient_local")
_LATCHED_1 = QoSProfile(depth=1, durability="transient_local")
_SCAN_QUEUE: Final = 100  # amcl's laser subscriber and message filter queues
_MAP_RETRY_S: Final = 0.5  # amcl's "Request for map failed; trying again..." period
_LASER_CHECK_S: Final = 15.0  # amcl's check_laser_timer_
_POSE_PARAMETERS: Final = (
    "initial_pose_x",
    "initial_pose_y",
    "initial_pose_a",
    "initial_cov_xx",
    "initial_cov_yy",
    "initial_cov_aa",
)


def _strip(frame: str) -> str:
    return frame.lstrip("/")


class AmclNode(Node):
    """``amcl``: Monte Carlo localization of a laser robot on a known map, live.

    Args:
        context: the context the node joins.
        node_name: defaults to ``amcl``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (the launch file's private
            ``<param>``s), ``remappings`` of :class:`~roverlab.core.Node`.

    Attributes:
        params: the validated :class:`AmclParams` (as declared at start).
        amcl: the filter, or None until a usable map arrived.
        last_pose: the last ``amcl_pose`` message published, or None.
        scans_processed: scans handed to the filter.

    Raises:
        AmclParamsError: a parameter out of range.
        ParameterError: a parameter override that does not fit its declared type.
    """

    def __init__(self, context: Context, *, node_name: str = "amcl", **node_kwargs: Any) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        values: dict[str, Any] = {}
        for f in dataclasses.fields(AmclParams):  # odom_model_type before the alphas
            default = AmclParams.default_of(f.name, str(values.get("odom_model_type", "")))
            values[f.name] = self.declare_parameter(f.name, default).value
        self.rng = np.random.default_rng(int(self.declare_parameter("seed", 0).value))
        for key in self.unused_parameter_overrides():  # names amcl does not read: warned
            if "/" not in key and "." not in key:  # about once each, by from_ros
                values[key] = self.declare_parameter(key, None).value
        warnings: list[str] = []
        self.params = AmclParams.from_ros(values, warnings=warnings)
        for w in warnings:
            self.get_logger().warning(w)
        p = self.params
        self.global_frame = _strip(p.global_frame_id)
        self.odom_frame = _strip(p.odom_frame_id)
        self.base_frame = _strip(p.base_frame_id)
        self.amcl: Amcl | None = None
        self.last_pose: Any = None
        self.scans_processed = 0
        self._pending_initial: tuple[SE2, np.ndarray] | None = None
        self._map_to_odom: Transform3 | None = None
        self._last_odom: SE2 | None = None
        self._last_scan_frame = ""
        self._last_scan_ns: int | None = None
        self._last_cloud_ns: int | None = None
        self._cloud_waiting = False  # a cloud was due while nobody listened
        self._last_save_ns = self.get_clock().now_ns()
        self._first_map_received = False
        self._throttle = Throttle(self)
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.pose_publisher = self.create_publisher(
            PoseWithCovarianceStamped, "amcl_pose", _LATCHED_2
        )
        self.cloud_publisher = self.create_publisher(PoseArray, "particlecloud", _LATCHED_2)
        self.scan_filter = TfMessageFilter(
            self, self.tf_buffer, [self.odom_frame], _SCAN_QUEUE, self._on_scan
        )
        self.create_subscription(mc.LaserScan, "scan", self._on_scan_arrived, _SCAN_QUEUE)
        self.create_subscription(
            mc.PoseWithCovarianceStamped, "initialpose", self._on_initial_pose, 2
        )
        self._map_client: Any = None
        self._map_timer: Any = None
        if p.use_map_topic:
            self.create_subscription(mc.OccupancyGrid, "map", self._on_map_topic, _LATCHED_1)
            self.get_logger().info("Subscribed to map topic.")
        else:
            self._request_map()
        self._wire_services()
        self.create_timer(_LASER_CHECK_S, self._check_laser)

    # ------------------------------------------------------------------ services
    def _wire_services(self) -> None:
        """``global_localization``, ``request_nomotion_update`` (``std_srvs/Empty``) and
        ``set_map`` (``nav_msgs/SetMap``)."""
        self.create_service("std_srvs/srv/Empty", "global_localization", self._on_global)
        self.create_service("std_srvs/srv/Empty", "request_nomotion_update", self._on_nomotion)
        self.create_service("nav_msgs/srv/SetMap", "set_map", self._on_set_map)

    def _on_global(self, _request: Any, response: Any) -> Any:
        if self.amcl is not None:
            self.get_logger().info("Initializing with uniform distribution")
            self.amcl.global_localization()
            self.get_logger().info("Global initialisation done!")
        return response

    def _on_nomotion(self, _request: Any, response: Any) -> Any:
        if self.amcl is not None:
            self.amcl.request_nomotion_update()
        return response

    def _on_set_map(self, request: Any, response: Any) -> Any:
        response.success = self._handle_map(request.map)
        if response.success:
            self._handle_initial_pose(request.initial_pose)
        return response

    # ------------------------------------------------------------------ map
    def _request_map(self) -> None:
        self._map_client = self.create_client("nav_msgs/srv/GetMap", "static_map")
        self.get_logger().info("Requesting the map...")
        self._map_timer = self.create_timer(_MAP_RETRY_S, self._try_map_request)
        self._try_map_request()

    def _try_map_request(self) -> None:
        if self.amcl is not None or self._map_client is None:
            return
        if not self._map_client.service_is_ready():
            self._throttle.warning("map", "Request for map failed; trying again...")
            return
        request = self._map_client.srv_type.Request()
        self._map_client.call_async(request).add_done_callback(self._on_map_reply)

    def _on_map_reply(self, future: Any) -> None:
        try:
            reply = future.result()
        except ServiceError as err:
            self._throttle.warning("map", f"Request for map failed ({err}); trying again...")
            return
        if reply is None or self.amcl is not None:
            return
        if self._handle_map(reply.map) and self._map_timer is not None:
            self.destroy_timer(self._map_timer)
            self._map_timer = None

    def _on_map_topic(self, msg: Any) -> None:
        if self.params.first_map_only and self._first_map_received:
            return
        self._first_map_received = self._handle_map(msg) or self._first_map_received

    def _handle_map(self, msg: Any) -> bool:
        """Restart the filter on a new map; False (with an error) if it cannot be used."""
        info = msg.info
        log = self.get_logger()
        log.info(
            f"Received a {int(info.width)} X {int(info.height)} map @ "
            f"{float(info.resolution):.3f} m/pix"
        )
        if _strip(str(msg.header.frame_id)) != self.global_frame:
            log.warning(
                f"Frame_id of map received:'{msg.header.frame_id}' doesn't match "
                f"global_frame_id:'{self.global_frame}'. This could cause issues with "
                "reading published topics"
            )
        try:
            data = occupancy_grid_to_array(msg)
            origin = info.origin.position
            amcl_map = AmclMap(
                data=data,
                resolution_m=float(info.resolution),
                origin_xy=(float(origin.x), float(origin.y)),
                max_dist_m=self.params.laser_likelihood_max_dist,
            )
        except (AmclError, ValueError) as err:
            log.error(f"map rejected: {err}")
            return False
        params = self._current_params()
        try:
            self.amcl = Amcl(params, amcl_map, rng=self.rng)
        except AmclError as err:
            log.error(
                f"{err} (initial_pose_x/y); particles spread over the free cells instead "
                "(global localization)"
            )
            self.amcl = Amcl(params, amcl_map, rng=self.rng, global_start=True)
        self._map_to_odom = None
        if self._pending_initial is not None:
            self._apply_initial(*self._pending_initial)
            self._pending_initial = None
        return True

    def _current_params(self) -> AmclParams:
        """The parameters with the initial pose as now set (save_pose_rate writes it)."""
        values: dict[str, Any] = {}
        for name in _POSE_PARAMETERS:
            value = float(self.get_parameter(name).value)
            if math.isnan(value):
                self.get_logger().warning(f"ignoring NAN in {name}")
                continue
            values[name] = value
        return dataclasses.replace(self.params, **values)

    # ------------------------------------------------------------------ initial pose
    def _on_initial_pose(self, msg: Any) -> None:
        self._handle_initial_pose(msg)

    def _handle_initial_pose(self, msg: Any) -> None:
        frame = _strip(str(msg.header.frame_id))
        log = self.get_logger()
        if not frame:
            log.warning("Received initial pose with empty frame_id.  You should always supply a "
                        "frame_id.")  # fmt: skip
        elif frame != self.global_frame:
            log.warning(
                f'Ignoring initial pose in frame "{frame}"; initial poses must be in the '
                f'global frame, "{self.global_frame}"'
            )
            return
        x, y, a = xytheta_from_pose(msg.pose.pose)
        pose = SE2(x, y, a)
        # a pose estimate from the past: add the odometry's motion since its stamp
        try:
            moved, _ = self.tf_buffer.lookup_transform_full(
                self.base_frame,
                Time.from_msg(msg.header.stamp),
                self.base_frame,
                self.get_clock().now(),
                self.odom_frame,
            )
            pose = pose * moved.to_se2()
        except TransformException:
            pass  # no odometry yet, or a stamp outside the buffer: use the pose as given
        c = np.asarray(msg.pose.covariance, dtype=np.float64).reshape(6, 6)
        cov = np.zeros((3, 3))
        cov[:2, :2] = c[:2, :2]
        cov[2, 2] = c[5, 5]
        log.info(f"Setting pose ({self.get_clock().now().nanoseconds / 1e9:.6f}): "
                 f"{pose.x:.3f} {pose.y:.3f} {pose.theta:.3f}")  # fmt: skip
        if self.amcl is None:
            self._pending_initial = (pose, cov)
            return
        self._apply_initial(pose, cov)

    def _apply_initial(self, pose: SE2, cov: np.ndarray) -> None:
        assert self.amcl is not None
        try:
            self.amcl.set_initial_pose(pose, cov)
        except AmclError as err:
            self.get_logger().warning(f"initial pose ignored: {err}")

    # ------------------------------------------------------------------ scans
    def _on_scan_arrived(self, scan: Any) -> None:
        self._last_scan_frame = _strip(str(scan.header.frame_id))
        self.scan_filter.add(scan)

    def _check_laser(self) -> None:
        now = self.get_clock().now_ns()
        last = self._last_scan_ns
        if last is not None and now - last <= round(_LASER_CHECK_S * 1e9):
            return
        idle = (now - last) / 1e9 if last is not None else _LASER_CHECK_S
        text = (
            f"No laser scan received (and thus no pose updates have been published) for "
            f"{idle:.1f} seconds. Verify that data is being published on the "
            f"{self.resolve_topic_name('scan')} topic."
        )
        if self.scan_filter.waiting or self.scan_filter.dropped:
            text = (
                f"No laser scan processed for {idle:.1f} seconds: scans in frame "
                f"'{self._last_scan_frame}' wait for the transform '{self.odom_frame}' <- "
                f"'{self._last_scan_frame}' (is that frame published on TF?)"
            )
        self.get_logger().warning(text)

    def _laser_inputs(self, scan: Any, stamp: Time) -> tuple[SE2, np.ndarray, tuple[float, float]]:
        """Odometry pose at the scan, beam bearings in the base frame (amcl's way: the yaw
        of the first beam and of the increment turned into the base frame), laser x, y."""
        frame = _strip(str(scan.header.frame_id))
        base_laser, _ = self.tf_buffer.lookup_transform(self.base_frame, frame, stamp)
        odom_base, _ = self.tf_buffer.lookup_transform(self.odom_frame, self.base_frame, stamp)
        q = base_laser.rotation
        a0 = float(scan.angle_min)
        yaw0 = yaw_from_quat(quat_multiply(q, quat_from_yaw(a0)))
        yaw1 = yaw_from_quat(quat_multiply(q, quat_from_yaw(a0 + float(scan.angle_increment))))
        inc = math.fmod(yaw1 - yaw0 + 5.0 * math.pi, 2.0 * math.pi) - math.pi
        n = len(scan.ranges)
        bearings = yaw0 + inc * np.arange(n, dtype=np.float64)
        tx, ty, _ = base_laser.translation
        return odom_base.to_se2(), bearings, (float(tx), float(ty))

    def _on_scan(self, scan: Any) -> None:
        self._last_scan_ns = self.get_clock().now_ns()
        if self.amcl is None:
            return
        stamp = Time.from_msg(scan.header.stamp)
        try:
            odom, bearings, laser_xy = self._laser_inputs(scan, stamp)
        except TransformException as err:
            self._throttle.warning("odom", f"Failed to compute odom pose, skipping scan ({err})")
            return
        try:
            result = self.amcl.process_scan(
                odom_pose=odom,
                ranges=np.asarray(scan.ranges, dtype=np.float64),
                bearings=bearings,
                laser_xy=laser_xy,
                range_min=float(scan.range_min),
                range_max=float(scan.range_max),
            )
        except AmclError as err:
            self._throttle.warning("input", f"scan dropped: {err}")
            return
        self.scans_processed += 1
        self._last_odom = odom
        if result.note:
            self._throttle.warning("note", f"scan in frame '{scan.header.frame_id}': "
                                   f"{result.note}")  # fmt: skip
        if result.updated:
            self._publish_cloud()
        if result.estimate is not None:
            self._publish_pose(result.estimate, scan.header.stamp)
            self._map_to_odom = Transform3.from_se2(result.estimate.pose * ~odom)
            self._send_transform(stamp)
        elif self._map_to_odom is not None:
            self._send_transform(stamp)
            self._maybe_save_pose()

    # ------------------------------------------------------------------ outputs
    def _publish_cloud(self) -> None:
        assert self.amcl is not None
        rate = self.params.gui_publish_rate
        now = self.get_clock().now_ns()
        last = self._last_cloud_ns
        if rate > 0.0 and last is not None and now - last < round(1e9 / rate):
            return
        self._last_cloud_ns = now
        if not self.cloud_publisher.has_listeners:
            # a PoseArray of every particle is costly: build it only for a reader; one who
            # subscribes later gets the current set at once (the topic is latched)
            if not self._cloud_waiting:
                self._cloud_waiting = True
                self.cloud_publisher.when_listened(self._on_cloud_listener)
            return
        self._send_cloud()

    def _on_cloud_listener(self) -> None:
        # the subscriber may be made on another thread: read the particles on the executor's
        self.context.executor.call_soon_threadsafe(self._cloud_for_listener)

    def _cloud_for_listener(self) -> None:
        self._cloud_waiting = False
        if self.amcl is not None:
            self._send_cloud()

    def _send_cloud(self) -> None:
        assert self.amcl is not None
        msg = PoseArray(
            header={"frame_id": self.global_frame, "stamp": stamp_to_msg(self.get_clock().now())},
            poses=poses_from_xytheta(self.amcl.pf.poses),
        )
        self.cloud_publisher.publish(msg)

    def _publish_pose(self, estimate: PoseEstimate, stamp: Any) -> None:
        e = estimate.pose
        cov = np.zeros(36)
        cov[0], cov[1] = estimate.covariance[0, 0], estimate.covariance[0, 1]
        cov[6], cov[7] = estimate.covariance[1, 0], estimate.covariance[1, 1]
        cov[35] = estimate.covariance[2, 2]
        msg = PoseWithCovarianceStamped(
            header={"frame_id": self.global_frame, "stamp": stamp},
            pose={"pose": pose_from_xytheta(e.x, e.y, e.theta), "covariance": cov},
        )
        self.pose_publisher.publish(msg)
        self.last_pose = msg
        self._warn_spread(estimate.covariance)

    def _warn_spread(self, cov: np.ndarray) -> None:
        """amcl's standard deviation diagnostic: "Too large" beyond ``std_warn_level_*``
        (a throttled warning here; roverlab publishes no ``/diagnostics``)."""
        p = self.params
        std = np.sqrt(np.maximum(np.diag(cov)[:3], 0.0))
        levels = (p.std_warn_level_x, p.std_warn_level_y, p.std_warn_level_yaw)
        over = [
            f"{name} {s:.3f} > std_warn_level_{name} {lvl:g}"
            for name, s, lvl in zip(("x", "y", "yaw"), std, levels, strict=True)
            if s > lvl
        ]
        if over:
            self._throttle.warning("std", "Standard deviation too large: " + ", ".join(over))

    def _send_transform(self, stamp: Time) -> None:
        if not self.params.tf_broadcast or self._map_to_odom is None:
            return
        expiry = stamp + Duration.from_seconds(self.params.transform_tolerance)
        self.tf_broadcaster.send_transform(
            transform_to_msg(self.global_frame, self.odom_frame, expiry, self._map_to_odom)
        )

    def _maybe_save_pose(self) -> None:
        """Write the pose to ``initial_pose_*`` / ``initial_cov_*`` (amcl's
        ``savePoseToServer``) every ``1 / save_pose_rate`` seconds."""
        rate = self.params.save_pose_rate
        now = self.get_clock().now_ns()
        if rate <= 0.0 or now - self._last_save_ns < round(1e9 / rate):
            return
        if self._map_to_odom is None or self._last_odom is None or self.last_pose is None:
            return
        self._last_save_ns = now
        pose = self._map_to_odom.to_se2() * self._last_odom
        c = self.last_pose.pose.covariance
        for name, value in (
            ("initial_pose_x", pose.x), ("initial_pose_y", pose.y),
            ("initial_pose_a", pose.theta), ("initial_cov_xx", c[0]),
            ("initial_cov_yy", c[7]), ("initial_cov_aa", c[35]),
        ):  # fmt: skip
            self.set_parameter(name, float(value))

    @property
    def map_to_odom(self) -> Transform3 | None:
        """The ``map -> odom`` transform being broadcast, or None before the first pose."""
        return self._map_to_odom
