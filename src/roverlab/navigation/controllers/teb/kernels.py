"""teb_local_planner's edges (cost terms), compiled: errors, numeric Jacobians, obstacle
association and the robot models' distances.

An edge joins up to three band poses and two time differences; its local values are
``p0 (x, y, th), p1, p2, dt0, dt1``. Residuals are ``sqrt(weight) * error`` (TEB's
information matrices are diagonal weights), so the least-squares cost equals g2o's
``chi2``. Jacobians are central differences per edge (g2o's numeric linearisation, which
TEB uses), written straight into the CSR data of the sparse Jacobian.

Edge types: 0 velocity, 1 acceleration, 2 acceleration at the start (measured velocity),
3 acceleration at the goal (goal velocity), 4 time optimal, 5 shortest path,
6 kinematics (differential drive), 7 kinematics (car-like), 8 obstacle, 9 inflated
obstacle, 10 via point, 11 preferred turning direction (``aux[0]``: +1 left, -1 right).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = [
    "EDGE_RESIDUALS",
    "associate_obstacles",
    "build_structure",
    "evaluate",
    "robot_distance",
]

_jit = numba.njit(cache=True, nogil=True)

#: residuals per edge type
EDGE_RESIDUALS = np.array([2, 2, 2, 2, 1, 1, 2, 2, 1, 2, 1, 1], dtype=np.int64)
# which local slots an edge type reads: poses 0..2 (3 values each), dts 3..4
_POSES_USED = np.array([2, 3, 2, 2, 0, 2, 2, 2, 1, 1, 1, 2], dtype=np.int64)
_DTS_USED = np.array([1, 2, 1, 1, 1, 0, 0, 0, 0, 0, 0, 0], dtype=np.int64)
_DELTA = 1e-7


@_jit
def _norm_angle(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


@_jit
def _sig(x: float) -> float:
    return x / (1.0 + abs(x))


@_jit
def _bound_interval(v: float, a: float, b: float, eps: float) -> float:
    if v < a + eps:
        return -v + (a + eps)
    if v <= b - eps:
        return 0.0
    return v - (b - eps)


@_jit
def _bound_sym(v: float, a: float, eps: float) -> float:
    if v < -a + eps:
        return -v - a + eps
    if v <= a - eps:
        return 0.0
    return v - a + eps


@_jit
def _bound_below(v: float, a: float, eps: float) -> float:
    if v >= a + eps:
        return 0.0
    return -v + (a + eps)


@_jit
def _seg_dist(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    dx = bx - ax
    dy = by - ay
    d2 = dx * dx + dy * dy
    t = 0.0 if d2 == 0.0 else ((px - ax) * dx + (py - ay) * dy) / d2
    t = min(1.0, max(0.0, t))
    return math.hypot(ax + t * dx - px, ay + t * dy - py)


@_jit
def robot_distance(
    x: float, y: float, th: float, model: int, mp: NDArray[np.float64], ox: float, oy: float
) -> float:
    """The distance from TEB's robot model at ``(x, y, th)`` to a point obstacle.

    ``model``: 0 point, 1 circular (radius), 2 two circles (front offset, front radius,
    rear offset, rear radius), 3 line (start x, y, end x, y), 4 polygon (vertices; the
    distance to its outline, as TEB's ``distance_point_to_polygon_2d``).
    """
    if model == 0:
        return math.hypot(ox - x, oy - y)
    if model == 1:
        return math.hypot(ox - x, oy - y) - mp[0]
    c = math.cos(th)
    s = math.sin(th)
    if model == 2:
        fx = x + mp[0] * c
        fy = y + mp[0] * s
        rx = x - mp[2] * c
        ry = y - mp[2] * s
        return min(math.hypot(ox - fx, oy - fy) - mp[1], math.hypot(ox - rx, oy - ry) - mp[3])
    if model == 3:
        ax = x + mp[0] * c - mp[1] * s
        ay = y + mp[0] * s + mp[1] * c
        bx = x + mp[2] * c - mp[3] * s
        by = y + mp[2] * s + mp[3] * c
        return _seg_dist(ox, oy, ax, ay, bx, by)
    nv = mp.shape[0] // 2
    if nv == 1:
        return math.hypot(ox - (x + mp[0] * c - mp[1] * s), oy - (y + mp[0] * s + mp[1] * c))
    best = 1e300
    last = nv if nv > 2 else nv - 1
    for k in range(last):
        j = (k + 1) % nv
        ax = x + mp[2 * k] * c - mp[2 * k + 1] * s
        ay = y + mp[2 * k] * s + mp[2 * k + 1] * c
        bx = x + mp[2 * j] * c - mp[2 * j + 1] * s
        by = y + mp[2 * j] * s + mp[2 * j + 1] * c
        best = min(best, _seg_dist(ox, oy, ax, ay, bx, by))
    return best


@_jit
def _signed_vel(
    x0: float, y0: float, t0: float, x1: float, y1: float, t1: float, dt: float, exact: bool
) -> tuple[float, float]:
    dx = x1 - x0
    dy = y1 - y0
    dist = math.hypot(dx, dy)
    ang = _norm_angle(t1 - t0)
    if exact and ang != 0.0:
        radius = dist / (2.0 * math.sin(ang / 2.0))
        dist = abs(ang * radius)
    vel = dist / dt * _sig(100.0 * (dx * math.cos(t0) + dy * math.sin(t0)))
    return vel, ang / dt


@_jit
def _edge_error(
    et: int,
    v: NDArray[np.float64],
    aux: NDArray[np.float64],
    cfg: NDArray[np.float64],
    model: int,
    mp: NDArray[np.float64],
    err: NDArray[np.float64],
) -> None:
    """One edge's error vector (TEB's ``computeError``). ``cfg``: max_vel_x,
    max_vel_x_backwards, max_vel_theta, acc_lim_x, acc_lim_theta, penalty_epsilon,
    min_turning_radius, min_obstacle_dist, inflation_dist, obstacle_cost_exponent,
    exact_arc_length."""
    eps = cfg[5]
    exact = cfg[10] != 0.0
    if et == 0:
        vel, om = _signed_vel(v[0], v[1], v[2], v[3], v[4], v[5], v[9], exact)
        err[0] = _bound_interval(vel, -cfg[1], cfg[0], eps)
        err[1] = _bound_sym(om, cfg[2], eps)
    elif et == 1:
        v1, o1 = _signed_vel(v[0], v[1], v[2], v[3], v[4], v[5], v[9], exact)
        v2, o2 = _signed_vel(v[3], v[4], v[5], v[6], v[7], v[8], v[10], exact)
        dts = v[9] + v[10]
        err[0] = _bound_sym((v2 - v1) * 2.0 / dts, cfg[3], eps)
        err[1] = _bound_sym((o2 - o1) * 2.0 / dts, cfg[4], eps)
    elif et == 2:
        v2, o2 = _signed_vel(v[0], v[1], v[2], v[3], v[4], v[5], v[9], exact)
        err[0] = _bound_sym((v2 - aux[0]) / v[9], cfg[3], eps)
        err[1] = _bound_sym((o2 - aux[1]) / v[9], cfg[4], eps)
    elif et == 3:
        v1, o1 = _signed_vel(v[0], v[1], v[2], v[3], v[4], v[5], v[9], exact)
        err[0] = _bound_sym((aux[0] - v1) / v[9], cfg[3], eps)
        err[1] = _bound_sym((aux[1] - o1) / v[9], cfg[4], eps)
    elif et == 4:
        err[0] = v[9]
    elif et == 5:
        err[0] = math.hypot(v[3] - v[0], v[4] - v[1])
    elif et == 6 or et == 7:
        dx = v[3] - v[0]
        dy = v[4] - v[1]
        c0 = math.cos(v[2])
        s0 = math.sin(v[2])
        err[0] = abs((c0 + math.cos(v[5])) * dy - (s0 + math.sin(v[5])) * dx)
        if et == 6:
            err[1] = _bound_below(dx * c0 + dy * s0, 0.0, 0.0)
        else:
            ang = _norm_angle(v[5] - v[2])
            if ang == 0.0:
                err[1] = 0.0
            elif exact:
                err[1] = _bound_below(
                    abs(math.hypot(dx, dy) / (2.0 * math.sin(ang / 2.0))), cfg[6], 0.0
                )
            else:
                err[1] = _bound_below(math.hypot(dx, dy) / abs(ang), cfg[6], 0.0)
    elif et == 8 or et == 9:
        d = robot_distance(v[0], v[1], v[2], model, mp, aux[0], aux[1])
        e = _bound_below(d, cfg[7], eps)
        if cfg[9] != 1.0 and cfg[7] > 0.0:
            e = cfg[7] * (e / cfg[7]) ** cfg[9]
        err[0] = e
        if et == 9:
            err[1] = _bound_below(d, cfg[8], 0.0)
    elif et == 10:
        err[0] = math.hypot(v[0] - aux[0], v[1] - aux[1])
    else:  # TEB's EdgePreferRotDir
        err[0] = _bound_below(aux[0] * _norm_angle(v[5] - v[2]), 0.0, 0.0)


@_jit
def _slot_var(slot: int, p: NDArray[np.int64], d: NDArray[np.int64], n: int) -> int:
    """The optimisation variable of local slot ``slot`` (-1 if fixed or unused)."""
    if slot < 9:
        pi = p[slot // 3]
        if pi < 1 or pi > n - 2:
            return -1
        return 3 * (pi - 1) + slot % 3
    di = d[slot - 9]
    if di < 0:
        return -1
    return 3 * (n - 2) + di


@_jit
def build_structure(
    etype: NDArray[np.int64], pidx: NDArray[np.int64], didx: NDArray[np.int64], n: int
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The CSR ``indptr`` and ``indices`` of the Jacobian, and each edge's first row."""
    ne = etype.shape[0]
    rows = 0
    nnz = 0
    row0 = np.empty(ne, dtype=np.int64)
    for e in range(ne):
        row0[e] = rows
        nfree = 0
        for slot in range(11):
            used = slot < 3 * _POSES_USED[etype[e]] if slot < 9 else slot - 9 < _DTS_USED[etype[e]]
            if used and _slot_var(slot, pidx[e], didx[e], n) >= 0:
                nfree += 1
        rows += EDGE_RESIDUALS[etype[e]]
        nnz += nfree * EDGE_RESIDUALS[etype[e]]
    indptr = np.empty(rows + 1, dtype=np.int64)
    indices = np.empty(nnz, dtype=np.int64)
    k = 0
    r = 0
    for e in range(ne):
        for _q in range(EDGE_RESIDUALS[etype[e]]):
            indptr[r] = k
            r += 1
            for slot in range(11):
                used = (
                    slot < 3 * _POSES_USED[etype[e]] if slot < 9 else slot - 9 < _DTS_USED[etype[e]]
                )
                if not used:
                    continue
                var = _slot_var(slot, pidx[e], didx[e], n)
                if var >= 0:
                    indices[k] = var
                    k += 1
    indptr[rows] = k
    return indptr, indices, row0


