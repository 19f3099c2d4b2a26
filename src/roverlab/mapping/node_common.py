"""What the SLAM nodes share: a scan's TF inputs (node side: uses the TF buffer)."""

from __future__ import annotations

from typing import Any

from roverlab.core import Time
from roverlab.geometry import SE2
from roverlab.mapping.laser import LaserGeometry, laser_geometry
from roverlab.tf import Buffer

__all__ = ["scan_inputs"]


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
