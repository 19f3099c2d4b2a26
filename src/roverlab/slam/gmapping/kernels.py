"""Compiled kernels of the particle filter: scan matching, proposal sampling, map updates.

Every kernel works on the maps of all particles at once: ``cells`` is a
``(particles, height, width, 4)`` uint16 array, one slab per particle, whose last axis holds
gmapping's per-cell counters:

* ``HITS``: beams that ended in the cell;
* ``VISITS``: beams that passed through or ended in the cell (occupancy ``hits / visits``;
  never visited cells are unknown);
* ``MEAN_X``, ``MEAN_Y``: the mean of the hit points inside the cell, in units of
  ``delta / 65536`` from the cell's lower corner (gmapping's ``PointAccumulator`` keeps the
  sum of the points; the mean is what the scan matcher measures distances to).

Cell ``[iy, ix]`` covers ``x in ox + [ix, ix + 1) * delta`` and ``y in oy + [iy, iy + 1) *
delta``. A counter about to overflow halves both counts first (the ratio stays).

Batch kernels (``match_all``, ``proposal_all``, ``register_all``) run their particles in
parallel (``numba.prange``): each particle reads and writes only its own slab, so the result
does not depend on the thread count.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "HITS",
    "MEAN_SCALE",
    "MEAN_X",
    "MEAN_Y",
    "VISITS",
    "backtrack",
    "match_all",
    "proposal_all",
    "register_all",
    "score_pose",
    "search_window",
]

HITS = 0
VISITS = 1
MEAN_X = 2
MEAN_Y = 3
#: A cell's mean hit point is stored in units of ``delta / MEAN_SCALE``.
MEAN_SCALE = 65536.0
_COUNT_MAX = 65535
# A cell is occupied for the matcher when hits / visits > 0.1, free when < 0.1 or unknown
# (gmapping's fullness threshold): compared as integers, 10 * hits against visits.
_FULLNESS_DEN = 10
# Hill-climbing rounds are bounded even if the score keeps creeping up.
_MAX_CLIMB_ROUNDS = 400

_jit = numba.njit(cache=True, nogil=True)
_pjit = numba.njit(cache=True, nogil=True, parallel=True)


@_jit
def _wrap(a: float) -> float:
    """Angle wrapped to [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@_jit
def score_pose(
    cells: NDArray[np.uint16],
    p: int,
    ox: float,
    oy: float,
    delta: float,
    x: float,
    y: float,
    th: float,
    hit: NDArray[np.float64],
    free: NDArray[np.float64],
    kernel: int,
    inv_sigma: float,
    inv_lsigma: float,
    no_hit: float,
) -> tuple[float, float]:
    """Matcher score and log-likelihood of the scan at robot pose ``(x, y, th)``.

    For each beam, the correspondence is the occupied cell within ``kernel`` cells of the
    endpoint's cell whose mean hit point is nearest to the endpoint, among the cells whose
    companion one step back along the beam (``free`` - ``hit``) is free. With ``d`` that
    distance, the score adds ``exp(-d^2 * inv_sigma)`` and the log-likelihood
    ``-d^2 * inv_lsigma``; a beam without a correspondence adds ``no_hit`` to the latter.

    Args:
        cells: the maps of all particles; ``p`` selects one.
        p: the particle.
        ox, oy: world position of the lower corner of cell ``[0, 0]`` (m).
        delta: cell size (m).
        x, y, th: robot pose in the map frame.
        hit: (B, 2) beam endpoints in the robot frame (m).
        free: (B, 2) points one cell back from each endpoint, robot frame (m).
        kernel: correspondence search half-width (cells).
        inv_sigma: ``1 / sigma`` of the score.
        inv_lsigma: ``1 / lsigma`` of the log-likelihood.
        no_hit: log-likelihood of a beam without correspondence.

    Returns:
        ``(score, log_likelihood)``.
    """
    h = cells.shape[1]
    w = cells.shape[2]
    inv_d = 1.0 / delta
    mscale = delta / MEAN_SCALE
    c = math.cos(th)
    s = math.sin(th)
    score = 0.0
    ll = 0.0
    for b in range(hit.shape[0]):
        hx = x + c * hit[b, 0] - s * hit[b, 1]
        hy = y + s * hit[b, 0] + c * hit[b, 1]
        fx = x + c * free[b, 0] - s * free[b, 1]
        fy = y + s * free[b, 0] + c * free[b, 1]
        ihx = int(math.floor((hx - ox) * inv_d))
        ihy = int(math.floor((hy - oy) * inv_d))
        sfx = int(math.floor((fx - ox) * inv_d)) - ihx
        sfy = int(math.floor((fy - oy) * inv_d)) - ihy
        best = math.inf
        for dy in range(-kernel, kernel + 1):
            cy = ihy + dy
            if cy < 0 or cy >= h:
                continue
            for dx in range(-kernel, kernel + 1):
                cx = ihx + dx
                if cx < 0 or cx >= w:
                    continue
                nh = np.int64(cells[p, cy, cx, HITS])
                nv = np.int64(cells[p, cy, cx, VISITS])
                if nv == 0 or _FULLNESS_DEN * nh <= nv:
                    continue
                qx = cx + sfx
                qy = cy + sfy
                if 0 <= qx < w and 0 <= qy < h:
                    fv = np.int64(cells[p, qy, qx, VISITS])
                    if fv > 0 and _FULLNESS_DEN * np.int64(cells[p, qy, qx, HITS]) >= fv:
                        continue
                mx = ox + cx * delta + cells[p, cy, cx, MEAN_X] * mscale
                my = oy + cy * delta + cells[p, cy, cx, MEAN_Y] * mscale
                d2 = (hx - mx) * (hx - mx) + (hy - my) * (hy - my)
                if d2 < best:
                    best = d2
        if best < math.inf:
            score += math.exp(-best * inv_sigma)
            ll -= best * inv_lsigma
        else:
            ll += no_hit
    return score, ll


@_jit
def _climb(
    cells: NDArray[np.uint16],
    p: int,
    ox: float,
    oy: float,
    delta: float,
    x: float,
    y: float,
    th: float,
    hit: NDArray[np.float64],
    free: NDArray[np.float64],
    kernel: int,
    inv_sigma: float,
    lstep: float,
    astep: float,
    iterations: int,
) -> tuple[float, float, float, float]:
    """gmapping's hill climbing: try the six unit moves, keep the best, halve on a stall."""
    cur, _ = score_pose(cells, p, ox, oy, delta, x, y, th, hit, free, kernel, inv_sigma, 0.0, 0.0)
    best = -1.0
    ld = lstep
    ad = astep
    refinement = 0
    for _round in range(_MAX_CLIMB_ROUNDS):
        if best >= cur:
            refinement += 1
            ld *= 0.5
            ad *= 0.5
        best = cur
        bx = x
        by = y
        bt = th
        for move in range(6):
            nx = x
            ny = y
            nt = th
            if move == 0:
                nx += ld
            elif move == 1:
                nx -= ld
            elif move == 2:
                ny += ld
            elif move == 3:
                ny -= ld
            elif move == 4:
                nt += ad
            else:
                nt -= ad
            sc, _ = score_pose(
                cells, p, ox, oy, delta, nx, ny, nt, hit, free, kernel, inv_sigma, 0.0, 0.0
            )
            if sc > cur:
                cur = sc
                bx = nx
                by = ny
                bt = nt
        x = bx
        y = by
        th = bt
        if not (cur > best or refinement < iterations):
            break
    return x, y, _wrap(th), cur


@_pjit
def match_all(
    cells: NDArray[np.uint16],
    owners: NDArray[np.int64],
    ox: float,
    oy: float,
    delta: float,
    poses: NDArray[np.float64],
    hit: NDArray[np.float64],
    free: NDArray[np.float64],
    kernel: int,
    inv_sigma: float,
    lstep: float,
    astep: float,
    iterations: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Hill-climb every start pose on the map of its owner.

    Args:
        owners: (K,) the particle whose map each start pose is matched on.
        poses: (K, 3) start poses (the odometry samples).
        (others as :func:`score_pose`; ``lstep`` / ``astep`` the initial steps,
        ``iterations`` the number of step halvings)

    Returns:
        ``(matched (P, 3), scores (P,))``.
    """
    n = poses.shape[0]
    out = np.empty((n, 3))
    scores = np.empty(n)
    for p in numba.prange(n):
        x, y, th, sc = _climb(
            cells,
            owners[p],
            ox,
            oy,
            delta,
            poses[p, 0],
            poses[p, 1],
            poses[p, 2],
            hit,
            free,
            kernel,
            inv_sigma,
            lstep,
            astep,
            iterations,
        )
        out[p, 0] = x
        out[p, 1] = y
        out[p, 2] = th
        scores[p] = sc
    return out, scores


@_pjit
def proposal_all(
    cells: NDArray[np.uint16],
    ox: float,
    oy: float,
    delta: float,
    centers: NDArray[np.float64],
    hit: NDArray[np.float64],
    free: NDArray[np.float64],
    kernel: int,
    inv_sigma: float,
    inv_lsigma: float,
    no_hit: float,
    offsets: NDArray[np.float64],
    motion_mean: NDArray[np.float64],
    motion_inv_var: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The Gaussian approximation of the improved proposal, per particle.

    Around each particle's center (its scan-matched pose), the poses ``center + offsets[j]``
    are weighted by ``tau_j = p(z | m, x_j) * p(x_j | x_{t-1}, u)``: the scan
    log-likelihood plus the log density of the odometry Gaussian (mean ``motion_mean``,
    robot-frame inverse variances ``motion_inv_var``). Their weighted mean and covariance
    define the proposal; ``log(sum_j tau_j)`` is the weight factor (the normaliser eta).

    Returns:
        ``(mean (P, 3), covariance (P, 3, 3), log_eta (P,))``.
    """
    n = centers.shape[0]
    k = offsets.shape[0]
    mean = np.empty((n, 3))
    cov = np.zeros((n, 3, 3))
    log_eta = np.empty(n)
    for p in numba.prange(n):
        tau = np.empty(k)
        mc = math.cos(motion_mean[p, 2])
        ms = math.sin(motion_mean[p, 2])
        for j in range(k):
            x = centers[p, 0] + offsets[j, 0]
            y = centers[p, 1] + offsets[j, 1]
            th = centers[p, 2] + offsets[j, 2]
            _, ll = score_pose(
                cells,
                p,
                ox,
                oy,
                delta,
                x,
                y,
                th,
                hit,
                free,
                kernel,
                inv_sigma,
                inv_lsigma,
                no_hit,
            )
            dx = x - motion_mean[p, 0]
            dy = y - motion_mean[p, 1]
            ex = mc * dx + ms * dy
            ey = -ms * dx + mc * dy
            et = _wrap(th - motion_mean[p, 2])
            tau[j] = ll - 0.5 * (
                ex * ex * motion_inv_var[0]
                + ey * ey * motion_inv_var[1]
                + et * et * motion_inv_var[2]
            )
        tmax = tau.max()
        total = 0.0
        m0 = 0.0
        m1 = 0.0
        m2 = 0.0
        for j in range(k):
            wj = math.exp(tau[j] - tmax)
            tau[j] = wj
            total += wj
            m0 += wj * offsets[j, 0]
            m1 += wj * offsets[j, 1]
            m2 += wj * offsets[j, 2]
        m0 /= total
        m1 /= total
        m2 /= total
        for j in range(k):
            d0 = offsets[j, 0] - m0
            d1 = offsets[j, 1] - m1
            d2 = offsets[j, 2] - m2
            wj = tau[j] / total
            cov[p, 0, 0] += wj * d0 * d0
            cov[p, 0, 1] += wj * d0 * d1
            cov[p, 0, 2] += wj * d0 * d2
            cov[p, 1, 1] += wj * d1 * d1
            cov[p, 1, 2] += wj * d1 * d2
            cov[p, 2, 2] += wj * d2 * d2
        cov[p, 1, 0] = cov[p, 0, 1]
        cov[p, 2, 0] = cov[p, 0, 2]
        cov[p, 2, 1] = cov[p, 1, 2]
        mean[p, 0] = centers[p, 0] + m0
        mean[p, 1] = centers[p, 1] + m1
        mean[p, 2] = _wrap(centers[p, 2] + m2)
        log_eta[p] = tmax + math.log(total)
    return mean, cov, log_eta


@_jit
def _halve(cells: NDArray[np.uint16], p: int, iy: int, ix: int) -> None:
    cells[p, iy, ix, HITS] = cells[p, iy, ix, HITS] >> 1
    cells[p, iy, ix, VISITS] = cells[p, iy, ix, VISITS] >> 1


@_jit
def _register_one(
    cells: NDArray[np.uint16],
    p: int,
    ox: float,
    oy: float,
    delta: float,
    pose_x: float,
    pose_y: float,
    pose_th: float,
    origin: NDArray[np.float64],
    ends: NDArray[np.float64],
    is_hit: NDArray[np.bool_],
) -> None:
    h = cells.shape[1]
    w = cells.shape[2]
    inv_d = 1.0 / delta
    c = math.cos(pose_th)
    s = math.sin(pose_th)
    lx = pose_x + c * origin[0] - s * origin[1]
    ly = pose_y + s * origin[0] + c * origin[1]
    x0 = int(math.floor((lx - ox) * inv_d))
    y0 = int(math.floor((ly - oy) * inv_d))
    for b in range(ends.shape[0]):
        ex = pose_x + c * ends[b, 0] - s * ends[b, 1]
        ey = pose_y + s * ends[b, 0] + c * ends[b, 1]
        fx = (ex - ox) * inv_d
        fy = (ey - oy) * inv_d
        x1 = int(math.floor(fx))
        y1 = int(math.floor(fy))
        # Bresenham from the laser's cell to the end cell; every cell but the last is
        # passed through (one visit each).
        adx = abs(x1 - x0)
        ady = -abs(y1 - y0)
        sx = 1 if x0 < x1 else -1
        sy = 1 if y0 < y1 else -1
        err = adx + ady
        ix = x0
        iy = y0
        while ix != x1 or iy != y1:
            if 0 <= ix < w and 0 <= iy < h:
                if cells[p, iy, ix, VISITS] == _COUNT_MAX:
                    _halve(cells, p, iy, ix)
                cells[p, iy, ix, VISITS] += 1
            e2 = 2 * err
            if e2 >= ady:
                err += ady
                ix += sx
            if e2 <= adx:
                err += adx
                iy += sy
        if not is_hit[b] or not (0 <= x1 < w and 0 <= y1 < h):
            continue
        if cells[p, y1, x1, VISITS] == _COUNT_MAX:
            _halve(cells, p, y1, x1)
        n = np.int64(cells[p, y1, x1, HITS]) + 1
        cells[p, y1, x1, HITS] = n
        cells[p, y1, x1, VISITS] += 1
        qx = min(max((fx - x1) * MEAN_SCALE, 0.0), MEAN_SCALE - 1.0)
        qy = min(max((fy - y1) * MEAN_SCALE, 0.0), MEAN_SCALE - 1.0)
        mx = float(cells[p, y1, x1, MEAN_X])
        my = float(cells[p, y1, x1, MEAN_Y])
        cells[p, y1, x1, MEAN_X] = int(min(mx + (qx - mx) / n + 0.5, MEAN_SCALE - 1.0))
        cells[p, y1, x1, MEAN_Y] = int(min(my + (qy - my) / n + 0.5, MEAN_SCALE - 1.0))


@_pjit
def register_all(
    cells: NDArray[np.uint16],
    ox: float,
    oy: float,
    delta: float,
    poses: NDArray[np.float64],
    origin: NDArray[np.float64],
    ends: NDArray[np.float64],
    is_hit: NDArray[np.bool_],
) -> None:
    """Integrate one scan into every particle's map at that particle's pose.

    Args:
        poses: (P, 3) robot poses.
        origin: (2,) the laser's position in the robot frame (m).
        ends: (B, 2) beam end points in the robot frame (cropped to the usable range).
        is_hit: (B,) whether the beam ended on an obstacle (below the usable range); a
            cropped beam only clears the cells before its end.
    """
    for p in numba.prange(poses.shape[0]):
        _register_one(
            cells, p, ox, oy, delta, poses[p, 0], poses[p, 1], poses[p, 2], origin, ends, is_hit
        )


@_jit
def backtrack(parent: NDArray[np.int64], node: int) -> NDArray[np.int64]:
    """Node indices from the root of the trajectory tree down to ``node``."""
    depth = 0
    k = node
    while k >= 0:
        depth += 1
        k = parent[k]
    out = np.empty(depth, dtype=np.int64)
    k = node
    for i in range(depth - 1, -1, -1):
        out[i] = k
        k = parent[k]
    return out


@_pjit
def search_window(
    cells: NDArray[np.uint16],
    p: int,
    ox: float,
    oy: float,
    delta: float,
    x0: float,
    y0: float,
    th0: float,
    hit: NDArray[np.float64],
    free: NDArray[np.float64],
    kernel: int,
    inv_sigma: float,
    lin_half: float,
    lin_step: float,
    ang_half: float,
    ang_step: float,
) -> NDArray[np.float64]:
    """Score every pose of a regular window around ``(x0, y0, th0)`` on particle ``p``'s map.

    Returns:
        ``(A, L, L)`` scores: angle ``th0 + (a - na) * ang_step``, x ``x0 + (i - nl) *
        lin_step``, y ``y0 + (j - nl) * lin_step`` with ``nl = round(lin_half / lin_step)``
        and ``na = round(ang_half / ang_step)``.
    """
    nl = int(round(lin_half / lin_step))
    na = int(round(ang_half / ang_step))
    out = np.empty((2 * na + 1, 2 * nl + 1, 2 * nl + 1))
    for a in numba.prange(2 * na + 1):
        th = th0 + (a - na) * ang_step
        for i in range(2 * nl + 1):
            x = x0 + (i - nl) * lin_step
            for j in range(2 * nl + 1):
                sc, _ = score_pose(
                    cells,
                    p,
                    ox,
                    oy,
                    delta,
                    x,
                    y0 + (j - nl) * lin_step,
                    th,
                    hit,
                    free,
                    kernel,
                    inv_sigma,
                    0.0,
                    0.0,
                )
                out[a, i, j] = sc
    return out
