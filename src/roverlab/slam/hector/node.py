"""The ``hector_mapping`` node: a thin wrapper of :class:`~roverlab.slam.hector.HectorSLAM`.

What ROS 1's ``hector_mapping/hector_mapping`` (``HectorMappingRos``) does, with its names:

* subscribes ``scan_topic`` (default ``scan``, queue ``scan_subscriber_queue_size``); with
  ``use_tf_scan_transformation`` (default) a scan waits up to 0.5 s for
  ``base_frame <- scan frame`` at its stamp and is dropped with a message if it never comes;
  without it the laser sits at the base frame's origin;
* ``use_tf_pose_start_estimate``: the match starts from ``map -> base_frame`` through TF
  (the last ``map -> odom`` times ``odom -> base_frame`` at the stamp), else from the last
  estimate;
* publishes per scan ``slam_out_pose`` (``geometry_msgs/PoseStamped``) and
  ``pose_update_topic`` (default ``poseupdate``, ``PoseWithCovarianceStamped``), both in
  frame ``map`` as hector stamps them, and ``scanmatch_odom`` (``nav_msgs/Odometry``) with
  ``pub_odometry``;
* ``pub_map_odom_transform`` (default true): broadcasts ``map_frame -> odom_frame`` =
  pose * (``odom_frame -> base_frame`` at the stamp)^-1 at the scan's stamp; without that
  transform (e.g. ``odom_frame == base_frame``, hector's setup without odometry) the
  identity is used, so ``map -> base_frame`` itself is broadcast;
* ``pub_map_scanmatch_transform`` (default true): ``map_frame ->
  tf_map_scanmatch_transform_frame_name`` (``scanmatcher_frame``) = the pose;
* publishes ``map`` and ``map_metadata`` (latched) every ``map_pub_period`` seconds when the
  map changed (hector publishes the finest level only);
* ``sys_msg_topic`` (default ``syscommand``, ``std_msgs/String``): ``reset`` clears the map
  and the pose;
* ``advertise_map_service`` (default true): the ``dynamic_map`` service
  (``nav_msgs/GetMap``) answers with the last published map.

Parameters: the algorithm's (:class:`~roverlab.slam.hector.HectorParams`: ROS names and
defaults, plus roverlab's matcher options) and the node's above. ``pub_drawings``,
``pub_debug_output`` and ``output_timing`` are not implemented: a launch file that sets
them gets a warning.

One deviation: the ``poseupdate`` covariance is the inverse of the matcher's Hessian (m,
rad), a covariance; hector itself copies the Hessian there.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from roverlab.core import Context, Time
from roverlab.geometry import SE2, Transform3
from roverlab.msgs import (
    Odometry,
    PoseStamped,
    PoseWithCovarianceStamped,
    pose_from_xytheta,
)
from roverlab.msgs import classes as mc
from roverlab.slam.hector.errors import HectorInputError, OutOfMapError
from roverlab.slam.hector.params import HectorParams
from roverlab.slam.hector.slam import HectorSLAM
from roverlab.slam.laser import laser_geometry
from roverlab.slam.node_common import SlamNode
from roverlab.tf import (
    TfMessageFilter,
    TransformException,
    transform_to_msg,
)

__all__ = ["NODE_DEFAULTS", "HectorMapping"]

# hector waits this long (s) for the laser's transform (``waitForTransform(..., 0.5)``)
_TF_WAIT_S = 0.5

#: The node-level parameters this node implements, with hector_mapping's defaults.
NODE_DEFAULTS: dict[str, Any] = {
    "pub_map_odom_transform": True,
    "pub_map_scanmatch_transform": True,
    "pub_odometry": False,
    "scan_subscriber_queue_size": 5,
    "scan_topic": "scan",
    "sys_msg_topic": "syscommand",
    "pose_update_topic": "poseupdate",
    "use_tf_scan_transformation": True,
    "use_tf_pose_start_estimate": False,
    "base_frame": "base_link",
    "map_frame": "map",
    "odom_frame": "odom",
    "tf_map_scanmatch_transform_frame_name": "scanmatcher_frame",
    "map_pub_period": 2.0,
    "advertise_map_service": True,
}


class HectorMapping(SlamNode):
    """``hector_mapping``: scan-matching SLAM on a multi-resolution grid, live.

    Args:
        context: the context the node joins.
        node_name: defaults to ``hector_mapping``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (the launch file's private
            ``<param>``s), ``remappings`` of :class:`~roverlab.core.Node`.

    Attributes:
        params: the validated :class:`HectorParams`.
        slam: the algorithm (:class:`HectorSLAM`); each scan sets its laser pose and height.
        pose: the last robot pose in the map frame.
        scans_processed: scans matched so far.
        map_msg: the last ``nav_msgs/OccupancyGrid`` published, or None.

    Raises:
        HectorParamsError: an algorithm parameter of the wrong type or out of range.
        ParameterError: a parameter override that does not fit its declared type.
    """

    def __init__(
        self, context: Context, *, node_name: str = "hector_mapping", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        algo: dict[str, Any] = {}
        for f in dataclasses.fields(HectorParams):
            algo[f.name] = self.declare_parameter(f.name, f.default).value
        node = {k: self.declare_parameter(k, v).value for k, v in NODE_DEFAULTS.items()}
        if float(node["map_pub_period"]) <= 0.0:
            raise ValueError(f"map_pub_period must be > 0, got {node['map_pub_period']}")
        if int(node["scan_subscriber_queue_size"]) < 1:
            raise ValueError("scan_subscriber_queue_size must be >= 1")
        self.use_tf_pose_start_estimate = bool(node["use_tf_pose_start_estimate"])
        if self.use_tf_pose_start_estimate:
            # map->base through TF = last map->odom * odom->base(t): the last estimate moved
            # by the odometry since, which is what the algorithm's use_odometry does
            algo["use_odometry"] = True
        self.params = HectorParams.from_ros(algo)
        self.base_frame = str(node["base_frame"]).lstrip("/")
        self.map_frame = str(node["map_frame"]).lstrip("/")
        self.odom_frame = str(node["odom_frame"]).lstrip("/")
        self.scanmatch_frame = str(node["tf_map_scanmatch_transform_frame_name"]).lstrip("/")
        self.pub_map_odom_transform = bool(node["pub_map_odom_transform"])
        self.pub_map_scanmatch_transform = bool(node["pub_map_scanmatch_transform"])
        self.use_tf_scan_transformation = bool(node["use_tf_scan_transformation"])
        self.slam = HectorSLAM(self.params)
        self.pose = SE2()
        self.scans_processed = 0
        self._published_updates = -1
        self._failed = False
        self._setup_map_io(map_service=bool(node["advertise_map_service"]))
        self.pose_publisher = self.create_publisher(PoseStamped, "slam_out_pose", 1)
        self.pose_update_publisher = self.create_publisher(
            PoseWithCovarianceStamped, str(node["pose_update_topic"]), 1
        )
        self.odometry_publisher = (
            self.create_publisher(Odometry, "scanmatch_odom", 50) if node["pub_odometry"] else None
        )
        queue = int(node["scan_subscriber_queue_size"])
        if self.use_tf_scan_transformation:
            self.scan_filter: TfMessageFilter | None = TfMessageFilter(
                self,
                self.tf_buffer,
                [self.base_frame],
                queue,
                self._on_scan,
                timeout_s=_TF_WAIT_S,
                optional_frames=self._optional_frames(),
                on_timeout=self._on_scan_timeout,
            )
            self.create_subscription(
                mc.LaserScan, str(node["scan_topic"]), self.scan_filter.add, queue
            )
        else:
            self.scan_filter = None
            self.create_subscription(mc.LaserScan, str(node["scan_topic"]), self._on_scan, queue)
        self.create_subscription(mc.String, str(node["sys_msg_topic"]), self._on_syscommand, 2)
        self.create_timer(float(node["map_pub_period"]), self.publish_map)
        # hector latches the (empty) map's metadata at start-up
        self.metadata_publisher.publish(self._grid_msg(self.slam.occupancy(0), self.map_frame).info)
        log = self.get_logger()
        log.info(f"HectorSM base_frame: {self.base_frame}")
        log.info(f"HectorSM map_frame: {self.map_frame}")
        log.info(f"HectorSM odom_frame: {self.odom_frame}")
        log.info(f"HectorSM scan_topic: {self.resolve_topic_name(str(node['scan_topic']))}")

    def _optional_frames(self) -> list[str]:
        """The odometry frame, when a scan needs ``odom -> base`` (hector waits 0.5 s)."""
        needs_odom = self.pub_map_odom_transform or self.params.use_odometry
        return [self.odom_frame] if needs_odom and self.odom_frame != self.base_frame else []

    # ------------------------------------------------------------------ scans
    def _on_scan(self, scan: Any) -> None:
        if self._failed:
            return
        stamp = Time.from_msg(scan.header.stamp)
        frame = str(scan.header.frame_id).lstrip("/")
        ranges = np.asarray(scan.ranges, dtype=np.float64)
        if self.use_tf_scan_transformation:
            try:
                base_laser, _ = self.tf_buffer.lookup_transform(self.base_frame, frame, stamp)
            except TransformException:
                self._on_scan_timeout(scan)
                return
        else:
            base_laser = Transform3()
        laser = laser_geometry(scan, base_laser)
        odom_base = self._odom_base(stamp)
        self.slam.laser_z_m = laser.z_m
        odom_pose = None
        if self.params.use_odometry or self.params.map_with_known_poses:
            if odom_base is None:
                self._throttle.warning(
                    "odom",
                    f"no transform {self.odom_frame} -> {self.base_frame} at the scan's stamp: "
                    "scan skipped",
                )
                return
            odom_pose = odom_base.to_se2()
        try:
            self.pose = self.slam.process(
                ranges,
                laser.angles,
                odom_pose,
                range_min=float(scan.range_min),
                range_max=float(scan.range_max),
                laser_offset=laser.offset,
            )
        except HectorInputError as err:
            self._throttle.warning("input", f"scan dropped: {err}")
            return
        except OutOfMapError as err:
            self._failed = True
            self.get_logger().error(f"{err}; hector_mapping stops (reset it on syscommand)")
            return
        self.scans_processed += 1
        self._publish_pose(scan, stamp, odom_base)

    def _on_scan_timeout(self, scan: Any) -> None:
        frame = str(scan.header.frame_id).lstrip("/")
        self.get_logger().info(
            f"lookupTransform {self.base_frame} to {frame} timed out. Could not transform "
            "laser scan into base_frame."
        )

    def _odom_base(self, stamp: Time) -> Transform3 | None:
        if self.odom_frame == self.base_frame:
            return Transform3()
        try:
            tf, _ = self.tf_buffer.lookup_transform(self.odom_frame, self.base_frame, stamp)
        except TransformException:
            return None
        return tf

    def _publish_pose(self, scan: Any, stamp: Time, odom_base: Transform3 | None) -> None:
        x, y, th = self.pose.x, self.pose.y, self.pose.theta
        header = {"header_stamp": scan.header.stamp, "header_frame_id": "map"}
        pose = pose_from_xytheta(x, y, th)
        self.pose_publisher.publish(PoseStamped(**header, pose=pose))
        cov = np.zeros((6, 6))
        cov[np.ix_([0, 1, 5], [0, 1, 5])] = self.covariance()
        with_cov = PoseWithCovarianceStamped(
            **header, pose=mc.PoseWithCovariance(pose, cov.reshape(-1))
        )
        self.pose_update_publisher.publish(with_cov)
        if self.odometry_publisher is not None:
            self.odometry_publisher.publish(Odometry(**header, pose=with_cov.pose))
        map_base = Transform3.from_se2(self.pose)
        if self.pub_map_odom_transform:
            if odom_base is None:
                self._throttle.warning(
                    "map_odom",
                    f"Transform failed during publishing of map_odom transform: no "
                    f"{self.odom_frame} -> {self.base_frame} at {stamp.seconds:.3f} s",
                )
                odom_base = Transform3()
            self._map_to_odom = map_base * ~odom_base
            self.tf_broadcaster.send_transform(
                transform_to_msg(self.map_frame, self.odom_frame, stamp, self._map_to_odom)
            )
        if self.pub_map_scanmatch_transform:
            self.tf_broadcaster.send_transform(
                transform_to_msg(self.map_frame, self.scanmatch_frame, stamp, map_base)
            )

    def covariance(self) -> np.ndarray:
        """(3, 3) covariance of the last match (x, y, yaw): the inverse of its Hessian."""
        h = self.slam.last_hessian
        if not np.all(np.isfinite(h)) or not np.any(h):
            return np.zeros((3, 3))
        return np.asarray(np.linalg.pinv(h), dtype=np.float64)

    # ------------------------------------------------------------------ map
    def publish_map(self) -> None:
        """Publish ``map`` and ``map_metadata`` if the map changed since the last time."""
        if self.slam.map_updates == self._published_updates:
            return
        self._published_updates = self.slam.map_updates
        self._publish_map_msg(self._grid_msg(self.slam.occupancy(0), self.map_frame))

    def _on_syscommand(self, msg: Any) -> None:
        text = str(msg.data)
        self.get_logger().info(f"HectorSM sysMsgCallback, msg contents: {text}")
        if text == "reset":
            self.get_logger().info("HectorSM reset")
            self.slam.reset()
            self.pose = SE2()
            self._failed = False
            self._published_updates = -1
