"""Hector's multi-resolution log-odds occupancy grid, updated by compiled Bresenham lines.

Every level is a square grid of its own (level ``i``: cell size ``map_resolution * 2**i``,
``map_size // 2**i`` cells per side), all covering the same square of the world and all
updated with every map update, as hector does (the coarse levels are not down-sampled
copies). All levels live in flat arrays with per-level offsets so that one compiled call
updates, or matches against, the whole pyramid.

Map coordinates of a level: the world point ``(x, y)`` is at ``(x / res + cx, y / res + cy)``
with ``(cx, cy) = (map_start_x, map_start_y) * size``; the centre of cell ``(ix, iy)`` is at
map coordinates ``(ix, iy)`` (a cell spans ``[ix - 0.5, ix + 0.5)``).

A map update follows hector's ``OccGridMapUtil``: for each beam the cells from the laser to
the endpoint are marked free and the endpoint cell occupied, each cell changes at most once
per update, and occupied wins over free (a cell first passed through and later hit has its
free increment undone). Log-odds increments are ``log(p / (1 - p))`` of
``update_factor_free`` / ``update_factor_occupied``; a cell's occupancy probability (the map
value ``M`` the scan matcher interpolates) is kept next to its log-odds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.slam.hector.params import HectorParams

__all__ = ["HectorMap", "MultiResGrid", "prob_to_log_odds"]

_jit = numba.njit(cache=True, nogil=True)

#: hector stops adding occupied evidence once a cell's log-odds reach this value.
_LOG_ODDS_OCC_CAP = 50.0
#: map value ``M`` of a cell never observed (log-odds 0).
UNKNOWN_VALUE = 0.5


def prob_to_log_odds(p: float) -> float:
    """``log(p / (1 - p))``, hector's conversion of an update factor to an increment."""
    return math.log(p / (1.0 - p))


@dataclass(frozen=True, slots=True)
class HectorMap:
    """One map level as an occupancy grid (``nav_msgs/OccupancyGrid`` conventions).

    Attributes:
        data: (H, W) int8, row 0 at the lowest y; -1 unknown, 0 free, 100 occupied
            (hector: log-odds < 0 is free, > 0 occupied, exactly 0 unknown).
        resolution: cell size (m).
        origin: world ``(x, y)`` of the outer corner of cell ``(0, 0)`` (m).
    """

    data: NDArray[np.int8]
    resolution: float
    origin: tuple[float, float]

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """Column and row of the cell holding world point ``(x, y)`` (may be outside)."""
        return (
            math.floor((x - self.origin[0]) / self.resolution),
            math.floor((y - self.origin[1]) / self.resolution),
        )


@_jit
def _set_prob(logodds: NDArray[np.float32], prob: NDArray[np.float32], i: int) -> None:
    e = math.exp(min(float(logodds[i]), 80.0))
    prob[i] = e / (1.0 + e)


@_jit
def _update_line(
    logodds: NDArray[np.float32],
    prob: NDArray[np.float32],
    stamp: NDArray[np.int32],
    off: int,
    size: int,
    x0: int,
    y0: int,
    x1: int,
    y1: int,
    mark_free: int,
    mark_occ: int,
    lfree: float,
    locc: float,
) -> None:
    # Bresenham from (x0, y0) to (x1, y1): every cell but the last is free, the last is hit.
    dx = abs(x1 - x0)
    dy = -abs(y1 - y0)
    sx = 1 if x0 < x1 else -1
    sy = 1 if y0 < y1 else -1
    err = dx + dy
    x = x0
    y = y0
    while x != x1 or y != y1:
        i = off + y * size + x
        if stamp[i] < mark_free:
            logodds[i] += lfree
            stamp[i] = mark_free
            _set_prob(logodds, prob, i)
        e2 = 2 * err
        if e2 >= dy:
            err += dy
            x += sx
        if e2 <= dx:
            err += dx
            y += sy
    i = off + y1 * size + x1
    if stamp[i] < mark_occ:
        if stamp[i] == mark_free:
            logodds[i] -= lfree
        if logodds[i] < _LOG_ODDS_OCC_CAP:
            logodds[i] += locc
        stamp[i] = mark_occ
        _set_prob(logodds, prob, i)


