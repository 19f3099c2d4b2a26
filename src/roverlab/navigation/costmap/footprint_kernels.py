"""Compiled footprint kernels: base_local_planner's ``footprintCost`` (CostmapModel's
outline rasterisation), the cells it reads, and the exact outline cells.

Grids and cells as in :mod:`.kernels`.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.maps.raytrace import trace_segment_cells
from roverlab.navigation.costmap.kernels import INSCRIBED, LETHAL, NO_INFO, line_cost

__all__ = ["cells_cost", "footprint_cells", "footprint_cost", "outline_cells"]

_jit = numba.njit(cache=True, nogil=True)


@_jit
def footprint_cells(
    w: int,
    h: int,
    res: float,
    ox: float,
    oy: float,
    x: float,
    y: float,
    c: float,
    s: float,
    fp: NDArray[np.float64],
    scale: float,
    out: NDArray[np.int64],
) -> bool:
    """The cells :func:`footprint_cost` reads at ``(x, y, th)`` (``c``, ``s``: ``cos th``,
    ``sin th``): ``out[0]`` the centre's
    ``(mx, my)``, ``out[1 + k]`` vertex ``k``'s (of ``fp`` scaled by ``scale``; none
    when ``fp`` has fewer than 3 points). False (``out`` partly written) when the centre
    or a vertex is off the ``w`` x ``h`` grid. The cost depends on these cells only, so
    two poses with the same cells cost the same."""
    if x < ox or y < oy:
        return False
    cx = int((x - ox) / res)
    cy = int((y - oy) / res)
    if cx >= w or cy >= h:
        return False
    out[0, 0] = cx
    out[0, 1] = cy
    m = fp.shape[0]
    if m < 3:
        return True
    for k in range(m):
        wx = x + scale * (fp[k, 0] * c - fp[k, 1] * s)
        wy = y + scale * (fp[k, 0] * s + fp[k, 1] * c)
        if wx < ox or wy < oy:
            return False
        mx = int((wx - ox) / res)
        my = int((wy - oy) / res)
        if mx >= w or my >= h:
            return False
        out[k + 1, 0] = mx
        out[k + 1, 1] = my
    return True


@_jit
def cells_cost(
    costs: NDArray[np.uint8], cells: NDArray[np.int64], m: int, buf: NDArray[np.int64]
) -> float:
    """:func:`footprint_cost` from :func:`footprint_cells`' cells of an ``m``-point
    footprint (all on the grid): the highest cost on the outline's Bresenham lines (vertex
    ``k`` to ``k + 1``, the last edge back to vertex 0) and the centre cell, -6 at a lethal
    or unknown cell; for ``m < 3`` the centre's cost, -6 from inscribed up."""
    center = costs[cells[0, 1], cells[0, 0]]
    if m < 3:
        if center in (LETHAL, INSCRIBED, NO_INFO):
            return -6.0
        return float(center)
    best = 0.0
    for k in range(1, m + 1):  # the edge from vertex k - 1 (row k) to vertex k % m
        b = k % m + 1
        lc = line_cost(costs, cells[k, 0], cells[k, 1], cells[b, 0], cells[b, 1], buf)
        if lc < 0:
            return -6.0
        best = max(best, lc)
    return max(best, float(center))


@_jit
def footprint_cost(
    costs: NDArray[np.uint8],
    res: float,
    ox: float,
    oy: float,
    x: float,
    y: float,
    th: float,
    fp: NDArray[np.float64],
    scale: float,
    buf: NDArray[np.int64],
) -> float:
    """base_local_planner's ``footprintCost`` at ``(x, y, th)`` (CostmapModel's edge
    rasterisation of the footprint ``fp`` scaled by ``scale``): the highest cost on its
    outline (and its centre cell), or -6 when a cell is lethal or unknown or the footprint
    leaves the grid. ``buf`` is scratch space for the Bresenham cells."""
    h, w = costs.shape
    cells = np.empty((fp.shape[0] + 1, 2), dtype=np.int64)
    if not footprint_cells(w, h, res, ox, oy, x, y, math.cos(th), math.sin(th), fp, scale, cells):
        return -6.0
    return cells_cost(costs, cells, fp.shape[0], buf)


@_jit
def outline_cells(
    w: int,
    h: int,
    res: float,
    ox: float,
    oy: float,
    x: float,
    y: float,
    th: float,
    fp: NDArray[np.float64],
    out: NDArray[np.int64],
) -> int:
    """Every cell (flat index ``my * w + mx``) that the outline of the polygon ``fp`` at
    ``(x, y, th)`` crosses, from the vertices' true positions (roverlab's exact grid
    tracer, clipped to the grid), written to ``out`` (room for ``2 * (w + h)`` per edge);
    returns the count (cells shared by two edges appear twice)."""
    c = math.cos(th)
    s = math.sin(th)
    m = fp.shape[0]
    n = 0
    gx0 = 0.0
    gy0 = 0.0
    for k in range(m + 1):
        j = k % m
        gx = (x + fp[j, 0] * c - fp[j, 1] * s - ox) / res
        gy = (y + fp[j, 0] * s + fp[j, 1] * c - oy) / res
        if k > 0:
            n += trace_segment_cells(gx0, gy0, gx, gy, w, h, out[n:])
        gx0 = gx
        gy0 = gy
    return n
