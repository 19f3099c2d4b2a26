"""What the graph mapper gives back: a pose for every scan, and the occupancy map.

Karto keeps only its keyframes; :func:`blend_scan_poses` places every other scan between
the optimised keyframes before and after it, and :func:`render_map` renders the map from
optimised poses as Karto's ``OccupancyGrid`` does (hits over passes, cells passed by at
most :data:`MIN_PASS_THROUGH` beams unknown, occupied above a hit ratio of
:data:`OCCUPANCY_THRESHOLD`, beams beyond ``max_laser_range`` clearing up to it). Both are
used by :class:`~roverlab.slam.graph.slam.GraphSLAM`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roverlab.maps.grid import CountGrid
from roverlab.slam.graph.params import GraphParams
from roverlab.slam.graph.poses import _compose, _inverse, _relative, _Scan

__all__ = ["MIN_PASS_THROUGH", "OCCUPANCY_THRESHOLD", "GraphMap", "blend_scan_poses", "render_map"]

FloatArray = NDArray[np.float64]

#: Karto's ``OccupancyGrid`` defaults: minimum passes for a known cell, and hit ratio.
MIN_PASS_THROUGH = 2
OCCUPANCY_THRESHOLD = 0.1


@dataclass(frozen=True, eq=False)
class GraphMap:
    """The occupancy map (``nav_msgs/OccupancyGrid`` conventions).

    Attributes:
        data: ``(H, W)`` int8, row 0 at the lowest y; -1 unknown, 0 free, 100 occupied.
        resolution: cell size (m).
        origin: world ``(x, y)`` of the outer corner of cell ``(0, 0)`` (m).
    """

    data: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float]

    @property
    def origin_xy(self) -> tuple[float, float]:
        """Alias of :attr:`origin` (the name :class:`roverlab.maps.grid` uses)."""
        return self.origin


def blend_scan_poses(
    kf_pose: FloatArray,
    kf_prev_rel: FloatArray,
    kf_scan_index: Sequence[int],
    scan_ref: Sequence[int],
    scan_rel: Sequence[FloatArray],
) -> FloatArray:
    """``(N, 3)`` pose of every scan from the keyframes' current poses.

    A scan between keyframes ``r`` and ``r + 1`` is placed relative to both optimised
    keyframes (through its relative pose to ``r`` and ``r + 1``'s relative pose to ``r``
    as matched) and the two placements are blended by the scan's position between the
    keyframes.

    Args:
        kf_pose: ``(K, 3)`` keyframe poses.
        kf_prev_rel: ``(K, 3)`` pose of keyframe ``k`` in keyframe ``k - 1`` as matched.
        kf_scan_index: the scan index of each keyframe.
        scan_ref: each scan's keyframe (the last one at or before it).
        scan_rel: each scan's pose relative to that keyframe.
    """
    n = len(scan_ref)
    if n == 0:
        return np.zeros((0, 3))
    ref = np.asarray(scan_ref, dtype=np.intp)
    rel = np.asarray(scan_rel, dtype=np.float64)
    a = _compose(kf_pose[ref], rel)
    k = kf_pose.shape[0]
    idx = np.asarray(kf_scan_index, dtype=np.intp)
    has_next = ref + 1 < k
    if np.any(has_next):
        r = ref[has_next]
        nxt = r + 1
        b = _compose(_compose(kf_pose[nxt], _inverse(kf_prev_rel[nxt])), rel[has_next])
        s = np.flatnonzero(has_next)
        w = (s - idx[r]) / np.maximum(idx[nxt] - idx[r], 1)
        delta = _relative(a[has_next], b)
        a[has_next] = _compose(a[has_next], delta * w[:, None])
    return a


def render_map(poses: FloatArray, scans: Sequence[_Scan], params: GraphParams) -> GraphMap:
    """The map of ``scans`` at the robot ``poses`` (``(N, 3)``, one per scan), rendered
    with the shared :class:`~roverlab.maps.grid.CountGrid` (Karto's ``OccupancyGrid``
    rule); an empty map of one unknown cell when there is no scan."""
    res = params.resolution
    if len(scans) == 0:
        return GraphMap(np.full((1, 1), -1, dtype=np.int8), res, (0.0, 0.0))
    lasers = _compose(poses, np.asarray([s.laser_offset for s in scans]))
    x0, y0 = lasers[:, :2].min(axis=0) - 1.0
    x1, y1 = lasers[:, :2].max(axis=0) + 1.0
    ox = math.floor(x0 / res) * res
    oy = math.floor(y0 / res) * res
    grid = CountGrid(
        max(1, math.ceil((x1 - ox) / res)), max(1, math.ceil((y1 - oy) / res)), res, (ox, oy)
    )
    for pose, scan in zip(lasers, scans, strict=True):
        grid.update_scan(
            pose,
            scan.ranges,
            scan.angles,
            scan.range_max if math.isfinite(scan.range_max) else 1e9,
            range_min=max(scan.range_min, params.min_laser_range),
            usable_range=params.max_laser_range,
            grow=True,
        )
    data = grid.to_occupancy(occupied_thresh=OCCUPANCY_THRESHOLD)
    data[grid.visits <= MIN_PASS_THROUGH] = -1
    return GraphMap(data, res, grid.origin_xy)