@_jit
def _update_levels(
    logodds: NDArray[np.float32],
    prob: NDArray[np.float32],
    stamp: NDArray[np.int32],
    offsets: NDArray[np.int64],
    sizes: NDArray[np.int64],
    inv_res: NDArray[np.float64],
    centers: NDArray[np.float64],
    x: float,
    y: float,
    theta: float,
    origin: NDArray[np.float64],
    points: NDArray[np.float64],
    stamp_base: int,
    lfree: float,
    locc: float,
) -> None:
    c = math.cos(theta)
    s = math.sin(theta)
    ox = x + c * origin[0] - s * origin[1]
    oy = y + s * origin[0] + c * origin[1]
    mark_free = stamp_base + 1
    mark_occ = stamp_base + 2
    for lev in range(len(sizes)):
        size = sizes[lev]
        off = offsets[lev]
        k = inv_res[lev]
        cx = centers[lev, 0]
        cy = centers[lev, 1]
        bx = int(math.floor(ox * k + cx + 0.5))
        by = int(math.floor(oy * k + cy + 0.5))
        if bx < 0 or by < 0 or bx >= size or by >= size:
            continue
        for j in range(points.shape[0]):
            px = points[j, 0]
            py = points[j, 1]
            wx = x + c * px - s * py
            wy = y + s * px + c * py
            ex = int(math.floor(wx * k + cx + 0.5))
            ey = int(math.floor(wy * k + cy + 0.5))
            if ex < 0 or ey < 0 or ex >= size or ey >= size:
                continue  # hector skips beams whose endpoint lies outside the map
            if ex == bx and ey == by:
                continue
            _update_line(
                logodds, prob, stamp, off, size, bx, by, ex, ey, mark_free, mark_occ, lfree, locc
            )


