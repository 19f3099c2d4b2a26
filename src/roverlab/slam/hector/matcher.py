"""Hector's scan matcher: Gauss-Newton on the pose against the bilinearly interpolated map.

For beam endpoints ``s_i`` (robot frame) and a pose ``xi = (x, y, theta)``, the matcher
minimises ``sum_i (1 - M(S_i(xi)))**2`` where ``S_i(xi) = R(theta) s_i + (x, y)`` in map
coordinates and ``M`` is the occupancy probability, interpolated bilinearly between the
four surrounding cell centres; ``grad M`` is the exact gradient of that bilinear patch
(Kohlbrecher et al. 2011, eqs. 4-6). One Gauss-Newton step solves
``H dxi = sum_i (grad M dS_i/dxi)^T (1 - M(S_i))`` with
``H = sum_i (grad M dS_i/dxi)^T (grad M dS_i/dxi)``.

Matching runs coarse to fine over the map levels: the coarsest level starts from the
prediction, each finer level starts from the coarser result. Like hector, the translation
is solved in the cells of the level, a rotation step is clipped to 0.2 rad and matching
stops when the Hessian is degenerate (no map gradient under the scan).

Two additions make the constant-pose prediction hold up at low scan rates (hector was
built for 40 Hz scanners; the classic benchmark logs are 5 Hz with 10 degree turns and
20 cm jumps between scans, beyond the one-cell reach of a bilinear gradient); both can be
switched off to get hector's plain iteration:

* a pre-search on the coarsest level: the cost is evaluated for headings within
  ``+-angle_search`` (rad) of the prediction in ``angle_search_step`` steps, then, at the
  best heading, for translations within ``+-translation_search_cells`` whole cells; the
  Gauss-Newton iteration starts from the best pose found (the prediction wins ties);
* step control: a step that would raise the cost is retried with Levenberg-Marquardt
  damping ``H + lambda diag(H)`` instead of taken; a level stops once the steps become
  smaller than ``min_step`` cells.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["MAX_ROTATION_STEP", "cost", "interpolate", "match", "normal_equations"]

_jit = numba.njit(cache=True, nogil=True)

#: Largest rotation (rad) one Gauss-Newton step may make (hector's clip).
MAX_ROTATION_STEP = 0.2

# Levenberg-Marquardt damping: first value after a rejected step, growth, give-up value.
_LAMBDA_START = 1.0
_LAMBDA_GROWTH = 10.0
_LAMBDA_MAX = 1e4


@_jit
def _interp(
    prob: NDArray[np.float32], off: int, size: int, mx: float, my: float
) -> tuple[float, float, float]:
    """Bilinear map value and its gradient (per cell) at map coordinates ``(mx, my)``.

    Outside the map (or within one cell of its far edges) the value and gradient are 0.
    """
    if not (mx >= 0.0 and my >= 0.0 and mx < size - 1 and my < size - 1):
        return 0.0, 0.0, 0.0
    ix = int(mx)
    iy = int(my)
    fx = mx - ix
    fy = my - iy
    i = off + iy * size + ix
    p00 = float(prob[i])
    p10 = float(prob[i + 1])
    p01 = float(prob[i + size])
    p11 = float(prob[i + size + 1])
    gx = fy * (p11 - p01) + (1.0 - fy) * (p10 - p00)
    gy = fx * (p11 - p10) + (1.0 - fx) * (p01 - p00)
    v = fy * (fx * p11 + (1.0 - fx) * p01) + (1.0 - fy) * (fx * p10 + (1.0 - fx) * p00)
    return v, gx, gy


@_jit
def _interp_many(
    prob: NDArray[np.float32], off: int, size: int, coords: NDArray[np.float64]
) -> NDArray[np.float64]:
    out = np.empty((coords.shape[0], 3))
    for j in range(coords.shape[0]):
        v, gx, gy = _interp(prob, off, size, coords[j, 0], coords[j, 1])
        out[j, 0] = v
        out[j, 1] = gx
        out[j, 2] = gy
    return out


@_jit
def _cost(
    prob: NDArray[np.float32],
    off: int,
    size: int,
    k: float,
    mx: float,
    my: float,
    theta: float,
    points: NDArray[np.float64],
) -> float:
    """``sum (1 - M)^2`` at the map-coordinate pose ``(mx, my, theta)`` of one level."""
    return _cost_below(prob, off, size, k, mx, my, theta, points, np.inf)


@_jit
def _cost_below(
    prob: NDArray[np.float32],
    off: int,
    size: int,
    k: float,
    mx: float,
    my: float,
    theta: float,
    points: NDArray[np.float64],
    bound: float,
) -> float:
    """:func:`_cost`, abandoned (returning a value >= ``bound``) once it reaches ``bound``:
    a search over many poses skips the rest of a pose already worse than its best."""
    c = math.cos(theta)
    s = math.sin(theta)
    total = 0.0
    for j in range(points.shape[0]):
        px = points[j, 0] * k
        py = points[j, 1] * k
        v, _, _ = _interp(prob, off, size, mx + c * px - s * py, my + s * px + c * py)
        total += (1.0 - v) * (1.0 - v)
        if total >= bound:
            break
    return total


@_jit
def _solve3(h: NDArray[np.float64], g: NDArray[np.float64], out: NDArray[np.float64]) -> bool:
    """Solve the symmetric 3x3 system ``h out = g``; False when (nearly) singular."""
    a, b, c = h[0, 0], h[0, 1], h[0, 2]
    d, e, f = h[1, 1], h[1, 2], h[2, 2]
    c00 = d * f - e * e
    c01 = c * e - b * f
    c02 = b * e - c * d
    det = a * c00 + b * c01 + c * c02
    if not (abs(det) > 1e-12 * abs(a * d * f)) or det == 0.0:
        return False
    c11 = a * f - c * c
    c12 = b * c - a * e
    c22 = a * d - b * b
    out[0] = (c00 * g[0] + c01 * g[1] + c02 * g[2]) / det
    out[1] = (c01 * g[0] + c11 * g[1] + c12 * g[2]) / det
    out[2] = (c02 * g[0] + c12 * g[1] + c22 * g[2]) / det
    return True


@_jit
def _normal_equations(
    prob: NDArray[np.float32],
    off: int,
    size: int,
    k: float,
    mx: float,
    my: float,
    theta: float,
    points: NDArray[np.float64],
    h: NDArray[np.float64],
    g: NDArray[np.float64],
) -> float:
    """Fill ``h`` and ``g`` at the map-coordinate pose; return the cost there."""
    c = math.cos(theta)
    s = math.sin(theta)
    h[:, :] = 0.0
    g[:] = 0.0
    total = 0.0
    for j in range(points.shape[0]):
        px = points[j, 0] * k
        py = points[j, 1] * k
        v, gx, gy = _interp(prob, off, size, mx + c * px - s * py, my + s * px + c * py)
        r = 1.0 - v
        total += r * r
        jt = gx * (-s * px - c * py) + gy * (c * px - s * py)
        g[0] += gx * r
        g[1] += gy * r
        g[2] += jt * r
        h[0, 0] += gx * gx
        h[0, 1] += gx * gy
        h[0, 2] += gx * jt
        h[1, 1] += gy * gy
        h[1, 2] += gy * jt
        h[2, 2] += jt * jt
    h[1, 0] = h[0, 1]
    h[2, 0] = h[0, 2]
    h[2, 1] = h[1, 2]
    return total


@_jit
def _match(
    prob: NDArray[np.float32],
    offsets: NDArray[np.int64],
    sizes: NDArray[np.int64],
    inv_res: NDArray[np.float64],
    centers: NDArray[np.float64],
    points: NDArray[np.float64],
    x: float,
    y: float,
    theta: float,
    iters_coarse: int,
    iters_fine: int,
    min_step: float,
    damped: bool,
    search_range: float,
    search_step: float,
    search_cells: int,
    hessian: NDArray[np.float64],
) -> NDArray[np.float64]:
    h = np.zeros((3, 3))
    hd = np.zeros((3, 3))
    g = np.zeros(3)
    step = np.zeros(3)
    top = len(sizes) - 1
    for lev in range(top, -1, -1):
        k = inv_res[lev]
        size = sizes[lev]
        off = offsets[lev]
        mx = x * k + centers[lev, 0]
        my = y * k + centers[lev, 1]
        if lev == top and search_range > 0.0 and search_step > 0.0:
            best_c = _cost(prob, off, size, k, mx, my, theta, points)
            best_t = theta
            n = int(search_range / search_step + 1e-9)
            for q in range(-n, n + 1):
                if q != 0:
                    t = theta + q * search_step
                    c = _cost(prob, off, size, k, mx, my, t, points)
                    if c < best_c:
                        best_c = c
                        best_t = t
            theta = best_t
        if lev == top and search_cells > 0:
            best_c = _cost(prob, off, size, k, mx, my, theta, points)
            bx = mx
            by = my
            for qx in range(-search_cells, search_cells + 1):
                for qy in range(-search_cells, search_cells + 1):
                    if qx != 0 or qy != 0:
                        c = _cost(prob, off, size, k, mx + qx, my + qy, theta, points)
                        if c < best_c:
                            best_c = c
                            bx = mx + qx
                            by = my + qy
            mx = bx
            my = by
        iters = iters_fine if lev == 0 else iters_coarse
        lam = 0.0
        cur = _normal_equations(prob, off, size, k, mx, my, theta, points, h, g)
        for _ in range(iters):
            if h[0, 0] == 0.0 or h[1, 1] == 0.0:
                break
            for a in range(3):
                for b in range(3):
                    hd[a, b] = h[a, b]
                hd[a, a] += lam * h[a, a]
            if not _solve3(hd, g, step):
                break
            dth = min(max(step[2], -MAX_ROTATION_STEP), MAX_ROTATION_STEP)
            if damped:
                trial = _cost(prob, off, size, k, mx + step[0], my + step[1], theta + dth, points)
                if trial > cur:
                    lam = _LAMBDA_START if lam == 0.0 else lam * _LAMBDA_GROWTH
                    if lam > _LAMBDA_MAX:
                        break
                    continue
                lam = lam / _LAMBDA_GROWTH if lam > _LAMBDA_START else 0.0
            mx += step[0]
            my += step[1]
            theta += dth
            cur = _normal_equations(prob, off, size, k, mx, my, theta, points, h, g)
            if abs(step[0]) < min_step and abs(step[1]) < min_step and abs(dth) < 0.1 * min_step:
                break
        x = (mx - centers[lev, 0]) / k
        y = (my - centers[lev, 1]) / k
    # the Hessian at the final pose on the finest level, in metres and radians
    k = inv_res[0]
    _normal_equations(
        prob,
        offsets[0],
        sizes[0],
        k,
        x * k + centers[0, 0],
        y * k + centers[0, 1],
        theta,
        points,
        h,
        g,
    )
    for a in range(3):
        for b in range(3):
            sa = k if a < 2 else 1.0
            sb = k if b < 2 else 1.0
            hessian[a, b] = h[a, b] * sa * sb
    out = np.empty(3)
    out[0] = x
    out[1] = y
    out[2] = math.atan2(math.sin(theta), math.cos(theta))
    return out


def interpolate(prob: NDArray[np.float32], coords: NDArray[np.float64]) -> NDArray[np.float64]:
    """Bilinear value and gradient of a (size, size) ``[iy, ix]`` grid at map coordinates.

    Args:
        prob: square grid of map values, row ``iy``, column ``ix`` (cell centres at integers).
        coords: (N, 2) map coordinates ``(mx, my)`` in cells.

    Returns:
        (N, 3) float64 ``M, dM/dmx, dM/dmy``; zeros outside the map.
    """
    grid = np.ascontiguousarray(prob, dtype=np.float32)
    if grid.ndim != 2 or grid.shape[0] != grid.shape[1]:
        raise ValueError("prob must be a square 2-D grid")
    pts = np.ascontiguousarray(coords, dtype=np.float64).reshape(-1, 2)
    return _interp_many(grid.reshape(-1), 0, grid.shape[0], pts)


def cost(
    prob: NDArray[np.float32],
    points: NDArray[np.float64],
    pose_cells: tuple[float, float, float],
    cells_per_m: float = 1.0,
) -> float:
    """Hector's matching cost ``sum (1 - M(S_i))^2`` on one (size, size) grid.

    Args:
        prob: square grid of map values (as :func:`interpolate`).
        points: (N, 2) endpoints in the robot frame (m).
        pose_cells: ``mx, my`` (map coordinates, cells) and ``theta`` (rad) of the robot.
        cells_per_m: the grid's ``1 / resolution``.
    """
    grid = np.ascontiguousarray(prob, dtype=np.float32)
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    mx, my, th = (float(v) for v in pose_cells)
    return float(_cost(grid.reshape(-1), 0, grid.shape[0], float(cells_per_m), mx, my, th, pts))


def normal_equations(
    prob: NDArray[np.float32],
    points: NDArray[np.float64],
    pose_cells: tuple[float, float, float],
    cells_per_m: float = 1.0,
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Cost, Gauss-Newton Hessian and right-hand side on one (size, size) grid.

    With ``J_i = grad M(S_i) dS_i/dxi`` (per cell and radian) and ``r_i = 1 - M(S_i)``:
    returns ``(sum r_i^2, sum J_i^T J_i, sum J_i^T r_i)``; the cost's gradient with respect
    to ``(mx, my, theta)`` is ``-2 * sum J_i^T r_i``.

    Args:
        prob, points, pose_cells, cells_per_m: as :func:`cost`.
    """
    grid = np.ascontiguousarray(prob, dtype=np.float32)
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2)
    mx, my, th = (float(v) for v in pose_cells)
    h = np.zeros((3, 3))
    g = np.zeros(3)
    total = _normal_equations(
        grid.reshape(-1), 0, grid.shape[0], float(cells_per_m), mx, my, th, pts, h, g
    )
    return float(total), h, g


