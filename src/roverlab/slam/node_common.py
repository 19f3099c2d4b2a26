"""What the SLAM nodes share: TF in and out, the latched map topics, the dynamic_map service
and a scan's TF inputs (:class:`SlamNode`)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from roverlab.core import Node, QoSProfile, Service, Time
from roverlab.geometry import SE2, Transform3
from roverlab.msgs import MapMetaData, OccupancyGrid, array_to_occupancy_grid
from roverlab.slam.laser import LaserGeometry, laser_geometry
from roverlab.tf import (
    Buffer,
    Throttle,
    TransformBroadcaster,
    TransformException,
    TransformListener,
)

__all__ = ["LATCHED", "SlamNode", "advertise_map_service", "scan_inputs"]

#: The QoS of ``map`` and ``map_metadata`` (latched, as the ROS nodes publish them).
LATCHED = QoSProfile(depth=1, durability="transient_local")


def advertise_map_service(node: Node, current_map: Callable[[], Any]) -> Service:
    """The ``dynamic_map`` service (``nav_msgs/GetMap``) of a SLAM node: the last map it
    published. Before the first map the call fails, as gmapping's and karto's do."""

    def on_request(_request: Any, response: Any) -> Any:
        msg = current_map()
        if msg is None:
            raise RuntimeError("no map has been built yet")
        response.map = msg
        return response

    return node.create_service("nav_msgs/GetMap", "dynamic_map", on_request)


def scan_inputs(
    buffer: Buffer, scan: Any, base_frame: str, odom_frame: str
) -> tuple[Time, LaserGeometry, SE2]:
    """A scan's stamp, its beams in the base frame and the odometry pose at its stamp.

    Raises:
        TransformException: ``base_frame <- laser`` or ``odom_frame <- base_frame`` is not
            known at the scan's stamp.
    """
    stamp = Time.from_msg(scan.header.stamp)
    frame = str(scan.header.frame_id).lstrip("/")
    base_laser, _ = buffer.lookup_transform(base_frame, frame, stamp)
    odom_base, _ = buffer.lookup_transform(odom_frame, base_frame, stamp)
    return stamp, laser_geometry(scan, base_laser), odom_base.to_se2()


class SlamNode(Node):
    """Base of the live SLAM nodes: :meth:`_setup_map_io` makes what they all have (a TF
    buffer, listener and broadcaster, the latched ``map`` and ``map_metadata`` topics, the
    ``dynamic_map`` service); :meth:`_publish_map_msg` publishes a map on both topics."""

    def _setup_map_io(self, *, map_service: bool = True) -> None:
        self.map_msg: Any = None
        self._map_to_odom = Transform3()
        self._throttle = Throttle(self)
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.map_publisher = self.create_publisher(OccupancyGrid, "map", LATCHED)
        if map_service:
            self.map_service = advertise_map_service(self, lambda: self.map_msg)
        self.metadata_publisher = self.create_publisher(MapMetaData, "map_metadata", LATCHED)

    @property
    def map_to_odom(self) -> Transform3:
        """The ``map -> odom`` transform being broadcast."""
        return self._map_to_odom

    def _publish_map_msg(self, msg: Any) -> None:
        """Keep ``msg`` as the current map (for ``dynamic_map``) and publish it and its info."""
        self.map_msg = msg
        self.map_publisher.publish(msg)
        self.metadata_publisher.publish(msg.info)

    def _grid_msg(self, grid: Any, frame_id: str) -> Any:
        """A ``nav_msgs/OccupancyGrid`` of ``grid`` (``data``, ``resolution``, ``origin``)
        stamped now."""
        return array_to_occupancy_grid(
            grid.data,
            resolution=grid.resolution,
            origin=(grid.origin[0], grid.origin[1], 0.0),
            frame_id=frame_id,
            stamp=self.get_clock().now(),
        )

    def _scan_inputs(
        self, scan: Any, base_frame: str, odom_frame: str
    ) -> tuple[Time, LaserGeometry, SE2] | None:
        """:func:`scan_inputs`, or None (with a throttled warning) when TF lacks them."""
        try:
            return scan_inputs(self.tf_buffer, scan, base_frame, odom_frame)
        except TransformException as err:
            self._throttle.warning("odom", f"Failed to compute odom pose, skipping scan ({err})")
            return None

    def _process_scan(
        self,
        process: Callable[..., Any],
        scan: Any,
        inputs: tuple[Time, LaserGeometry, SE2],
        input_error: type[Exception],
    ) -> tuple[bool, Any]:
        """``process(ranges, angles, odom, t, range_min=, range_max=, laser_offset=)`` on a
        scan: ``(True, its result)``, or ``(False, None)`` with a throttled warning when it
        raises ``input_error``."""
        stamp, laser, odom = inputs
        try:
            return True, process(
                np.asarray(scan.ranges, dtype=np.float64),
                laser.angles,
                odom,
                stamp.nanoseconds / 1e9,
                range_min=float(scan.range_min),
                range_max=float(scan.range_max),
                laser_offset=laser.offset,
            )
        except input_error as err:
            self._throttle.warning("input", f"scan dropped: {err}")
            return False, None
