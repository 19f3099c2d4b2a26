"""Hector's side of the degeneracy check: the map values under a scan's endpoints.

:func:`roverlab.slam.degeneracy.scan_constraint` tells from a scan's surface normals along
which direction it cannot fix the robot; hector counts only the endpoints on surfaces its map
already holds (:func:`map_values` above the occupied threshold).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.hector.matcher import interpolate

__all__ = ["map_values"]


def map_values(
    prob: NDArray[np.float32],
    inv_res: float,
    center: tuple[float, float],
    pose: NDArray[np.float64],
    points: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The map value ``M`` under each endpoint (N, 2, robot frame) at ``pose``; 0.5
    (unknown) outside the map.

    Args:
        prob: (size, size) map values of the finest level.
        inv_res: its cells per metre.
        center: map coordinates of the world origin.
        pose: (3,) robot pose in the map frame.
        points: (N, 2) endpoints in the robot frame (m).
    """
    c, s = math.cos(pose[2]), math.sin(pose[2])
    wx = pose[0] + c * points[:, 0] - s * points[:, 1]
    wy = pose[1] + s * points[:, 0] + c * points[:, 1]
    coords = np.column_stack((wx * inv_res + center[0], wy * inv_res + center[1]))
    inside = (coords >= 0).all(axis=1) & (coords < prob.shape[0] - 1).all(axis=1)
    return np.where(inside, interpolate(prob, coords)[:, 0], 0.5)