class MultiResGrid:
    """The map pyramid: log-odds, probabilities and update stamps of every level."""

    def __init__(self, params: HectorParams) -> None:
        self.params = params
        levels = params.map_multi_res_levels
        self.sizes = np.array([params.level_size(i) for i in range(levels)], dtype=np.int64)
        self.resolutions = np.array(
            [params.level_resolution(i) for i in range(levels)], dtype=np.float64
        )
        self.inv_res = 1.0 / self.resolutions
        self.centers = np.array(
            [[params.map_start_x * n, params.map_start_y * n] for n in self.sizes],
            dtype=np.float64,
        )
        self.offsets = np.zeros(levels, dtype=np.int64)
        self.offsets[1:] = np.cumsum(self.sizes[:-1] ** 2)
        total = int((self.sizes**2).sum())
        self.logodds = np.zeros(total, dtype=np.float32)
        self.prob = np.full(total, UNKNOWN_VALUE, dtype=np.float32)
        self.stamp = np.zeros(total, dtype=np.int32)
        self._stamp_base = 0
        self.log_odds_free = prob_to_log_odds(params.update_factor_free)
        self.log_odds_occupied = prob_to_log_odds(params.update_factor_occupied)
        self.updates = 0

    def grow(self) -> None:
        """Double every level's side, keeping what is mapped where it is in the world (the
        old square sits in the middle of the new one). hector_mapping's map is fixed in
        size; roverlab's offline runs grow it instead of failing when the robot nears an
        edge."""
        old_sizes, old_offsets = self.sizes.copy(), self.offsets.copy()
        arrays = (self.logodds, self.prob, self.stamp)
        self.sizes = old_sizes * 2
        self.centers = self.centers + (old_sizes // 2)[:, None].astype(np.float64)
        self.offsets = np.zeros_like(old_offsets)
        self.offsets[1:] = np.cumsum(self.sizes[:-1] ** 2)
        total = int((self.sizes**2).sum())
        fresh = (
            np.zeros(total, dtype=np.float32),
            np.full(total, UNKNOWN_VALUE, dtype=np.float32),
            np.zeros(total, dtype=np.int32),
        )
        for old, new in zip(arrays, fresh, strict=True):
            for level, n in enumerate(old_sizes):
                n, h = int(n), int(n) // 2
                src = old[int(old_offsets[level]) : int(old_offsets[level]) + n * n].reshape(n, n)
                m = 2 * n
                dst = new[int(self.offsets[level]) : int(self.offsets[level]) + m * m].reshape(m, m)
                dst[h : h + n, h : h + n] = src
        self.logodds, self.prob, self.stamp = fresh

    def reset(self) -> None:
        """Forget everything: every cell back to unknown."""
        self.logodds[:] = 0.0
        self.prob[:] = UNKNOWN_VALUE
        self.stamp[:] = 0
        self._stamp_base = 0
        self.updates = 0

    def update(
        self, pose: NDArray[np.float64], origin: NDArray[np.float64], points: NDArray[np.float64]
    ) -> None:
        """Integrate one scan into every level.

        Args:
            pose: (3,) robot pose ``x, y, theta`` in the map frame.
            origin: (2,) laser position in the robot frame (m).
            points: (N, 2) float64 beam endpoints in the robot frame (m).
        """
        if self._stamp_base > np.iinfo(np.int32).max - 8:
            self.stamp[:] = 0
            self._stamp_base = 0
        _update_levels(
            self.logodds,
            self.prob,
            self.stamp,
            self.offsets,
            self.sizes,
            self.inv_res,
            self.centers,
            float(pose[0]),
            float(pose[1]),
            float(pose[2]),
            origin,
            points,
            self._stamp_base,
            self.log_odds_free,
            self.log_odds_occupied,
        )
        self._stamp_base += 3
        self.updates += 1

    def level_view(self, level: int, what: str = "prob") -> NDArray[np.float32]:
        """(size, size) view ``[iy, ix]`` of a level's ``"prob"`` or ``"logodds"`` array."""
        arr = self.prob if what == "prob" else self.logodds
        n = int(self.sizes[level])
        off = int(self.offsets[level])
        return arr[off : off + n * n].reshape(n, n)

    def to_map_coords(self, level: int, x: float, y: float) -> tuple[float, float]:
        """Map coordinates (cells) of world point ``(x, y)`` on ``level``."""
        k = float(self.inv_res[level])
        return x * k + float(self.centers[level, 0]), y * k + float(self.centers[level, 1])

    def contains(self, x: float, y: float, margin_cells: float = 1.0) -> bool:
        """Whether world point ``(x, y)`` lies inside the finest level (with a margin)."""
        mx, my = self.to_map_coords(0, x, y)
        n = float(self.sizes[0])
        lo, hi = margin_cells, n - 1.0 - margin_cells
        return lo <= mx <= hi and lo <= my <= hi

    def extent(self) -> tuple[float, float, float, float]:
        """World ``xmin, ymin, xmax, ymax`` covered by the finest level (m)."""
        res = float(self.resolutions[0])
        n = float(self.sizes[0])
        x0 = (-0.5 - float(self.centers[0, 0])) * res
        y0 = (-0.5 - float(self.centers[0, 1])) * res
        return x0, y0, x0 + n * res, y0 + n * res

    def occupancy(self, level: int = 0) -> HectorMap:
        """Level ``level`` as an int8 occupancy grid (-1 unknown, 0 free, 100 occupied)."""
        lo = self.level_view(level, "logodds")
        data = np.full(lo.shape, -1, dtype=np.int8)
        data[lo < 0.0] = 0
        data[lo > 0.0] = 100
        res = float(self.resolutions[level])
        origin = (
            (-0.5 - float(self.centers[level, 0])) * res,
            (-0.5 - float(self.centers[level, 1])) * res,
        )
        return HectorMap(data=data, resolution=res, origin=origin)
