"""The compiled kernels of Karto's correlative scan matcher (:mod:`roverlab.slam.graph.matcher`).

Numba functions on plain arrays: stamping the smear kernel and its block-max companion into
a correlation grid (:func:`_splat`), the branch-and-bound search over the coarse lattice
(:func:`_bnb_search`), the responses of a small lattice of poses (:func:`_lattice_responses`,
for the fine heading search and the covariance), the sub-cell Gauss-Newton step on the
bilinearly interpolated grid (:func:`_refine`), and Karto's ``FindValidPoints`` mask
(:func:`_valid_mask`). The grid layout, the response and the penalty are described in
:mod:`roverlab.slam.graph.matcher`, which holds the Python API around them.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
_jit = numba.njit(cache=True, nogil=True)

#: Karto's ``DISTANCE_PENALTY_GAIN`` and ``ANGLE_PENALTY_GAIN``.
_PENALTY_GAIN = 0.2
#: Karto's ``GridStates_Occupied``: the value of a cell a point falls in.
_OCCUPIED = 100.0


@_jit
def _max_stamp(grid: NDArray[np.uint8], kernel: NDArray[np.uint8], x0: int, y0: int) -> None:
    """``grid = max(grid, kernel)`` over the kernel placed with its corner at ``(x0, y0)``
    (clipped to the grid)."""
    h, w = grid.shape
    k = kernel.shape[0]
    for a in range(k):
        y = y0 + a
        if y < 0 or y >= h:
            continue
        for b in range(k):
            x = x0 + b
            if 0 <= x < w:
                v = kernel[a, b]
                if v > grid[y, x]:
                    grid[y, x] = v


@_jit
def _splat(
    data: NDArray[np.uint8],
    pool: NDArray[np.uint8],
    ix: NDArray[np.int64],
    iy: NDArray[np.int64],
    kernel: NDArray[np.uint8],
    pkernel: NDArray[np.uint8],
    half: int,
    block: int,
) -> None:
    """Max-splat the smear kernel (into ``data``) and the pooled kernel (into ``pool``)."""
    for n in range(ix.shape[0]):
        _max_stamp(data, kernel, ix[n] - half, iy[n] - half)
        _max_stamp(pool, pkernel, ix[n] - half - block + 1, iy[n] - half - block + 1)


@_jit
def _base_cells(
    px: FloatArray,
    py: FloatArray,
    cx: float,
    cy: float,
    heading: float,
    ox: float,
    oy: float,
    res: float,
    bx: NDArray[np.int64],
    by: NDArray[np.int64],
) -> None:
    c = math.cos(heading)
    s = math.sin(heading)
    for i in range(px.shape[0]):
        bx[i] = int(math.floor((cx + c * px[i] - s * py[i] - ox) / res))
        by[i] = int(math.floor((cy + s * px[i] + c * py[i] - oy) / res))


@_jit
def _sum_at(
    grid: NDArray[np.uint8], bx: NDArray[np.int64], by: NDArray[np.int64], dx: int, dy: int
) -> float:
    h, w = grid.shape
    total = 0
    for i in range(bx.shape[0]):
        x = bx[i] + dx
        y = by[i] + dy
        if 0 <= x < w and 0 <= y < h:
            total += grid[y, x]
    return float(total)


@_jit
def _penalty(d2: float, variance: float, floor: float) -> float:
    p = 1.0 - _PENALTY_GAIN * d2 / variance
    return p if p > floor else floor


@_jit
def _bnb_search(
    data: NDArray[np.uint8],
    pool: NDArray[np.uint8],
    block: int,
    ox: float,
    oy: float,
    res: float,
    px: FloatArray,
    py: FloatArray,
    cx: float,
    cy: float,
    cth: float,
    angles: FloatArray,
    n: int,
    penalise: bool,
    dist_var: float,
    ang_var: float,
    min_dist_pen: float,
    min_ang_pen: float,
) -> tuple[int, int, int, float]:
    """Best ``(dx, dy, angle index, response)`` over the lattice ``[-n, n]^2 x angles``."""
    npts = px.shape[0]
    na = angles.shape[0]
    bx = np.empty((na, npts), dtype=np.int64)
    by = np.empty((na, npts), dtype=np.int64)
    for a in range(na):
        _base_cells(px, py, cx, cy, cth + angles[a], ox, oy, res, bx[a], by[a])
    nb = (2 * n + block) // block
    total = na * nb * nb
    bound = np.empty(total)
    norm = 1.0 / (_OCCUPIED * npts)
    r2 = res * res
    k = 0
    for a in range(na):
        pa = _penalty(angles[a] * angles[a], ang_var, min_ang_pen) if penalise else 1.0
        for ky in range(nb):
            y0 = -n + ky * block
            y1 = min(y0 + block - 1, n)
            my = 0 if y0 <= 0 <= y1 else min(abs(y0), abs(y1))
            for kx in range(nb):
                x0 = -n + kx * block
                x1 = min(x0 + block - 1, n)
                mx = 0 if x0 <= 0 <= x1 else min(abs(x0), abs(x1))
                pd = _penalty((mx * mx + my * my) * r2, dist_var, min_dist_pen) if penalise else 1.0
                bound[k] = _sum_at(pool, bx[a], by[a], x0, y0) * norm * pa * pd
                k += 1
    order = np.argsort(-bound)
    best = -1.0
    bdx = 0
    bdy = 0
    ba = 0
    for o in range(total):
        k = order[o]
        if bound[k] <= best:
            break
        a = k // (nb * nb)
        rem = k - a * nb * nb
        ky = rem // nb
        kx = rem - ky * nb
        pa = _penalty(angles[a] * angles[a], ang_var, min_ang_pen) if penalise else 1.0
        y0 = -n + ky * block
        x0 = -n + kx * block
        for dy in range(y0, min(y0 + block - 1, n) + 1):
            for dx in range(x0, min(x0 + block - 1, n) + 1):
                pd = _penalty((dx * dx + dy * dy) * r2, dist_var, min_dist_pen) if penalise else 1.0
                score = _sum_at(data, bx[a], by[a], dx, dy) * norm * pa * pd
                if score > best:
                    best = score
                    bdx = dx
                    bdy = dy
                    ba = a
    return bdx, bdy, ba, best


@_jit
def _lattice_responses(
    data: NDArray[np.uint8],
    ox: float,
    oy: float,
    res: float,
    px: FloatArray,
    py: FloatArray,
    cx: float,
    cy: float,
    headings: FloatArray,
    m: int,
    penalise: bool,
    pcx: float,
    pcy: float,
    pth: float,
    dist_var: float,
    ang_var: float,
    min_dist_pen: float,
    min_ang_pen: float,
) -> FloatArray:
    """Responses ``(headings, 2m+1, 2m+1)`` of the poses ``(cx + dx res, cy + dy res, h)``;
    the penalty (if any) is taken relative to the prediction ``(pcx, pcy, pth)``."""
    npts = px.shape[0]
    na = headings.shape[0]
    out = np.zeros((na, 2 * m + 1, 2 * m + 1))
    bx = np.empty(npts, dtype=np.int64)
    by = np.empty(npts, dtype=np.int64)
    norm = 1.0 / (_OCCUPIED * npts)
    for a in range(na):
        _base_cells(px, py, cx, cy, headings[a], ox, oy, res, bx, by)
        da = headings[a] - pth
        da = (da + math.pi) % (2.0 * math.pi) - math.pi
        pa = _penalty(da * da, ang_var, min_ang_pen) if penalise else 1.0
        for dy in range(-m, m + 1):
            for dx in range(-m, m + 1):
                pd = 1.0
                if penalise:
                    ex = cx + dx * res - pcx
                    ey = cy + dy * res - pcy
                    pd = _penalty(ex * ex + ey * ey, dist_var, min_dist_pen)
                out[a, dy + m, dx + m] = _sum_at(data, bx, by, dx, dy) * norm * pa * pd
    return out


@_jit
def _bilinear(data: NDArray[np.uint8], gx: float, gy: float) -> tuple[float, float, float]:
    """Value (0..1) and gradient (per cell) of the grid at cell coordinates ``(gx, gy)``,
    cell centres at integer + 0.5."""
    h, w = data.shape
    x = gx - 0.5
    y = gy - 0.5
    x0 = int(math.floor(x))
    y0 = int(math.floor(y))
    if x0 < 0 or y0 < 0 or x0 + 1 >= w or y0 + 1 >= h:
        return 0.0, 0.0, 0.0
    fx = x - x0
    fy = y - y0
    v00 = data[y0, x0] / _OCCUPIED
    v10 = data[y0, x0 + 1] / _OCCUPIED
    v01 = data[y0 + 1, x0] / _OCCUPIED
    v11 = data[y0 + 1, x0 + 1] / _OCCUPIED
    v = (v00 * (1 - fx) + v10 * fx) * (1 - fy) + (v01 * (1 - fx) + v11 * fx) * fy
    dvx = (v10 - v00) * (1 - fy) + (v11 - v01) * fy
    dvy = (v01 - v00) * (1 - fx) + (v11 - v10) * fx
    return v, dvx, dvy


@_jit
def _interp_score(
    data: NDArray[np.uint8],
    ox: float,
    oy: float,
    res: float,
    px: FloatArray,
    py: FloatArray,
    x: float,
    y: float,
    th: float,
) -> float:
    c = math.cos(th)
    s = math.sin(th)
    total = 0.0
    for i in range(px.shape[0]):
        gx = (x + c * px[i] - s * py[i] - ox) / res
        gy = (y + s * px[i] + c * py[i] - oy) / res
        v, _, _ = _bilinear(data, gx, gy)
        total += v
    return total


@_jit
def _refine(
    data: NDArray[np.uint8],
    ox: float,
    oy: float,
    res: float,
    px: FloatArray,
    py: FloatArray,
    x: float,
    y: float,
    th: float,
    max_shift: float,
    max_turn: float,
    iterations: int,
) -> tuple[float, float, float]:
    """Gauss-Newton on ``sum (1 - M(T p))^2`` (M bilinear), each step kept only if it
    raises the interpolated score; the result stays within ``max_shift`` / ``max_turn``
    of the start."""
    x_start = x
    y_start = y
    th_start = th
    best = _interp_score(data, ox, oy, res, px, py, x, y, th)
    for _ in range(iterations):
        c = math.cos(th)
        s = math.sin(th)
        h00 = h01 = h02 = h11 = h12 = h22 = 0.0
        g0 = g1 = g2 = 0.0
        for i in range(px.shape[0]):
            gx = (x + c * px[i] - s * py[i] - ox) / res
            gy = (y + s * px[i] + c * py[i] - oy) / res
            v, dvx, dvy = _bilinear(data, gx, gy)
            if dvx == 0.0 and dvy == 0.0:
                continue
            dvx /= res
            dvy /= res
            jt = dvx * (-s * px[i] - c * py[i]) + dvy * (c * px[i] - s * py[i])
            r = 1.0 - v
            h00 += dvx * dvx
            h01 += dvx * dvy
            h02 += dvx * jt
            h11 += dvy * dvy
            h12 += dvy * jt
            h22 += jt * jt
            g0 += dvx * r
            g1 += dvy * r
            g2 += jt * r
        # solve the 3x3 system H d = g (Cramer's rule on the symmetric matrix)
        det = (
            h00 * (h11 * h22 - h12 * h12)
            - h01 * (h01 * h22 - h12 * h02)
            + h02 * (h01 * h12 - h11 * h02)
        )
        if not abs(det) > 1e-12:
            break
        d0 = (
            g0 * (h11 * h22 - h12 * h12) - h01 * (g1 * h22 - h12 * g2) + h02 * (g1 * h12 - h11 * g2)
        ) / det
        d1 = (
            h00 * (g1 * h22 - h12 * g2) - g0 * (h01 * h22 - h12 * h02) + h02 * (h01 * g2 - g1 * h02)
        ) / det
        d2 = (
            h00 * (h11 * g2 - g1 * h12) - h01 * (h01 * g2 - g1 * h02) + g0 * (h01 * h12 - h11 * h02)
        ) / det
        nx = min(max(x + d0, x_start - max_shift), x_start + max_shift)
        ny = min(max(y + d1, y_start - max_shift), y_start + max_shift)
        nth = min(max(th + d2, th_start - max_turn), th_start + max_turn)
        score = _interp_score(data, ox, oy, res, px, py, nx, ny, nth)
        if score <= best:
            break
        step = abs(nx - x) + abs(ny - y) + abs(nth - th)
        best = score
        x = nx
        y = ny
        th = nth
        if step < 1e-5:
            break
    return x, y, th


@_jit
def _valid_mask(
    wx: FloatArray, wy: FloatArray, vx: float, vy: float, min_d2: float
) -> NDArray[np.bool_]:
    """Karto's ``FindValidPoints``: keep runs of points that turn counter-clockwise as seen
    from the viewpoint ``(vx, vy)`` (the sensor that will be matched against them)."""
    n = wx.shape[0]
    keep = np.zeros(n, dtype=np.bool_)
    if n == 0:
        return keep
    fx = wx[0]
    fy = wy[0]
    trailing = 0
    for i in range(n):
        dx = fx - wx[i]
        dy = fy - wy[i]
        if dx * dx + dy * dy > min_d2:
            a = vy - fy
            b = fx - vx
            c = fy * vx - fx * vy
            ss = wx[i] * a + wy[i] * b + c
            fx = wx[i]
            fy = wy[i]
            if ss < 0.0:
                trailing = i
            else:
                for j in range(trailing, i + 1):
                    keep[j] = True
                trailing = i + 1
    return keep
