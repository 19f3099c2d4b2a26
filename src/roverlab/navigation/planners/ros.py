"""Planner results as ROS messages: the plan (``nav_msgs/Path``) and the potentials
(navfn's ``PointCloud2``, global_planner's ``OccupancyGrid``)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.msgs import (
    Path,
    array_to_occupancy_grid,
    poses_from_xytheta,
    xytheta_from_pose,
    xyz_to_pointcloud2,
)
from roverlab.msgs import classes as mc
from roverlab.msgs.convert import Stamp, stamp_to_msg
from roverlab.navigation.planners.navfn_kernels import POT_HIGH

__all__ = ["path_from_msg", "path_to_msg", "potential_to_grid", "potential_to_pointcloud"]


def path_to_msg(path: ArrayLike, frame_id: str, stamp: Stamp = None) -> Any:
    """An ``(N, 3)`` ``x, y, yaw`` path as a ``nav_msgs/Path`` (every pose stamped alike)."""
    t = stamp_to_msg(stamp)
    stamped, header = mc.PoseStamped, mc.Header
    poses = [stamped(header(t, frame_id), p) for p in poses_from_xytheta(path)]
    return Path(header={"stamp": t, "frame_id": frame_id}, poses=poses)


def path_from_msg(msg: Any) -> NDArray[np.float64]:
    """The ``(N, 3)`` ``x, y, yaw`` rows of a ``nav_msgs/Path``."""
    rows = [xytheta_from_pose(p.pose) for p in msg.poses]
    return np.asarray(rows, dtype=np.float64).reshape(-1, 3)


def potential_to_pointcloud(
    potential: NDArray[np.float32],
    origin_xy: tuple[float, float],
    resolution: float,
    start_cell: tuple[int, int] | None,
    frame_id: str,
    stamp: Stamp = None,
) -> Any:
    """navfn's ``visualize_potential`` cloud: a point per reached cell at its centre, ``z`` the
    potential scaled to 20 at the start cell (as NavfnROS; unscaled without a start)."""
    ys, xs = np.nonzero(potential < 1e7)
    p = potential[ys, xs].astype(np.float64)
    scale = 1.0
    if start_cell is not None:
        ref = float(potential[start_cell[1], start_cell[0]])
        if 0 < ref < POT_HIGH:
            scale = 20.0 / ref
    pts = np.column_stack(
        [
            origin_xy[0] + (xs + 0.5) * resolution,
            origin_xy[1] + (ys + 0.5) * resolution,
            p * scale,
        ]
    )
    return xyz_to_pointcloud2(pts, frame_id, stamp)


def potential_to_grid(
    potential: NDArray[np.float32],
    origin_xy: tuple[float, float],
    resolution: float,
    frame_id: str,
    stamp: Stamp = None,
    publish_scale: float = 100.0,
) -> Any:
    """global_planner's ``publish_potential`` grid: reached cells scaled to
    ``0..publish_scale`` by the largest reached potential, -1 elsewhere."""
    reached = potential < POT_HIGH
    top = float(potential[reached].max()) if reached.any() else 0.0
    out = np.full(potential.shape, -1, dtype=np.int8)
    if top > 0:
        out[reached] = np.clip(potential[reached] * publish_scale / top, 0, 100).astype(np.int8)
    return array_to_occupancy_grid(
        out, resolution=resolution, origin=(origin_xy[0], origin_xy[1], 0.0),
        frame_id=frame_id, stamp=stamp,
    )  # fmt: skip
