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

The compiled kernels (grid stamping, the branch-and-bound search, lattice responses, the
sub-cell step) are in :mod:`roverlab.slam.graph.kernels`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.graph.kernels import (
    _OCCUPIED,
    _bnb_search,
    _lattice_responses,
    _refine,
    _splat,
    _valid_mask,
)

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

#: Karto's ``MAX_VARIANCE``: the variance reported when no pose had a response.
_MAX_VARIANCE = 500.0
#: Karto's ``FindValidPoints`` minimum spacing of the points it compares (m).
_VALID_POINT_SPACING = 0.1


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
