"""Where a planar laser's beams point on the robot: shared by the SLAM nodes."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2, Transform3, quat_rotate
from roverlab.msgs import scan_angles

__all__ = ["LaserGeometry", "beam_endpoints", "laser_geometry"]


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


def beam_endpoints(
    ranges: NDArray[np.float64], angles: NDArray[np.float64], laser_offset: SE2
) -> NDArray[np.float64]:
    """``(N, 2)`` end points in the robot frame of beams of ``ranges`` at ``angles`` (laser
    frame) from a laser at ``laser_offset``."""
    ang = angles + laser_offset.theta
    return np.stack(
        [laser_offset.x + ranges * np.cos(ang), laser_offset.y + ranges * np.sin(ang)], axis=1
    )