@_jit
def evaluate(
    x: NDArray[np.float64],
    poses: NDArray[np.float64],
    dts: NDArray[np.float64],
    etype: NDArray[np.int64],
    pidx: NDArray[np.int64],
    didx: NDArray[np.int64],
    aux: NDArray[np.float64],
    sw: NDArray[np.float64],
    cfg: NDArray[np.float64],
    model: int,
    mp: NDArray[np.float64],
    want_jac: bool,
    r: NDArray[np.float64],
    jdata: NDArray[np.float64],
) -> None:
    """Residuals (and the Jacobian's CSR data) at ``x`` (free poses 1..n-2, then dts)."""
    n = poses.shape[0]
    cur = poses.copy()
    cdt = dts.copy()
    for i in range(1, n - 1):
        cur[i, 0] = x[3 * (i - 1)]
        cur[i, 1] = x[3 * (i - 1) + 1]
        cur[i, 2] = x[3 * (i - 1) + 2]
    off = 3 * (n - 2)
    for j in range(n - 1):
        cdt[j] = x[off + j]
    v = np.zeros(11)
    ep = np.zeros(2)
    em = np.zeros(2)
    e0 = np.zeros(2)
    row = 0
    k = 0
    for e in range(etype.shape[0]):
        et = etype[e]
        np_used = _POSES_USED[et]
        nd_used = _DTS_USED[et]
        for a in range(3):
            if a < np_used:
                pi = pidx[e, a]
                v[3 * a] = cur[pi, 0]
                v[3 * a + 1] = cur[pi, 1]
                v[3 * a + 2] = cur[pi, 2]
        for b in range(2):
            if b < nd_used:
                v[9 + b] = cdt[didx[e, b]]
        _edge_error(et, v, aux[e], cfg, model, mp, e0)
        nres = EDGE_RESIDUALS[et]
        for q in range(nres):
            r[row + q] = sw[row + q] * e0[q]
        if want_jac:
            # columns of this edge in slot order, each residual row holds them in order
            col = 0
            ncols = 0
            for slot in range(11):
                used = slot < 3 * np_used if slot < 9 else slot - 9 < nd_used
                if used and _slot_var(slot, pidx[e], didx[e], n) >= 0:
                    ncols += 1
            for slot in range(11):
                used = slot < 3 * np_used if slot < 9 else slot - 9 < nd_used
                if not used or _slot_var(slot, pidx[e], didx[e], n) < 0:
                    continue
                keep = v[slot]
                v[slot] = keep + _DELTA
                _edge_error(et, v, aux[e], cfg, model, mp, ep)
                v[slot] = keep - _DELTA
                _edge_error(et, v, aux[e], cfg, model, mp, em)
                v[slot] = keep
                for q in range(nres):
                    jdata[k + q * ncols + col] = sw[row + q] * (ep[q] - em[q]) / (2.0 * _DELTA)
                col += 1
            k += nres * ncols
        row += nres


