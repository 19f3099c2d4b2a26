"""Karto's correlative scan matcher, searched by branch and bound, with compiled kernels.

Karto (and slam_toolbox, which inherits its matcher) scores a candidate pose of a scan by
looking up its points in a *correlation grid*: every point of the reference scans marks its
cell with 100 and its neighbours with a Gaussian "smear" ``100 exp(-d^2 / 2 sigma^2)``
(``sigma`` = ``*_smear_deviation``, kernel half-width ``round(2 sigma / resolution)``
cells). The *response* of a pose is the sum of the grid values under the scan's points,
divided by ``100 * points``, in ``[0, 1]``. The sequential matcher multiplies it by a
penalty for straying from the odometry prediction,
``max(1 - 0.2 d^2 / distance_variance_penalty, minimum_distance_penalty)`` times the same
for the heading; the loop matcher does not penalise.

Karto searches a lattice exhaustively (every cell of the search square at every coarse
heading), then refines the heading around the best at ``fine_search_angle_offset`` steps.
Here the coarse lattice search gives the same maximum by branch and bound (the multi-
resolution idea of Olson's correlative matcher and of Cartographer): a second grid holds,
per cell, the maximum of the ``B x B`` block of cells above and right of it, so one lookup
per point bounds the score of all ``B^2`` translations of a block; blocks are visited best
bound first and skipped once their bound cannot beat the best pose found. The pooled grid
is splatted point by point with a pooled kernel, never computed by a pass over the grid.

The covariance follows Karto's ``ComputePositionalCovariance`` /
``ComputeAngularCovariance``: the response-weighted spread of the lattice poses whose
response is within 0.1 of the best (positions at the best heading, headings at the best
position), floored at ``0.1 resolution^2`` and divided by the best response. An optional
sub-cell Gauss-Newton step on the bilinearly interpolated grid (as hector_mapping matches)
then removes the lattice quantisation.

Karto's ``FindValidPoints`` (points of a reference scan seen from the back, through a thin
wall, are dropped) is :func:`valid_points`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "CorrelationGrid",
    "MatchResult",
    "Penalty",
    "block_size",
    "build_grid",
    "match_scan",
    "response",
    "valid_points",
]

FloatArray = NDArray[np.float64]
_jit = numba.njit(cache=True, nogil=True)

#: Karto's ``DISTANCE_PENALTY_GAIN`` and ``ANGLE_PENALTY_GAIN``.
_PENALTY_GAIN = 0.2
#: Karto's ``GridStates_Occupied``: the value of a cell a point falls in.
_OCCUPIED = 100.0
#: Karto's ``MAX_VARIANCE``: the variance reported when no pose had a response.
_MAX_VARIANCE = 500.0
#: Karto's ``FindValidPoints`` minimum spacing of the points it compares (m).
_VALID_POINT_SPACING = 0.1


# --------------------------------------------------------------------------------- kernels


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


# --------------------------------------------------------------------------------- API


def valid_points(world_points: FloatArray, viewpoint: tuple[float, float]) -> FloatArray:
    """The points (``(N, 2)``, in beam order, world frame) that face ``viewpoint``
    (Karto's ``FindValidPoints``)."""
    pts = np.ascontiguousarray(world_points, dtype=np.float64).reshape(-1, 2)
    keep = _valid_mask(
        np.ascontiguousarray(pts[:, 0]),
        np.ascontiguousarray(pts[:, 1]),
        float(viewpoint[0]),
        float(viewpoint[1]),
        _VALID_POINT_SPACING**2,
    )
    return pts[keep]


def block_size(half_cells: int) -> int:
    """Branch-and-bound block side for a search of ``[-half, half]`` cells: about
    ``sqrt(2 half + 1)``, so that bounds and expansions cost about the same."""
    return int(min(16, max(2, round(math.sqrt(2 * half_cells + 1)))))


@dataclass(frozen=True, eq=False)
class CorrelationGrid:
    """A smeared correlation grid and its block-max companion.

    Attributes:
        data: ``(H, W)`` uint8, 0..100: cell ``[iy, ix]`` covers
            ``x in ox + [ix, ix + 1) res``, ``y in oy + [iy, iy + 1) res``.
        pool: ``(H, W)`` uint8, ``pool[iy, ix] = max data[iy:iy+B, ix:ix+B]``.
        block: ``B``.
        origin: ``(ox, oy)``, m.
        resolution: cell side, m.
    """

    data: NDArray[np.uint8]
    pool: NDArray[np.uint8]
    block: int
    origin: tuple[float, float]
    resolution: float


def _kernels(
    smear: float, res: float, block: int
) -> tuple[NDArray[np.uint8], NDArray[np.uint8], int]:
    half = round(2.0 * smear / res)
    offs = np.arange(-half, half + 1) * res
    d2 = offs[None, :] ** 2 + offs[:, None] ** 2
    kernel = np.round(np.exp(-0.5 * d2 / (smear * smear)) * _OCCUPIED).astype(np.uint8)
    kernel[half, half] = int(_OCCUPIED)
    k = kernel.shape[0]
    padded = np.zeros((k + 2 * (block - 1), k + 2 * (block - 1)), dtype=np.uint8)
    padded[block - 1 : block - 1 + k, block - 1 : block - 1 + k] = kernel
    # pkernel[a, b] = max kernel[a-B+1 .. a, b-B+1 .. b] (window ending at a, b)
    pk = k + block - 1
    pkernel = np.zeros((pk, pk), dtype=np.uint8)
    for u in range(block):
        for v in range(block):
            np.maximum(pkernel, padded[u : u + pk, v : v + pk], out=pkernel)
    return kernel, pkernel, half


def build_grid(
    points: FloatArray,
    *,
    resolution: float,
    smear_deviation: float,
    block: int,
    bounds: tuple[float, float, float, float] | None = None,
) -> CorrelationGrid:
    """Smear world points into a :class:`CorrelationGrid`.

    Args:
        points: ``(N, 2)`` world points, m.
        resolution: cell side, m.
        smear_deviation: Gaussian smear, m.
        block: branch-and-bound block side, cells.
        bounds: ``(xmin, ymin, xmax, ymax)``: points outside are dropped and the grid
            covers at most this box (default: the points' bounding box).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if bounds is not None:
        inside = (
            (pts[:, 0] >= bounds[0])
            & (pts[:, 0] <= bounds[2])
            & (pts[:, 1] >= bounds[1])
            & (pts[:, 1] <= bounds[3])
        )
        pts = pts[inside]
    kernel, pkernel, half = _kernels(smear_deviation, resolution, block)
    if pts.shape[0] == 0:
        empty = np.zeros((1, 1), dtype=np.uint8)
        return CorrelationGrid(empty, empty.copy(), block, (0.0, 0.0), resolution)
    pad = (half + block + 2) * resolution
    x0 = math.floor((float(pts[:, 0].min()) - pad) / resolution) * resolution
    y0 = math.floor((float(pts[:, 1].min()) - pad) / resolution) * resolution
    w = int(math.ceil((float(pts[:, 0].max()) + pad - x0) / resolution)) + 1
    h = int(math.ceil((float(pts[:, 1].max()) + pad - y0) / resolution)) + 1
    data = np.zeros((h, w), dtype=np.uint8)
    pool = np.zeros((h, w), dtype=np.uint8)
    ix = np.floor((pts[:, 0] - x0) / resolution).astype(np.int64)
    iy = np.floor((pts[:, 1] - y0) / resolution).astype(np.int64)
    _splat(data, pool, ix, iy, kernel, pkernel, half, block)
    return CorrelationGrid(data, pool, block, (x0, y0), resolution)


@dataclass(frozen=True)
class Penalty:
    """The sequential matcher's odometry penalty (Karto's scan-matcher parameters)."""

    distance_variance: float
    angle_variance: float
    minimum_distance: float
    minimum_angle: float


class MatchResult(NamedTuple):
    """A match: the pose ``(x, y, theta)``, the lattice response, Karto's covariance."""

    pose: FloatArray
    response: float
    covariance: FloatArray


