"""The compiled ray tracer and scan-integration kernels of :mod:`roverlab.maps.grid`.

A beam marks exactly the cells its segment crosses (Amanatides-Woo DDA, every crossing
parameter computed from the start point, so there is no drift); a segment through a cell
corner also visits the side cell it reaches first along x. Cell units throughout: cell
``(ix, iy)`` covers ``[ix, ix + 1) x [iy, iy + 1)`` and has the flat index ``iy * w + ix``.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["integrate_counts", "integrate_log_odds", "trace_cells", "trace_segment_cells"]

_jit = numba.njit(cache=True, nogil=True)


@_jit
def _clip(p: float, q: float, t0: float, t1: float) -> tuple[float, float]:
    """One Liang-Barsky edge ``p * t <= q`` applied to the interval ``[t0, t1]``."""
    if p == 0.0:
        if q < 0.0:
            return 1.0, 0.0
        return t0, t1
    r = q / p
    if p < 0.0:
        if r > t0:
            t0 = r
    elif r < t1:
        t1 = r
    return t0, t1


@_jit
def _trace(
    gx0: float, gy0: float, gx1: float, gy1: float, w: int, h: int, out: NDArray[np.int64]
) -> int:
    """Write the flat indices ``iy * w + ix`` of the cells of ``[0, w) x [0, h)`` (cell
    units) that the segment ``g0 -> g1`` crosses, in order from ``g0``; return their count."""
    dx = gx1 - gx0
    dy = gy1 - gy0
    t0, t1 = _clip(-dx, gx0, 0.0, 1.0)
    t0, t1 = _clip(dx, w - gx0, t0, t1)
    t0, t1 = _clip(-dy, gy0, t0, t1)
    t0, t1 = _clip(dy, h - gy0, t0, t1)
    if t0 > t1:
        return 0
    ix = min(max(int(math.floor(gx0 + t0 * dx)), 0), w - 1)
    iy = min(max(int(math.floor(gy0 + t0 * dy)), 0), h - 1)
    stepx = 1 if dx > 0.0 else (-1 if dx < 0.0 else 0)
    stepy = 1 if dy > 0.0 else (-1 if dy < 0.0 else 0)
    offx = 1 if dx > 0.0 else 0
    offy = 1 if dy > 0.0 else 0
    cap = out.shape[0]
    n = 0
    # the parameter of the next x / y cell border; each is recomputed (by the same
    # expression) only when its cell index changed
    tx = (ix + offx - gx0) / dx if stepx != 0 else math.inf
    ty = (iy + offy - gy0) / dy if stepy != 0 else math.inf
    while n < cap:
        out[n] = iy * w + ix
        n += 1
        if tx <= ty:
            if tx >= t1:
                break
            ix += stepx
            if ix < 0 or ix >= w:
                break
            tx = (ix + offx - gx0) / dx
        else:
            if ty >= t1:
                break
            iy += stepy
            if iy < 0 or iy >= h:
                break
            ty = (iy + offy - gy0) / dy
    return n


#: The compiled tracer itself, for other compiled kernels (the costmap's obstacle-layer
#: clearing): ``trace_segment_cells(gx0, gy0, gx1, gy1, w, h, out) -> n`` writes the flat
#: indices ``iy * w + ix`` of the cells the segment crosses (cell units, clipped to the grid).
trace_segment_cells = _trace


@_jit
def integrate_log_odds(
    lo: NDArray[np.float32],
    mark: NDArray[np.uint8],
    gx0: float,
    gy0: float,
    gxe: NDArray[np.float64],
    gye: NDArray[np.float64],
    hit: NDArray[np.bool_],
    w: int,
    h: int,
    l_occ: float,
    l_free: float,
    l_min: float,
    l_max: float,
    touched: NDArray[np.int64],
    buf: NDArray[np.int64],
) -> int:
    """Update each touched cell once (hits first); return how many cells changed."""
    nt = 0
    cap = touched.shape[0]
    nb = gxe.shape[0]
    for b in range(nb):
        if not hit[b]:
            continue
        ix = int(math.floor(gxe[b]))
        iy = int(math.floor(gye[b]))
        if ix < 0 or ix >= w or iy < 0 or iy >= h:
            continue
        c = iy * w + ix
        if mark[c] == 0 and nt < cap:
            mark[c] = 1
            touched[nt] = c
            nt += 1
            lo[c] = min(max(lo[c] + l_occ, l_min), l_max)
    for b in range(nb):
        k = _trace(gx0, gy0, gxe[b], gye[b], w, h, buf)
        for j in range(k):
            c = buf[j]
            if mark[c] == 0 and nt < cap:
                mark[c] = 1
                touched[nt] = c
                nt += 1
                lo[c] = min(max(lo[c] + l_free, l_min), l_max)
    for j in range(nt):
        mark[touched[j]] = 0
    return nt


@_jit
def integrate_counts(
    hits: NDArray[np.int32],
    visits: NDArray[np.int32],
    gx0: float,
    gy0: float,
    gxe: NDArray[np.float64],
    gye: NDArray[np.float64],
    hit: NDArray[np.bool_],
    w: int,
    h: int,
    buf: NDArray[np.int64],
) -> None:
    """Per beam: visit every crossed cell once, and hit (and visit) the end cell."""
    for b in range(gxe.shape[0]):
        end = -1
        if hit[b]:
            ix = int(math.floor(gxe[b]))
            iy = int(math.floor(gye[b]))
            if 0 <= ix < w and 0 <= iy < h:
                end = iy * w + ix
                hits[end] += 1
                visits[end] += 1
        k = _trace(gx0, gy0, gxe[b], gye[b], w, h, buf)
        for j in range(k):
            c = buf[j]
            if c != end:
                visits[c] += 1


def trace_cells(
    start_xy: tuple[float, float],
    end_xy: tuple[float, float],
    *,
    resolution: float,
    origin_xy: tuple[float, float],
    width: int,
    height: int,
) -> NDArray[np.int64]:
    """The cells a segment crosses, in order, as an ``(N, 2)`` array of ``(ix, iy)``.

    The tracer the grids use, for tests and tools; cells outside the grid are left out.
    """
    res = float(resolution)
    ox, oy = float(origin_xy[0]), float(origin_xy[1])
    buf = np.empty(int(width) + int(height) + 2, dtype=np.int64)
    n = _trace(
        (float(start_xy[0]) - ox) / res,
        (float(start_xy[1]) - oy) / res,
        (float(end_xy[0]) - ox) / res,
        (float(end_xy[1]) - oy) / res,
        int(width),
        int(height),
        buf,
    )
    flat = buf[:n]
    return np.stack([flat % int(width), flat // int(width)], axis=1)