@_jit
def associate_obstacles(
    poses: NDArray[np.float64],
    obstacles: NDArray[np.float64],
    model: int,
    mp: NDArray[np.float64],
    force_dist: float,
    cutoff_dist: float,
    out_pose: NDArray[np.int64],
    out_obst: NDArray[np.int64],
    max_forced: int,
) -> int:
    """TEB's ``AddEdgesObstacles`` association: for each pose 1..n-2, every obstacle
    closer than ``force_dist`` (the ``max_forced`` closest of them: neighbouring costmap
    cells of one obstacle add near-copies of one edge), plus the closest one on the left
    and the closest one on the right within ``cutoff_dist``. Returns the number of
    ``(pose, obstacle)`` pairs."""
    n = poses.shape[0]
    cnt = 0
    cap = out_pose.shape[0]
    fk = np.empty(max(max_forced, 1), dtype=np.int64)
    fd = np.empty(max(max_forced, 1))
    for i in range(1, n - 1):
        nf = 0
        x = poses[i, 0]
        y = poses[i, 1]
        th = poses[i, 2]
        c = math.cos(th)
        s = math.sin(th)
        left = -1
        right = -1
        dl = 1e300
        dr = 1e300
        for k in range(obstacles.shape[0]):
            d = robot_distance(x, y, th, model, mp, obstacles[k, 0], obstacles[k, 1])
            if d < force_dist:
                if nf < max_forced:
                    fk[nf] = k
                    fd[nf] = d
                    nf += 1
                elif max_forced > 0:
                    worst = 0
                    for j in range(1, nf):
                        if fd[j] > fd[worst]:
                            worst = j
                    if d < fd[worst]:
                        fk[worst] = k
                        fd[worst] = d
                continue
            if d > cutoff_dist:
                continue
            if c * (obstacles[k, 1] - y) - s * (obstacles[k, 0] - x) > 0:
                if d < dl:
                    dl = d
                    left = k
            elif d < dr:
                dr = d
                right = k
        for j in range(nf):
            if cnt < cap:
                out_pose[cnt] = i
                out_obst[cnt] = fk[j]
                cnt += 1
        if left >= 0 and cnt < cap:
            out_pose[cnt] = i
            out_obst[cnt] = left
            cnt += 1
        if right >= 0 and cnt < cap:
            out_pose[cnt] = i
            out_obst[cnt] = right
            cnt += 1
    return cnt
