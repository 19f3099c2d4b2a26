"""The ``slam_gmapping`` node: a thin wrapper of :class:`~roverlab.slam.gmapping.GMapping`.

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

Parameters: every field of :class:`~roverlab.slam.gmapping.GMappingParams` under its ROS
name and default (``maxUrange``, ``particles``, ``delta``, ``linearUpdate``, ...; ``maxRange``
and ``tf_delay`` are unset by default, as in ROS), plus roverlab's ``seed`` (int, default 0:
ROS seeds the filter with the wall time, which cannot be reproduced).

The TF message filter is :class:`roverlab.tf.TfMessageFilter`; the laser's beams in the
base frame come from :func:`roverlab.slam.laser.laser_geometry`.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from roverlab.core import Context, Duration
from roverlab.geometry import Transform3
from roverlab.msgs import Float64
from roverlab.msgs import classes as mc
from roverlab.slam.gmapping.errors import GMappingInputError
from roverlab.slam.gmapping.params import GMappingParams
from roverlab.slam.gmapping.slam import GMapping
from roverlab.slam.node_common import SlamNode
from roverlab.tf import (
    TfMessageFilter,
    transform_to_msg,
)

__all__ = ["SlamGMapping"]

# tf's MessageFilter queue of slam_gmapping (``new tf::MessageFilter(..., odom_frame_, 5)``)
_FILTER_QUEUE = 5


class SlamGMapping(SlamNode):
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
        self.scans_processed = 0
        self.scans_received = 0
        self._last_map_ns: int | None = None
        self._initialised = False
        self._setup_map_io()
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
        inputs = self._scan_inputs(scan, p.base_frame, p.odom_frame)
        if inputs is None:
            return
        stamp, laser, _ = inputs
        if not self._initialised:
            self._initialised = True
            if laser.upside_down:
                self.get_logger().info("Laser is mounted upside down.")
            else:
                self.get_logger().info("Laser is mounted upwards.")
        ok, updated = self._process_scan(self.slam.process, scan, inputs, GMappingInputError)
        if not (ok and updated):
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
        self.entropy_publisher.publish(Float64(data=self.entropy()))
        self._publish_map_msg(msg)

    def entropy(self) -> float:
        """Entropy of the normalised particle weights (slam_gmapping's ``~entropy``)."""
        w = self.slam.weights()
        w = w[w > 0.0]
        return float(-np.sum(w * np.log(w)))

    # ------------------------------------------------------------------ TF
    def _publish_transform(self) -> None:
        p = self.params
        stamp = self.get_clock().now() + Duration.from_seconds(self._tf_delay)
        self.tf_broadcaster.send_transform(
            transform_to_msg(p.map_frame, p.odom_frame, stamp, self._map_to_odom)
        )