def _angle_set(offset: float, step: float) -> FloatArray:
    k = int(math.floor(offset / step + 1e-9))
    return np.arange(-k, k + 1, dtype=np.float64) * step


def response(grid: CorrelationGrid, points: FloatArray, pose: FloatArray) -> float:
    """Karto's response of one pose (no penalty)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if pts.shape[0] == 0:
        return 0.0
    out = _lattice_responses(
        grid.data, grid.origin[0], grid.origin[1], grid.resolution,
        np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]),
        float(pose[0]), float(pose[1]), np.array([float(pose[2])]), 0,
        False, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0,
    )  # fmt: skip
    return float(out[0, 0, 0])


def match_scan(
    grid: CorrelationGrid,
    points: FloatArray,
    prediction: FloatArray,
    *,
    search_dimension: float,
    coarse_angle_offset: float,
    coarse_angle_resolution: float,
    fine_angle_offset: float,
    penalty: Penalty | None,
    refine_angle: bool,
    subcell: bool,
    covariance: bool,
    response_expansion: bool,
) -> MatchResult:
    """Karto's ``ScanMatcher::MatchScan`` on a prepared grid.

    Args:
        grid: the correlation grid of the reference scans.
        points: ``(N, 2)`` points of the scan in the robot frame, m.
        prediction: ``(x, y, theta)`` search centre (and penalty reference).
        search_dimension: side of the searched square, m (step: the grid's resolution).
        coarse_angle_offset: half-width of the heading search, rad.
        coarse_angle_resolution: its step, rad.
        fine_angle_offset: step of the fine heading search (``refine_angle``), rad.
        penalty: the odometry penalty, or None (loop matching).
        refine_angle: Karto's ``doRefineMatch``: search the heading again in
            ``+- coarse_angle_resolution / 2`` at ``fine_angle_offset`` steps (and one cell
            around the best position), and take the angular variance from that search.
        subcell: finish with a sub-cell Gauss-Newton step.
        covariance: compute Karto's covariance (else a fixed placeholder of
            ``MAX_VARIANCE``).
        response_expansion: slam_toolbox's ``use_response_expansion``: with no response
            at all, widen the heading search by 20 degrees, up to three times.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    pred = np.asarray(prediction, dtype=np.float64).reshape(3)
    cov = np.diag([_MAX_VARIANCE, _MAX_VARIANCE, _MAX_VARIANCE])
    if pts.shape[0] == 0:
        return MatchResult(pred.copy(), 0.0, cov)
    px = np.ascontiguousarray(pts[:, 0])
    py = np.ascontiguousarray(pts[:, 1])
    res = grid.resolution
    ox, oy = grid.origin
    n = int(math.floor(0.5 * search_dimension / res + 1e-9))
    pen = penalty if penalty is not None else Penalty(1.0, 1.0, 0.0, 0.0)
    pflag = penalty is not None
    offset = coarse_angle_offset
    for attempt in range(4 if response_expansion else 1):
        angles = _angle_set(offset, coarse_angle_resolution)
        dx, dy, ia, best = _bnb_search(
            grid.data, grid.pool, grid.block, ox, oy, res, px, py,
            float(pred[0]), float(pred[1]), float(pred[2]), angles, n,
            pflag, pen.distance_variance, pen.angle_variance,
            pen.minimum_distance, pen.minimum_angle,
        )  # fmt: skip
        if best > 0.0 or attempt == 3:
            break
        offset += math.radians(20.0)
    if best <= 0.0:
        return MatchResult(pred.copy(), 0.0, cov)
    x = float(pred[0]) + dx * res
    y = float(pred[1]) + dy * res
    th = float(pred[2]) + float(angles[ia])
    ang_step = coarse_angle_resolution

    if refine_angle:
        fine = (
            float(pred[2])
            + float(angles[ia])
            + _angle_set(0.5 * coarse_angle_resolution, fine_angle_offset)
        )
        grid_r = _lattice_responses(
            grid.data, ox, oy, res, px, py, x, y, fine, 1,
            pflag, float(pred[0]), float(pred[1]), float(pred[2]),
            pen.distance_variance, pen.angle_variance, pen.minimum_distance, pen.minimum_angle,
        )  # fmt: skip
        k = int(np.argmax(grid_r))
        a, rem = divmod(k, 9)
        j, i = divmod(rem, 3)
        if grid_r[a, j, i] > best:
            best = float(grid_r[a, j, i])
            x += (i - 1) * res
            y += (j - 1) * res
            th = float(fine[a])
        ang_step = fine_angle_offset

    if covariance:
        cov = _covariance(
            grid, px, py, pred, x, y, th, best, n, ang_step, refine_angle, pflag, pen,
            coarse_angle_offset, coarse_angle_resolution,
        )  # fmt: skip
    if subcell:
        x, y, th = _refine(grid.data, ox, oy, res, px, py, x, y, th, res, ang_step, 8)
    th = (th + math.pi) % (2.0 * math.pi) - math.pi
    return MatchResult(np.array([x, y, th]), float(best), cov)


