"""Uniform 2-D grid over a :class:`~roverlab.raycast.scene.Scene`, and the exact ray tests.

The grid covers the scene bounds with square cells; each cell lists (CSR arrays
``cell_start``/``items``) every segment and circle whose closed footprint touches the cell
grown by a tiny margin. Item ``k < n_segments`` is segment ``k``; item ``k >= n_segments``
is circle ``k - n_segments``. A ray walks the cells in order (Amanatides & Woo DDA) and
tests only the listed primitives; it stops in the first cell whose exit distance is not
smaller than the best hit so far, so the answer equals a brute-force test of every
primitive.

The primitive tests (:func:`segment_hit`, :func:`segment_distance`, :func:`circle_hit`)
and the grid-entry helper :func:`grid_entry` are compiled with numba and shared by the lidar
and camera kernels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.errors import RaycastInputError
from roverlab.raycast.scene import Scene

__all__ = [
    "SEGMENT_PARAM_EPS",
    "Grid",
    "build_grid",
    "circle_hit",
    "dda_steps",
    "grid_entry",
    "scene_grid",
    "segment_distance",
    "segment_hit",
]

#: A ray hits a segment when the hit parameter ``s`` along it is in
#: ``[-SEGMENT_PARAM_EPS, 1 + SEGMENT_PARAM_EPS]``: rays through a shared corner of two
#: walls never leak through it because of rounding.
SEGMENT_PARAM_EPS = 1e-12

# a numerator beyond ``best * den`` by this factor is surely behind (rounding included)
_FAR_BEHIND = 1.0 + 1e-12

_MAX_CELLS_PER_AXIS = 1024
_MAX_CELLS = 1 << 20
_CELLS_PER_PRIMITIVE = 2.0
_PAD_REL = 1e-7  # listing margin, relative to the cell size
_CACHE_ATTR = "_raycast_grid"

_jit = numba.njit(cache=True, nogil=True)


@dataclass(frozen=True, eq=False)
class Grid:
    """Uniform grid of a scene: cell ``(ix, iy)`` covers ``x0 + [ix, ix+1) * cell`` by
    ``y0 + [iy, iy+1) * cell`` and lists ``items[cell_start[c]:cell_start[c+1]]``
    with ``c = iy * nx + ix``.

    Attributes:
        x0, y0: world coordinates of the grid's lower-left corner (m).
        cell: cell side (m).
        nx, ny: number of cells along x and y.
        cell_start: (nx*ny + 1,) int32 CSR offsets.
        items: int32 primitive indices (segments first, then circles offset by
            ``n_segments``).
        n_segments: number of segments of the scene the grid was built for.
    """

    x0: float
    y0: float
    cell: float
    nx: int
    ny: int
    cell_start: NDArray[np.int32]
    items: NDArray[np.int32]
    n_segments: int


@_jit
def segment_hit(
    ox: float, oy: float, dx: float, dy: float, x0: float, y0: float, x1: float, y1: float
) -> tuple[float, float]:
    """Distance along the unit ray ``o + t d`` (t >= 0) to segment ``p0 p1``, and ``s``.

    Returns ``(t, s)`` with ``s`` the hit parameter along the segment (0 at p0, 1 at p1,
    clamped to [0, 1]), or ``(inf, 0)`` for no hit. A ray lying on the segment's line
    hits its nearest point (distance 0 when the origin is on the segment).
    """
    ex = x1 - x0
    ey = y1 - y0
    wx = x0 - ox
    wy = y0 - oy
    den = dx * ey - dy * ex
    if den == 0.0:
        # parallel: only a collinear ray hits, at the nearest end (or 0 when on it)
        if wx * dy - wy * dx != 0.0:
            return math.inf, 0.0
        ta = wx * dx + wy * dy
        tb = (x1 - ox) * dx + (y1 - oy) * dy
        if ta < 0.0 and tb < 0.0:
            return math.inf, 0.0
        if ta <= 0.0 <= tb or tb <= 0.0 <= ta:
            el = ex * ex + ey * ey
            s0 = 0.0 if el == 0.0 else -(wx * ex + wy * ey) / el
            return 0.0, min(1.0, max(0.0, s0))
        if ta <= tb:
            return ta, 0.0
        return tb, 1.0
    t = (wx * ey - wy * ex) / den
    if t < 0.0:
        return math.inf, 0.0
    s = (wx * dy - wy * dx) / den
    if s < -SEGMENT_PARAM_EPS or s > 1.0 + SEGMENT_PARAM_EPS:
        return math.inf, 0.0
    return t, min(1.0, max(0.0, s))


@_jit
def segment_distance(
    ox: float,
    oy: float,
    dx: float,
    dy: float,
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    best: float,
) -> float:
    """:func:`segment_hit`'s distance if it is smaller than ``best``, else ``inf``.

    The lidar's inner test: it compares numerators against the determinant and divides
    only for a hit that may be nearer than ``best`` (same result as
    ``segment_hit(...)[0]``). The final test is on the distance itself, so the nearest
    of several primitives is the same whatever order they are tested in.
    """
    ex = x1 - x0
    ey = y1 - y0
    wx = x0 - ox
    wy = y0 - oy
    den = dx * ey - dy * ex
    nt = wx * ey - wy * ex  # t = nt / den
    ns = wx * dy - wy * dx  # s = ns / den
    if den > 0.0:
        if (
            nt < 0.0
            or nt >= best * den * _FAR_BEHIND
            or ns < -SEGMENT_PARAM_EPS * den
            or ns > (1.0 + SEGMENT_PARAM_EPS) * den
        ):
            return math.inf
        t = nt / den
        return t if t < best else math.inf
    if den < 0.0:
        if (
            nt > 0.0
            or nt <= best * den * _FAR_BEHIND
            or ns > -SEGMENT_PARAM_EPS * den
            or ns < (1.0 + SEGMENT_PARAM_EPS) * den
        ):
            return math.inf
        t = nt / den
        return t if t < best else math.inf
    t, _ = segment_hit(ox, oy, dx, dy, x0, y0, x1, y1)
    return t if t < best else math.inf


@_jit
def circle_hit(
    ox: float, oy: float, dx: float, dy: float, cx: float, cy: float, r: float
) -> tuple[float, float]:
    """Entry and exit distances of the unit ray ``o + t d`` through circle ``(c, r)``.

    Returns ``(t_in, t_out)``; ``t_in = 0`` when the origin is inside or on the circle;
    ``(inf, inf)`` when the ray misses or the circle lies behind the origin.
    """
    fx = ox - cx
    fy = oy - cy
    b = fx * dx + fy * dy
    c = fx * fx + fy * fy - r * r
    disc = b * b - c
    if c <= 0.0:
        return 0.0, -b + math.sqrt(max(disc, 0.0))
    if b >= 0.0 or disc < 0.0:
        return math.inf, math.inf
    q = -b + math.sqrt(disc)
    return c / q, q  # c / q = -b - sqrt(disc), computed without cancellation


@_jit
def grid_entry(
    ox: float,
    oy: float,
    dx: float,
    dy: float,
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
) -> tuple[float, int, int]:
    """Where the ray ``o + t d`` (t >= 0) enters the grid box.

    Returns ``(t0, ix, iy)``: the entry distance (0 when the origin is inside) and the
    first cell; ``t0 = inf`` when the ray misses the box.
    """
    gx1 = gx0 + nx * cell
    gy1 = gy0 + ny * cell
    t0 = 0.0
    t1 = math.inf
    if dx != 0.0:
        ta = (gx0 - ox) / dx
        tb = (gx1 - ox) / dx
        if ta > tb:
            ta, tb = tb, ta
        t0 = max(t0, ta)
        t1 = min(t1, tb)
    elif ox < gx0 or ox > gx1:
        return math.inf, 0, 0
    if dy != 0.0:
        ta = (gy0 - oy) / dy
        tb = (gy1 - oy) / dy
        if ta > tb:
            ta, tb = tb, ta
        t0 = max(t0, ta)
        t1 = min(t1, tb)
    elif oy < gy0 or oy > gy1:
        return math.inf, 0, 0
    if t0 > t1:
        return math.inf, 0, 0
    ix = int(math.floor((ox + t0 * dx - gx0) / cell))
    iy = int(math.floor((oy + t0 * dy - gy0) / cell))
    ix = min(max(ix, 0), nx - 1)
    iy = min(max(iy, 0), ny - 1)
    return t0, ix, iy


@_jit
def dda_steps(dx: float, dy: float) -> tuple[int, int, int, int, float, float]:
    """The constants of a grid walk (Amanatides-Woo) along direction ``(dx, dy)``.

    Returns ``(stepx, stepy, offx, offy, invdx, invdy)``: the cell step along each axis
    (-1, 0 or 1), 1 where the next boundary is the cell's upper side (else 0), and the
    inverse components (0 for a zero component, whose boundaries are never reached).
    """
    stepx = 1 if dx > 0.0 else (-1 if dx < 0.0 else 0)
    stepy = 1 if dy > 0.0 else (-1 if dy < 0.0 else 0)
    offx = 1 if dx > 0.0 else 0
    offy = 1 if dy > 0.0 else 0
    invdx = 1.0 / dx if dx != 0.0 else 0.0
    invdy = 1.0 / dy if dy != 0.0 else 0.0
    return stepx, stepy, offx, offy, invdx, invdy


@_jit
def _fill_grid(
    segments: NDArray[np.float64],
    circles: NDArray[np.float64],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    pad: float,
) -> tuple[NDArray[np.int32], NDArray[np.int32]]:
    ns = segments.shape[0]
    nc = circles.shape[0]
    counts = np.zeros(nx * ny + 1, dtype=np.int64)
    items = np.zeros(0, dtype=np.int32)
    cursor = np.zeros(nx * ny, dtype=np.int64)
    half = 0.5 * cell + pad
    for fill in range(2):
        for k in range(ns + nc):
            if k < ns:
                x0 = segments[k, 0]
                y0 = segments[k, 1]
                x1 = segments[k, 2]
                y1 = segments[k, 3]
                r = 0.0
                lox = min(x0, x1)
                hix = max(x0, x1)
                loy = min(y0, y1)
                hiy = max(y0, y1)
            else:
                x0 = circles[k - ns, 0]
                y0 = circles[k - ns, 1]
                r = circles[k - ns, 2]
                x1 = 0.0
                y1 = 0.0
                lox = x0 - r
                hix = x0 + r
                loy = y0 - r
                hiy = y0 + r
            ia = min(max(int(math.floor((lox - pad - gx0) / cell)), 0), nx - 1)
            ib = min(max(int(math.floor((hix + pad - gx0) / cell)), 0), nx - 1)
            ja = min(max(int(math.floor((loy - pad - gy0) / cell)), 0), ny - 1)
            jb = min(max(int(math.floor((hiy + pad - gy0) / cell)), 0), ny - 1)
            for j in range(ja, jb + 1):
                bcy = gy0 + (j + 0.5) * cell
                for i in range(ia, ib + 1):
                    bcx = gx0 + (i + 0.5) * cell
                    if k < ns:
                        # separating axis along the segment's normal (the x and y axes
                        # are covered by the bounding-box range)
                        ex = x1 - x0
                        ey = y1 - y0
                        dist = abs(ex * (bcy - y0) - ey * (bcx - x0))
                        if dist > (abs(ex) + abs(ey)) * half:
                            continue
                    else:
                        qx = max(abs(bcx - x0) - half, 0.0)
                        qy = max(abs(bcy - y0) - half, 0.0)
                        if qx * qx + qy * qy > (r + pad) * (r + pad):
                            continue
                    c = j * nx + i
                    if fill == 0:
                        counts[c + 1] += 1
                    else:
                        items[cursor[c]] = k
                        cursor[c] += 1
        if fill == 0:
            for c in range(nx * ny):
                counts[c + 1] += counts[c]
            items = np.empty(counts[nx * ny], dtype=np.int32)
            cursor[:] = counts[: nx * ny]
    return counts.astype(np.int32), items


def _cell_size(bounds: tuple[float, float, float, float], n_primitives: int) -> float:
    xmin, ymin, xmax, ymax = bounds
    w = xmax - xmin
    h = ymax - ymin
    extent = max(w, h, 1e-3)
    if n_primitives <= 0:
        return extent
    area = max(w * h, extent * extent / _MAX_CELLS_PER_AXIS)
    cell = math.sqrt(area / (_CELLS_PER_PRIMITIVE * n_primitives))
    cell = max(cell, extent / _MAX_CELLS_PER_AXIS)
    while math.ceil(w / cell + 1) * math.ceil(h / cell + 1) > _MAX_CELLS:
        cell *= 1.25
    return cell


def build_grid(scene: Scene, *, cell_m: float | None = None) -> Grid:
    """Build the acceleration grid of ``scene``.

    Args:
        scene: the scene.
        cell_m: cell side in metres; by default chosen from the scene's extent and its
            number of primitives (about two cells per primitive, at most 1024 per axis).

    Returns:
        The grid (use :func:`scene_grid` to build it once per scene).

    Raises:
        RaycastInputError: ``cell_m`` not positive and finite.
    """
    bounds = scene.bounds
    n = len(scene.segments) + len(scene.circles)
    cell = float(cell_m) if cell_m is not None else _cell_size(bounds, n)
    if not (math.isfinite(cell) and cell > 0.0):
        raise RaycastInputError(f"grid cell size must be positive and finite, got {cell}")
    xmin, ymin, xmax, ymax = bounds
    margin = 0.01 * cell
    nx = max(1, math.ceil((xmax - xmin + 2 * margin) / cell))
    ny = max(1, math.ceil((ymax - ymin + 2 * margin) / cell))
    gx0 = xmin - 0.5 * (nx * cell - (xmax - xmin))
    gy0 = ymin - 0.5 * (ny * cell - (ymax - ymin))
    pad = _PAD_REL * cell + 1e-12 * max(abs(gx0), abs(gy0), 1.0)
    cell_start, items = _fill_grid(scene.segments, scene.circles, gx0, gy0, cell, nx, ny, pad)
    return Grid(
        x0=float(gx0),
        y0=float(gy0),
        cell=cell,
        nx=int(nx),
        ny=int(ny),
        cell_start=cell_start,
        items=items,
        n_segments=len(scene.segments),
    )


def scene_grid(scene: Scene, *, cell_m: float | None = None) -> Grid:
    """The grid of ``scene``, built on first use and cached on the scene object.

    Args:
        scene: the scene.
        cell_m: rebuild (and cache) the grid with this cell size if the cached one has
            another; by default keep whatever is cached, or build with the automatic size.

    The cache is rebuilt when ``scene.segments`` or ``scene.circles`` is replaced by
    another array; a Scene's arrays must not be modified in place after first use.
    """
    cached = scene.__dict__.get(_CACHE_ATTR)
    if cached is not None:
        segments, circles, grid = cached
        if (
            segments is scene.segments
            and circles is scene.circles
            and (cell_m is None or grid.cell == float(cell_m))
        ):
            return grid
    grid = build_grid(scene, cell_m=cell_m)
    scene.__dict__[_CACHE_ATTR] = (scene.segments, scene.circles, grid)
    return grid
