"""What the SLAM nodes share: a scan's TF inputs and the dynamic_map service."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from roverlab.core import Node, Service, Time
from roverlab.geometry import SE2
from roverlab.slam.laser import LaserGeometry, laser_geometry
from roverlab.tf import Buffer

__all__ = ["advertise_map_service", "scan_inputs"]


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