def _covariance(
    grid: CorrelationGrid,
    px: FloatArray,
    py: FloatArray,
    pred: FloatArray,
    x: float,
    y: float,
    th: float,
    best: float,
    n: int,
    ang_step: float,
    refined: bool,
    pflag: bool,
    pen: Penalty,
    coarse_offset: float,
    coarse_step: float,
) -> FloatArray:
    res = grid.resolution
    ox, oy = grid.origin
    # positions: the lattice around the best pose at its heading (Karto: the whole search
    # square; responses fall below best - 0.1 well inside a few smear widths)
    m = min(n, 24)
    pos = _lattice_responses(
        grid.data, ox, oy, res, px, py, x, y, np.array([th]), m,
        pflag, float(pred[0]), float(pred[1]), float(pred[2]),
        pen.distance_variance, pen.angle_variance, pen.minimum_distance, pen.minimum_angle,
    )[0]  # fmt: skip
    offs = np.arange(-m, m + 1) * res
    wgt = np.where(pos >= best - 0.1, pos, 0.0)
    norm = float(wgt.sum())
    cov = np.zeros((3, 3))
    if norm > 1e-9:
        vxx = float((wgt * offs[None, :] ** 2).sum()) / norm
        vyy = float((wgt * offs[:, None] ** 2).sum()) / norm
        vxy = float((wgt * offs[None, :] * offs[:, None]).sum()) / norm
        floor = 0.1 * res * res
        mult = 1.0 / best
        cov[0, 0] = max(vxx, floor) * mult
        cov[1, 1] = max(vyy, floor) * mult
        cov[0, 1] = cov[1, 0] = vxy * mult
    else:
        cov[0, 0] = cov[1, 1] = _MAX_VARIANCE
    if refined:
        heads = th + _angle_set(0.5 * coarse_step, ang_step)
    else:
        heads = th + _angle_set(coarse_offset, coarse_step)
    if refined:
        ang = _lattice_responses(
            grid.data, ox, oy, res, px, py, x, y, heads, 0,
            pflag, float(pred[0]), float(pred[1]), float(pred[2]),
            pen.distance_variance, pen.angle_variance, pen.minimum_distance, pen.minimum_angle,
        )[:, 0, 0]  # fmt: skip
        aw = np.where(ang >= best - 0.1, ang, 0.0)
        an = float(aw.sum())
        if an > 1e-9:
            acc = float((aw * (heads - th) ** 2).sum())
            if acc < 1e-9:
                acc = ang_step * ang_step
            cov[2, 2] = acc / an
        else:
            cov[2, 2] = 1000.0 * ang_step * ang_step
    else:
        cov[2, 2] = 4.0 * ang_step * ang_step
    return cov
