"""Building layouts for simulated SLAM logs: free rectangles on a grid plus a route.

A :class:`Building` is an occupancy grid (walls are every cell not inside one of the free
rectangles; pillars are rectangles put back) and the route a robot drives through it, as
waypoints. Walls are axis-aligned and bare, so a corridor looks the same along its whole
length: the case where a scan matcher without odometry has nothing to hold on to.

:func:`building` makes one by name (:data:`BUILDINGS`):

* ``corridor``: one straight corridor ``length_m`` long (default 60 m), driven end to end;
* ``t_junction``: a corridor with a side branch, driven up the branch and back;
* ``x_junction``: two crossing corridors, each arm driven out and back;
* ``loop``: a rectangular ring corridor whose centre line is ``length_m`` long (default
  100 m), driven round once and on to the first corner, so the loop closes;
* ``hall``: an open 20 m x 14 m hall with pillars, driven round in a lawnmower pattern.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.data.errors import SlamError

__all__ = ["BUILDINGS", "Building", "building"]

#: Cell size of the building grids (m).
GRID_RESOLUTION_M: Final = 0.05
#: Corridor width (m).
CORRIDOR_WIDTH_M: Final = 2.0
#: Empty margin around the layout (m).
_MARGIN_M: Final = 1.0

Rect = tuple[float, float, float, float]  # x0, y0, x1, y1 (m)


@dataclass(frozen=True, eq=False)
class Building:
    """A simulated building.

    Attributes:
        name: its name (one of :data:`BUILDINGS`).
        grid: (H, W) bool, True for wall; row 0 at the lowest y.
        resolution: cell size (m).
        origin: world ``(x, y)`` of the corner of cell ``(0, 0)`` (m).
        route: (K, 2) waypoints (m) the robot drives through in order.
        start_heading: the robot's heading at the first waypoint (rad).
    """

    name: str
    grid: NDArray[np.bool_]
    resolution: float
    origin: tuple[float, float]
    route: NDArray[np.float64]
    start_heading: float

    @property
    def extent_m(self) -> float:
        """The larger side of the building (m)."""
        return float(max(self.grid.shape)) * self.resolution


def _rasterise(
    free: list[Rect], pillars: list[Rect]
) -> tuple[NDArray[np.bool_], tuple[float, float]]:
    xs = [v for r in free for v in (r[0], r[2])]
    ys = [v for r in free for v in (r[1], r[3])]
    x0, y0 = min(xs) - _MARGIN_M, min(ys) - _MARGIN_M
    w = int(math.ceil((max(xs) + _MARGIN_M - x0) / GRID_RESOLUTION_M))
    h = int(math.ceil((max(ys) + _MARGIN_M - y0) / GRID_RESOLUTION_M))
    grid = np.ones((h, w), dtype=bool)

    def cells(r: Rect) -> tuple[slice, slice]:
        c0 = round((r[0] - x0) / GRID_RESOLUTION_M)
        c1 = round((r[2] - x0) / GRID_RESOLUTION_M)
        r0 = round((r[1] - y0) / GRID_RESOLUTION_M)
        r1 = round((r[3] - y0) / GRID_RESOLUTION_M)
        return slice(r0, r1), slice(c0, c1)

    for r in free:
        grid[cells(r)] = False
    for r in pillars:
        grid[cells(r)] = True
    return grid, (x0, y0)


def _make(
    name: str, free: list[Rect], route: list[tuple[float, float]], pillars: list[Rect] | None = None
) -> Building:
    grid, origin = _rasterise(free, pillars or [])
    pts = np.array(route, dtype=np.float64)
    d = pts[1] - pts[0]
    return Building(name, grid, GRID_RESOLUTION_M, origin, pts, math.atan2(d[1], d[0]))


def _corridor(length_m: float) -> Building:
    half = CORRIDOR_WIDTH_M / 2
    return _make("corridor", [(0.0, -half, length_m, half)], [(1.0, 0.0), (length_m - 1.0, 0.0)])


def _t_junction(length_m: float) -> Building:
    half, mid = CORRIDOR_WIDTH_M / 2, length_m / 2
    branch = length_m / 2
    free = [(0.0, -half, length_m, half), (mid - half, 0.0, mid + half, branch)]
    route = [(1.0, 0.0), (mid, 0.0), (mid, branch - 1.0), (mid, 0.0), (length_m - 1.0, 0.0)]
    return _make("t_junction", free, route)


def _x_junction(length_m: float) -> Building:
    half, mid = CORRIDOR_WIDTH_M / 2, length_m / 2
    free = [(0.0, -half, length_m, half), (mid - half, -mid, mid + half, mid)]
    route = [
        (1.0, 0.0),
        (mid, 0.0),
        (mid, mid - 1.0),
        (mid, 0.0),
        (mid, -mid + 1.0),
        (mid, 0.0),
        (length_m - 1.0, 0.0),
    ]
    return _make("x_junction", free, route)


def _loop(length_m: float) -> Building:
    # a ring corridor round a block, the centre line a (3 : 2) rectangle of this perimeter
    a = 0.3 * length_m
    b = 0.2 * length_m
    half = CORRIDOR_WIDTH_M / 2
    free = [
        (-half, -half, a + half, half),
        (-half, b - half, a + half, b + half),
        (-half, -half, half, b + half),
        (a - half, -half, a + half, b + half),
    ]
    route = [(0.0, 0.0), (a, 0.0), (a, b), (0.0, b), (0.0, 0.0), (a, 0.0)]
    return _make("loop", free, route)


def _hall(length_m: float) -> Building:
    w, h = length_m, 0.7 * length_m
    pillars = [
        (x - 0.3, y - 0.3, x + 0.3, y + 0.3)
        for x in (0.25 * w, 0.5 * w, 0.75 * w)
        for y in (0.33 * h, 0.67 * h)
    ]
    route = [
        (1.5, 1.5),
        (w - 1.5, 1.5),
        (w - 1.5, 0.5 * h),
        (1.5, 0.5 * h),
        (1.5, h - 1.5),
        (w - 1.5, h - 1.5),
    ]
    return _make("hall", [(0.0, 0.0, w, h)], route, pillars)


#: Layouts by name, with the default ``length_m`` of each.
BUILDINGS: Final = {
    "corridor": 60.0,
    "t_junction": 40.0,
    "x_junction": 40.0,
    "loop": 100.0,
    "hall": 20.0,
}

_MAKERS: Final = {
    "corridor": _corridor,
    "t_junction": _t_junction,
    "x_junction": _x_junction,
    "loop": _loop,
    "hall": _hall,
}


def building(name: str, length_m: float | None = None) -> Building:
    """The layout ``name`` (see the module docstring) of size ``length_m``.

    Args:
        name: one of :data:`BUILDINGS`.
        length_m: the corridor length (``corridor``, ``t_junction``, ``x_junction``), the
            loop's centre-line length (``loop``) or the hall's width (``hall``); default:
            the value in :data:`BUILDINGS`.

    Raises:
        SlamError: an unknown name or a length out of 10-400 m.
    """
    if name not in _MAKERS:
        raise SlamError(f"unknown building {name!r} ({', '.join(BUILDINGS)})")
    length = BUILDINGS[name] if length_m is None else float(length_m)
    if not (math.isfinite(length) and 10.0 <= length <= 400.0):
        raise SlamError(f"building length must be within 10-400 m, got {length_m}")
    return _MAKERS[name](length)
