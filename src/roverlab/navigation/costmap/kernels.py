"""Compiled costmap kernels: Bresenham lines, convex fill, ray clearing, marking, inflation
(the footprint's cost and cells: :mod:`.footprint_kernels`).

All grids are ``(size_y, size_x)`` uint8 arrays in ``nav_msgs/OccupancyGrid`` order (row =
y). Cell coordinates are ``(mx, my)`` integers; world coordinates are turned into cell
units by the callers.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.maps.raytrace import trace_segment_cells

__all__ = [
    "bresenham",
    "clear_rays",
    "combine_max",
    "convex_fill",
    "height_filter",
    "inflate",
    "line_cost",
    "mark_observation",
    "mark_points",
    "raytrace_freespace",
    "scan_points",
]

_jit = numba.njit(cache=True, nogil=True)

LETHAL = 254
INSCRIBED = 253
NO_INFO = 255


@_jit
def bresenham(x0: int, y0: int, x1: int, y1: int, max_length: int, out: NDArray[np.int64]) -> int:
    """costmap_2d's ``raytraceLine``: the cells of the Bresenham line from ``(x0, y0)`` to
    ``(x1, y1)``, at most ``max_length`` steps along the dominant axis, both ends included.

    Writes ``(mx, my)`` rows into ``out`` (capacity ``max(|dx|, |dy|) + 1``); returns the
    count.
    """
    dx = x1 - x0
    dy = y1 - y0
    adx = abs(dx)
    ady = abs(dy)
    sx = 1 if dx > 0 else -1
    sy = 1 if dy > 0 else -1
    dist = math.hypot(dx, dy)
    scale = 1.0 if dist == 0.0 else min(1.0, max_length / dist)
    if adx >= ady:  # x is the dominant axis
        return _bresenham2d(out, x0, y0, sx, 0, 0, sy, adx, ady, scale)
    return _bresenham2d(out, x0, y0, 0, sy, sx, 0, ady, adx, scale)


@_jit
def _bresenham2d(
    out: NDArray[np.int64],
    x: int,
    y: int,
    major_x: int,
    major_y: int,
    minor_x: int,
    minor_y: int,
    d_major: int,
    d_minor: int,
    scale: float,
) -> int:
    """costmap_2d's ``bresenham2D``: one step along the dominant axis each cell, one along
    the other when the error overflows."""
    err = d_major // 2
    end = min(int(scale * d_major), d_major)
    n = 0
    for _ in range(end):
        out[n, 0] = x
        out[n, 1] = y
        n += 1
        x += major_x
        y += major_y
        err += d_minor
        if err >= d_major:
            x += minor_x
            y += minor_y
            err -= d_major
    out[n, 0] = x
    out[n, 1] = y
    return n + 1


@_jit
def convex_fill(grid: NDArray[np.uint8], poly: NDArray[np.int64], value: int) -> None:
    """costmap_2d's ``convexFillCells`` + set: every cell of the outline of the convex
    polygon ``poly`` ((M, 2) cells, M >= 3, all inside the grid) and between its lowest and
    highest outline cell of each column gets ``value``."""
    m = poly.shape[0]
    xmin = poly[0, 0]
    xmax = poly[0, 0]
    for k in range(m):
        xmin = min(xmin, poly[k, 0])
        xmax = max(xmax, poly[k, 0])
    ncol = xmax - xmin + 1
    lo = np.full(ncol, 1 << 30, dtype=np.int64)
    hi = np.full(ncol, -1, dtype=np.int64)
    cap = 0
    for k in range(m):
        j = (k + 1) % m
        cap = max(cap, abs(poly[j, 0] - poly[k, 0]), abs(poly[j, 1] - poly[k, 1]))
    buf = np.empty((cap + 2, 2), dtype=np.int64)
    for k in range(m):
        j = (k + 1) % m
        n = bresenham(poly[k, 0], poly[k, 1], poly[j, 0], poly[j, 1], 1 << 30, buf)
        for q in range(n):
            c = buf[q, 0] - xmin
            yy = buf[q, 1]
            lo[c] = min(lo[c], yy)
            hi[c] = max(hi[c], yy)
    for c in range(ncol):
        for yy in range(lo[c], hi[c] + 1):
            grid[yy, c + xmin] = value


@_jit
def line_cost(
    grid: NDArray[np.uint8], x0: int, y0: int, x1: int, y1: int, buf: NDArray[np.int64]
) -> float:
    """base_local_planner's ``CostmapModel::lineCost``: the highest cost along the Bresenham
    line, -1 at a lethal or unknown cell (both ends included)."""
    n = bresenham(x0, y0, x1, y1, 1 << 30, buf)
    best = 0.0
    for q in range(n):
        c = grid[buf[q, 1], buf[q, 0]]
        if c in (LETHAL, NO_INFO):
            return -1.0
        if c > best:
            best = float(c)
    return best


@_jit
def _grow_bounds(bounds: NDArray[np.float64], n: int, x: float, y: float) -> None:
    """``bounds`` (min x, min y, max x, max y) after ``n`` points, grown to hold ``(x, y)``."""
    if n == 0:
        bounds[0] = bounds[2] = x
        bounds[1] = bounds[3] = y
    else:
        bounds[0] = min(bounds[0], x)
        bounds[1] = min(bounds[1], y)
        bounds[2] = max(bounds[2], x)
        bounds[3] = max(bounds[3], y)


@_jit
def clear_rays(
    grid: NDArray[np.uint8],
    gx0: float,
    gy0: float,
    ends: NDArray[np.float64],
    max_cells: float,
    free_value: int,
    buf: NDArray[np.int64],
) -> None:
    """Free every cell each ray ``(gx0, gy0) -> ends[k]`` (cell units) crosses, up to
    ``max_cells`` from the origin; the rays are traced by roverlab's shared grid tracer
    (:func:`roverlab.maps.raytrace.trace_segment_cells`) and clipped to the grid."""
    for k in range(ends.shape[0]):
        _clear_ray(grid, gx0, gy0, ends[k, 0], ends[k, 1], max_cells, free_value, buf)


@_jit
def _clear_ray(
    grid: NDArray[np.uint8],
    gx0: float,
    gy0: float,
    ex: float,
    ey: float,
    max_cells: float,
    free_value: int,
    buf: NDArray[np.int64],
) -> None:
    h, w = grid.shape
    flat = grid.reshape(-1)
    dx = ex - gx0
    dy = ey - gy0
    d = math.hypot(dx, dy)
    if d > max_cells and d > 0.0:
        s = max_cells / d
        ex = gx0 + dx * s
        ey = gy0 + dy * s
    n = trace_segment_cells(gx0, gy0, ex, ey, w, h, buf)
    for q in range(n):
        flat[buf[q]] = free_value


@numba.njit(cache=True, nogil=True, error_model="numpy")
def raytrace_freespace(
    grid: NDArray[np.uint8],
    points: NDArray[np.float64],
    ox: float,
    oy: float,
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    res: float,
    raytrace_range: float,
    free_value: int,
    buf: NDArray[np.int64],
    bounds: NDArray[np.float64],
) -> int:
    """costmap_2d's ``ObstacleLayer::raytraceFreespace`` for one observation seen from
    ``(ox, oy)`` (inside the map ``[x0, x1) x [y0, y1)``, m): each point's ray is clipped
    to the map (costmap_2d's order of the four sides; a ray whose clipped end is not
    finite or not on the map is skipped), its cells up to ``raytrace_range`` are set to
    ``free_value`` (:func:`clear_rays`), and ``bounds`` (min x, min y, max x, max y) takes
    the rays' ends cut at ``raytrace_range`` (``updateRaytraceBounds``). Returns the rays
    traced (``bounds`` untouched when 0)."""
    gx0 = (ox - x0) / res
    gy0 = (oy - y0) / res
    max_cells = raytrace_range / res
    n = 0
    for k in range(points.shape[0]):
        wx = points[k, 0]
        wy = points[k, 1]
        a = wx - ox
        b = wy - oy
        if wx < x0:
            t = (x0 - ox) / a
            wx, wy = x0, oy + b * t
        if wy < y0:
            t = (y0 - oy) / b
            wx, wy = ox + a * t, y0
        if wx > x1:
            t = (x1 - ox) / a
            wx, wy = x1 - 0.001, oy + b * t
        if wy > y1:
            t = (y1 - oy) / b
            wx, wy = ox + a * t, y1 - 0.001
        if not (
            math.isfinite(wx) and math.isfinite(wy) and wx >= x0 and wy >= y0 and wx < x1
            and wy < y1
        ):  # fmt: skip
            continue
        _clear_ray(grid, gx0, gy0, (wx - x0) / res, (wy - y0) / res, max_cells, free_value, buf)
        dx = wx - ox
        dy = wy - oy
        full = math.hypot(dx, dy)
        scale = min(1.0, raytrace_range / full) if full > 0 else 1.0
        ex = ox + dx * scale
        ey = oy + dy * scale
        _grow_bounds(bounds, n, ex, ey)
        n += 1
    return n


@_jit
def mark_observation(
    grid: NDArray[np.uint8],
    points: NDArray[np.float64],
    origin: NDArray[np.float64],
    max_obstacle_height: float,
    obstacle_range: float,
    gx: float,
    gy: float,
    res: float,
    value: int,
    bounds: NDArray[np.float64],
) -> int:
    """costmap_2d's marking of one observation: each point no higher than
    ``max_obstacle_height``, closer (3-D) than ``obstacle_range`` to ``origin`` and on the
    grid (origin ``(gx, gy)``) sets its cell to ``value``; ``bounds`` (min x, min y, max
    x, max y) takes the marked points. Returns the points marked (``bounds`` untouched when
    0)."""
    h, w = grid.shape
    r2 = obstacle_range * obstacle_range
    n = 0
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        pz = points[k, 2]
        dx = px - origin[0]
        dy = py - origin[1]
        dz = pz - origin[2]
        if not (pz <= max_obstacle_height and (dx * dx + dy * dy) + dz * dz < r2):
            continue
        if not (px >= gx and py >= gy):
            continue
        mx = int((px - gx) / res)
        my = int((py - gy) / res)
        if mx >= w or my >= h:
            continue
        grid[my, mx] = value
        _grow_bounds(bounds, n, px, py)
        n += 1
    return n


@_jit
def scan_points(
    ranges: NDArray[np.float32],
    cos_a: NDArray[np.float64],
    sin_a: NDArray[np.float64],
    range_min: float,
    range_max: float,
    inf_is_valid: bool,
    rotation: NDArray[np.float64],
    translation: NDArray[np.float64],
) -> NDArray[np.float64]:
    """A LaserScan's points in another frame: laser_geometry's projection (readings in
    ``[range_min, range_max)``, NaN dropped; with ``inf_is_valid`` +inf counts as
    ``range_max - 0.0001``) of beams at angles with cosines ``cos_a`` and sines ``sin_a``,
    rotated by the quaternion ``rotation`` (x, y, z, w) and moved by ``translation``, with
    the arithmetic of :meth:`roverlab.geometry.Transform3.apply` (the same values).
    ``(N, 3)``, in beam order."""
    x, y, z, w = rotation[0], rotation[1], rotation[2], rotation[3]
    out = np.empty((ranges.shape[0], 3))
    n = 0
    for i in range(ranges.shape[0]):
        r = float(ranges[i])
        if inf_is_valid and r == np.inf:
            r = range_max - 1e-4
        if not (r >= range_min and r < range_max):
            continue
        px = r * cos_a[i]
        py = r * sin_a[i]
        pz = 0.0
        t0 = 2.0 * (y * pz - z * py)
        t1 = 2.0 * (z * px - x * pz)
        t2 = 2.0 * (x * py - y * px)
        out[n, 0] = ((px + w * t0) + (y * t2 - z * t1)) + translation[0]
        out[n, 1] = ((py + w * t1) + (z * t0 - x * t2)) + translation[1]
        out[n, 2] = ((pz + w * t2) + (x * t1 - y * t0)) + translation[2]
        n += 1
    return out[:n]


@_jit
def mark_points(
    grid: NDArray[np.uint8],
    cells: NDArray[np.int64],
    value: int,
) -> None:
    """Set ``grid[my, mx] = value`` for each ``(mx, my)`` row of ``cells``."""
    for k in range(cells.shape[0]):
        grid[cells[k, 1], cells[k, 0]] = value


@_jit
def inflate(
    master: NDArray[np.uint8],
    x0: int,
    y0: int,
    xn: int,
    yn: int,
    radius: int,
    bin_of: NDArray[np.int64],
    cost_of: NDArray[np.uint8],
    nbins: int,
    inflate_unknown: bool,
    seen: NDArray[np.bool_],
    node_cell: NDArray[np.int64],
    node_src: NDArray[np.int64],
    node_next: NDArray[np.int64],
    bin_head: NDArray[np.int64],
    bin_tail: NDArray[np.int64],
) -> int:
    """costmap_2d's ``InflationLayer::updateCosts`` on the window ``[x0, xn) x [y0, yn)``
    (already grown by the inflation radius by the caller).

    Lethal cells of the window seed distance bin 0; cells are then taken bin by bin in
    increasing distance to their source obstacle (``bin_of[|dx|, |dy|]`` is the rank of
    ``hypot(dx, dy)`` among the distances within ``radius``, -1 beyond), each cell takes
    ``cost_of[|dx|, |dy|]`` (max with its old cost; an unknown cell only takes inscribed
    and lethal costs, or any non-zero cost with ``inflate_unknown``) and offers its four
    neighbours with the same source. A cell is taken once (``seen``); a cell offered to a
    bin already passed is not revisited, as ROS's ordered bins. Returns the cells taken.
    """
    h, w = master.shape
    flat = master.reshape(-1)
    # a cell taken lies within ``radius`` of a seed of the window, a cell looked at one
    # further: only those are cleared (not the whole grid, 640 000 cells for BARN's
    # global costmap); ``seen`` elsewhere is never read
    rx0 = max(0, x0 - radius - 1)
    rx1 = min(w, xn + radius + 1)
    for j in range(max(0, y0 - radius - 1), min(h, yn + radius + 1)):
        seen[j * w + rx0 : j * w + rx1] = False
    bin_head[:nbins] = -1
    bin_tail[:nbins] = -1
    cap = node_cell.shape[0]
    nn = 0
    for j in range(y0, yn):
        for i in range(x0, xn):
            idx = j * w + i
            if flat[idx] == LETHAL and nn < cap:
                node_cell[nn] = idx
                node_src[nn] = idx
                node_next[nn] = -1
                if bin_tail[0] < 0:
                    bin_head[0] = nn
                else:
                    node_next[bin_tail[0]] = nn
                bin_tail[0] = nn
                nn += 1
    taken = 0
    for b in range(nbins):
        k = bin_head[b]
        while k >= 0:
            idx = node_cell[k]
            if not seen[idx]:
                seen[idx] = True
                taken += 1
                my = idx // w
                mx = idx - my * w
                src = node_src[k]
                sy = src // w
                sx = src - sy * w
                cost = cost_of[abs(mx - sx), abs(my - sy)]
                old = flat[idx]
                if old == NO_INFO and (
                    (inflate_unknown and cost > 0) or (not inflate_unknown and cost >= INSCRIBED)
                ):
                    flat[idx] = cost
                else:
                    flat[idx] = max(old, cost)
                for nb in range(4):  # the neighbour's cell from this one's: no division
                    nx = mx
                    ny = my
                    if nb == 0:
                        if mx == 0:
                            continue
                        nidx = idx - 1
                        nx = mx - 1
                    elif nb == 1:
                        if my == 0:
                            continue
                        nidx = idx - w
                        ny = my - 1
                    elif nb == 2:
                        if mx == w - 1:
                            continue
                        nidx = idx + 1
                        nx = mx + 1
                    else:
                        if my == h - 1:
                            continue
                        nidx = idx + w
                        ny = my + 1
                    if seen[nidx]:
                        continue
                    nb_bin = bin_of[abs(nx - sx), abs(ny - sy)]
                    if nb_bin < 0 or nn >= cap:
                        continue
                    node_cell[nn] = nidx
                    node_src[nn] = src
                    node_next[nn] = -1
                    if bin_tail[nb_bin] < 0:
                        bin_head[nb_bin] = nn
                    else:
                        node_next[bin_tail[nb_bin]] = nn
                    bin_tail[nb_bin] = nn
                    nn += 1
            k = node_next[k]
    return taken


@_jit
def combine_max(
    master: NDArray[np.uint8], own: NDArray[np.uint8], x0: int, y0: int, xn: int, yn: int
) -> None:
    """costmap_2d's ``CostmapLayer::updateWithMax`` on the window ``[x0, xn) x [y0, yn)``:
    a master cell takes the layer's cost where the layer knows it and the master cell is
    unknown or lower. The window is clipped to both grids."""
    h = min(master.shape[0], own.shape[0])
    w = min(master.shape[1], own.shape[1])
    for j in range(max(y0, 0), min(yn, h)):
        for i in range(max(x0, 0), min(xn, w)):
            c = own[j, i]
            if c == NO_INFO:
                continue
            m = master[j, i]
            if m == NO_INFO or m < c:
                master[j, i] = c


@_jit
def height_filter(
    points: NDArray[np.float64], min_height: float, max_height: float
) -> NDArray[np.float64]:
    """The rows of ``points`` (``(N, 3)``) with ``min_height <= z <= max_height`` and every
    coordinate finite, in order (an ObservationBuffer's height filter)."""
    n = points.shape[0]
    keep = np.empty(n, dtype=np.bool_)
    m = 0
    for k in range(n):
        x = points[k, 0]
        y = points[k, 1]
        z = points[k, 2]
        ok = (
            z <= max_height and z >= min_height
            and math.isfinite(x) and math.isfinite(y) and math.isfinite(z)
        )  # fmt: skip
        keep[k] = ok
        if ok:
            m += 1
    out = np.empty((m, 3))
    j = 0
    for k in range(n):
        if keep[k]:
            out[j, 0] = points[k, 0]
            out[j, 1] = points[k, 1]
            out[j, 2] = points[k, 2]
            j += 1
    return out
