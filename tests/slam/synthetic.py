"""Synthetic scans for the SLAM tests: ranges cast in a scene, wrapped as log records."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.slam.data import ScanRecord


def scan_record(
    timestamp: float,
    ranges: ArrayLike,
    beams: NDArray[np.float64],
    odom_pose: SE2,
    *,
    range_min: float,
    range_max: float,
    laser_offset: SE2 | None = None,
) -> ScanRecord:
    """A log record of ``ranges`` (float32) along the evenly spaced ``beams`` (rad, laser
    frame), taken at ``odom_pose`` by a laser at ``laser_offset`` (default: the robot's
    origin)."""
    return ScanRecord(
        timestamp=timestamp,
        ranges=np.asarray(ranges).astype(np.float32),
        angle_min=float(beams[0]),
        angle_increment=float(beams[1] - beams[0]),
        range_min=range_min,
        range_max=range_max,
        odom_pose=odom_pose,
        laser_offset=SE2() if laser_offset is None else laser_offset,
    )