def match(
    grid_prob: NDArray[np.float32],
    offsets: NDArray[np.int64],
    sizes: NDArray[np.int64],
    inv_res: NDArray[np.float64],
    centers: NDArray[np.float64],
    points: NDArray[np.float64],
    start: NDArray[np.float64],
    *,
    iters_coarse: int,
    iters_fine: int,
    angle_search: float = 0.0,
    angle_search_step: float = 0.01,
    translation_search_cells: int = 0,
    damped: bool = True,
    min_step: float = 1e-3,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Match robot-frame endpoints against a map pyramid (see the module docstring).

    Args:
        grid_prob: flat float32 map values of every level (:class:`MultiResGrid`'s ``prob``).
        offsets, sizes, inv_res, centers: the pyramid layout (see :class:`MultiResGrid`).
        points: (N, 2) float64 endpoints in the robot frame (m).
        start: (3,) initial pose ``x, y, theta`` in the map frame.
        iters_coarse: at most this many Gauss-Newton steps per coarse level.
        iters_fine: at most this many on the finest level.
        angle_search: half-width (rad) of the rotational pre-search; 0 disables it.
        angle_search_step: its heading step (rad).
        translation_search_cells: half-width, in coarsest-level cells, of the translational
            pre-search that follows the rotational one; 0 disables it.
        damped: retry cost-raising steps with Levenberg-Marquardt damping (False: take
            every Gauss-Newton step, as hector does).
        min_step: a level stops once a step moves less than this many cells (and a tenth
            of it in radians).

    Returns:
        The matched pose (3,) and the Gauss-Newton Hessian (3, 3) at it on the finest level
        (metres and radians; its inverse, scaled, is hector's covariance).
    """
    hessian = np.zeros((3, 3))
    pose = _match(
        grid_prob,
        offsets,
        sizes,
        inv_res,
        centers,
        np.ascontiguousarray(points, dtype=np.float64),
        float(start[0]),
        float(start[1]),
        float(start[2]),
        int(iters_coarse),
        int(iters_fine),
        float(min_step),
        bool(damped),
        float(angle_search),
        float(angle_search_step),
        int(translation_search_cells),
        hessian,
    )
    return pose, hessian
