"""dwa_local_planner's compiled core: the map grids' wavefront and the scoring of every
rollout in one kernel.

The critics, in DWAPlanner's order, each skipped when its scale is 0 (a negative cost
rejects the trajectory):

1. oscillation (scale 1): a direction forbidden by the oscillation flags: -5 / -7 / -6;
2. obstacle (``occdist_scale``): every point's footprint (scaled by the speed factor, see
   :func:`score_rollouts`) laid on the costmap along its edges; a lethal or unknown cell
   or a vertex off the map: -6, the centre off the map: -7; the cost is the highest cell
   cost (the sum with ``sum_scores``); the rollout is also checked for ``stop_time_buffer``
   seconds beyond its end;
3. goal front (``goal_distance_bias``): the local-goal grid at the point
   ``forward_point_distance`` ahead of the last pose (no failure);
4. alignment (``path_distance_bias``, 0 near the goal): the path grid at that point;
5. path (``path_distance_bias``): the path grid at the last pose; a point on an obstacle
   or unreachable cell of the grid: -3 / -2;
6. goal (``goal_distance_bias``): the local-goal grid at the last pose (same failures);
7. twirling (``twirling_scale``): ``|vth|``.

Grid critics return -4 for a point off the map.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.controllers.dwa.rollouts import rollout, shared_rollout
from roverlab.navigation.costmap.footprint_kernels import cells_cost, footprint_cells

__all__ = [
    "first_known_stretch",
    "rollout",
    "sample_grid",
    "score_rollouts",
    "target_distance",
    "target_distance_window",
]

_jit = numba.njit(cache=True, nogil=True)

LETHAL = 254
INSCRIBED = 253
NO_INFO = 255


@_jit
def target_distance(
    costs: NDArray[np.uint8], seeds: NDArray[np.int64], out: NDArray[np.float64]
) -> None:
    """base_local_planner's ``MapGrid::computeTargetDistance``: a 4-connected wavefront
    from the seed cells (distance 0) counting cells; lethal, inscribed and unknown cells get
    ``size`` (obstacle) and stop the wave; cells never reached keep ``size + 1``.

    The wave runs on a copy of the grid with a one-cell border (no bounds checks per
    neighbour): state 0 free and unseen, 1 an obstacle unseen, 2 seen (or the border).
    """
    h, w = costs.shape
    target_distance_window(costs, seeds, out, np.array([0, 0, w - 1, h - 1], dtype=np.int64))


@_jit
def target_distance_window(
    costs: NDArray[np.uint8],
    seeds: NDArray[np.int64],
    out: NDArray[np.float64],
    window: NDArray[np.int64],
) -> bool:
    """:func:`target_distance` with the wave stopped as soon as every cell of ``window``
    (``x0, y0, x1, y1``, cells, inclusive) has its final value: once every free cell and
    seed of the window grown by one cell has been expanded (a free cell's distance is
    final when the wave first reaches it, an obstacle cell's once each neighbour that can
    reach it, free or a seed, is expanded).
    Cells outside the window then hold the wave's values so far. Returns whether the wave
    ran to its end (every cell final); with a window of the whole grid it always does.
    """
    h, w = costs.shape
    size = h * w
    pw = w + 2
    # state & 3: 0 free and unseen, 1 an obstacle unseen, 2 seen (or the border), 3 reached
    # and to be expanded; + 4: inside the window grown by one cell (its expansion is
    # counted down in ``pending``; no division per cell to find it out)
    state = np.full((h + 2) * pw, 2, dtype=np.uint8)
    dist = np.full((h + 2) * pw, size + 1, dtype=np.int32)
    # the window grown by one cell, clipped to the grid (bordered coordinates)
    gx0 = max(window[0] - 1, 0) + 1
    gy0 = max(window[1] - 1, 0) + 1
    gx1 = min(window[2] + 1, w - 1) + 1
    gy1 = min(window[3] + 1, h - 1) + 1
    pending = 0
    for y in range(h):
        row = (y + 1) * pw + 1
        inside_y = gy0 <= y + 1 <= gy1
        for x in range(w):
            inside = inside_y and gx0 <= x + 1 <= gx1
            if costs[y, x] >= INSCRIBED:  # inscribed, lethal, unknown
                state[row + x] = 5 if inside else 1
            elif inside:
                state[row + x] = 4
                pending += 1
            else:
                state[row + x] = 0
    queue = np.empty(size + seeds.shape[0], dtype=np.int64)
    qh = 0
    qt = 0
    for k in range(seeds.shape[0]):
        idx = (seeds[k, 1] + 1) * pw + seeds[k, 0] + 1
        st = state[idx]
        if st == 5:
            pending += 1  # a seed on an obstacle is expanded too (a free one is counted)
        if st & 3 != 3:
            state[idx] = 3 | (st & 4)  # reached, to be expanded
        dist[idx] = 0
        queue[qt] = idx
        qt += 1
    while qh < qt and pending > 0:
        cur = queue[qh]
        qh += 1
        st = state[cur]
        if st & 3 == 3:
            state[cur] = 2
            pending -= st >> 2
        d = dist[cur] + 1
        for nb in range(4):
            if nb == 0:
                n = cur - 1
            elif nb == 1:
                n = cur + 1
            elif nb == 2:
                n = cur - pw
            else:
                n = cur + pw
            st = state[n] & 3
            if st >= 2:
                continue
            if st == 1:
                state[n] = 2
                dist[n] = size
                continue
            state[n] = state[n] | 3  # reached, to be expanded
            dist[n] = d
            queue[qt] = n
            qt += 1
    for y in range(h):
        row = (y + 1) * pw + 1
        for x in range(w):
            out[y, x] = dist[row + x]
    return qh >= qt


@_jit
def first_known_stretch(
    plan: NDArray[np.float64],
    costs: NDArray[np.uint8],
    res: float,
    ox: float,
    oy: float,
) -> NDArray[np.int64]:
    """The cells ``(ix, iy)`` of ``plan`` (``(N, >= 2)``, its points first made no farther
    apart than ``res`` as MapGrid's ``adjustPlanResolution``: ``a + j (b - a) / steps``)
    from its first point on a known cell of the costmap ``costs`` (origin ``ox, oy``) up
    to the point before the next one off the map or on unknown cost; ``(0, 2)`` when no
    point is on a known cell."""
    h, w = costs.shape
    n = plan.shape[0]
    total = 1
    for i in range(n - 1):
        d = math.hypot(plan[i + 1, 0] - plan[i, 0], plan[i + 1, 1] - plan[i, 1])
        total += int(math.ceil(d / res)) if d > res else 1
    out = np.empty((total, 2), dtype=np.int64)
    m = 0
    started = False
    for i in range(n):
        if i < n - 1:
            ax, ay = plan[i, 0], plan[i, 1]
            dx, dy = plan[i + 1, 0] - ax, plan[i + 1, 1] - ay
            d = math.hypot(dx, dy)
            steps = int(math.ceil(d / res)) if d > res else 1
        else:
            ax, ay, dx, dy, steps = plan[i, 0], plan[i, 1], 0.0, 0.0, 1
        for j in range(steps):
            px = ax + (j * dx) / steps
            py = ay + (j * dy) / steps
            cx = int(math.floor((px - ox) / res))
            cy = int(math.floor((py - oy) / res))
            ok = px >= ox and py >= oy and cx < w and cy < h and costs[cy, cx] != NO_INFO
            if ok:
                started = True
                out[m, 0] = cx
                out[m, 1] = cy
                m += 1
            elif started:
                return out[:m]
    return out[:m]


@_jit
def sample_grid(
    xs: NDArray[np.float64], ys: NDArray[np.float64], ths: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Every ``(x, y, th)`` of the three velocity samplings, ``th`` fastest, then ``y``."""
    out = np.empty((xs.shape[0] * ys.shape[0] * ths.shape[0], 3))
    k = 0
    for x in xs:
        for y in ys:
            for th in ths:
                out[k, 0] = x
                out[k, 1] = y
                out[k, 2] = th
                k += 1
    return out


@_jit
def _cell(w: int, h: int, res: float, ox: float, oy: float, x: float, y: float) -> tuple[int, int]:
    """The map cell of ``(x, y)``; ``(-1, -1)`` off the map."""
    if x < ox or y < oy:
        return -1, -1
    mx = int((x - ox) / res)
    my = int((y - oy) / res)
    if mx >= w or my >= h:
        return -1, -1
    return mx, my


#: :func:`_grid_critics`' answer to a read outside the window of final grid values
OUTSIDE_WINDOW = -1000.0


@_jit
def _in_window(window: NDArray[np.int64], mx: int, my: int) -> bool:
    return window[0] <= mx <= window[2] and window[1] <= my <= window[3]


@_jit
def _grid_critics(
    traj: NDArray[np.float64],
    num: int,
    res: float,
    ox: float,
    oy: float,
    size: float,
    path_grid: NDArray[np.float64],
    goal_grid: NDArray[np.float64],
    front_grid: NDArray[np.float64],
    scales: NDArray[np.float64],
    window: NDArray[np.int64],
) -> tuple[float, float]:
    """Critics 3-6 of the module docstring over the first ``num`` poses of ``traj`` (x, y,
    th, cos th, sin th): ``(failure, cost)``, the failure (< 0) of the first critic that
    fails, else 0 and the critics' weighted sum.

    Each critic, as MapGridCostFunction, visits every point and stops at its first
    failure: the two at ``forward_point_distance`` ahead (goal front, alignment) read
    different grids at the same points and fail only off the map, so one pass serves
    both; path and goal share the centres, and the path critic's failure, coming first,
    wins over the goal critic's at any point.

    A grid read outside ``window`` (``x0, y0, x1, y1``: the cells whose values are final,
    see :func:`target_distance_window`) returns :data:`OUTSIDE_WINDOW` at once.
    """
    h, w = path_grid.shape
    front_s, align_s, path_s, goal_s, fpd = scales[1], scales[2], scales[3], scales[4], scales[6]
    front_v = 0.0
    align_v = 0.0
    if front_s != 0.0 or align_s != 0.0:
        mx = -1
        my = -1
        for i in range(num):
            px = traj[i, 0] + fpd * traj[i, 3]
            py = traj[i, 1] + fpd * traj[i, 4]
            mx, my = _cell(w, h, res, ox, oy, px, py)
            if mx < 0:
                return -4.0, 0.0
        if not _in_window(window, mx, my):
            return OUTSIDE_WINDOW, 0.0
        front_v = front_grid[my, mx]
        align_v = path_grid[my, mx]
    path_v = 0.0
    goal_v = 0.0
    on_path = path_s != 0.0
    on_goal = goal_s != 0.0
    if on_path or on_goal:
        goal_fail = 0.0
        mx = -1
        my = -1
        for i in range(num):
            mx, my = _cell(w, h, res, ox, oy, traj[i, 0], traj[i, 1])
            if mx < 0:
                if on_path:
                    return -4.0, 0.0
                goal_fail = -4.0
                break
            if not _in_window(window, mx, my):
                return OUTSIDE_WINDOW, 0.0
            if on_path:
                v = path_grid[my, mx]
                if v == size:
                    return -3.0, 0.0
                if v == size + 1.0:
                    return -2.0, 0.0
            if on_goal and goal_fail == 0.0:
                v = goal_grid[my, mx]
                if v == size:
                    goal_fail = -3.0
                elif v == size + 1.0:
                    goal_fail = -2.0
                if goal_fail < 0.0 and not on_path:
                    break
        if goal_fail < 0.0:
            return goal_fail, 0.0
        path_v = path_grid[my, mx]
        goal_v = goal_grid[my, mx]
    total = 0.0
    if front_s != 0.0 and front_v != 0.0:
        total += front_v * front_s
    if align_s != 0.0 and align_v != 0.0:
        total += align_v * align_s
    if on_path and path_v != 0.0:
        total += path_v * path_s
    if on_goal and goal_v != 0.0:
        total += goal_v * goal_s
    return 0.0, total


@_jit
def _gen_ok(vx: float, vy: float, vth: float, gen: NDArray[np.float64]) -> bool:
    eps = 1e-4
    vmag = math.hypot(vx, vy)
    if (gen[3] >= 0 and vmag + eps < gen[3]) and (gen[5] >= 0 and abs(vth) + eps < gen[5]):
        return False
    return not (gen[4] >= 0 and vmag - eps > gen[4])


@_jit
def _rollout_cap(vx: float, vy: float, vth: float, gen: NDArray[np.float64]) -> int:
    vmag = math.hypot(vx, vy)
    num = int(math.ceil(max(vmag * gen[0] / gen[1], abs(vth) * gen[0] / gen[2])))
    dt = gen[0] / max(num, 1)
    return num + int(math.ceil(gen[6] / dt)) + 4


@_jit
def _same_rows(a: NDArray[np.int64], b: NDArray[np.int64], n: int) -> bool:
    same = True
    for i in range(n):
        if a[i, 0] != b[i, 0] or a[i, 1] != b[i, 1]:
            same = False
            break
    return same


@_jit
def score_rollouts(
    samples: NDArray[np.float64],
    pos: NDArray[np.float64],
    vel: NDArray[np.float64],
    gen: NDArray[np.float64],
    acc: NDArray[np.float64],
    continued_acceleration: bool,
    costs: NDArray[np.uint8],
    res: float,
    ox: float,
    oy: float,
    path_grid: NDArray[np.float64],
    goal_grid: NDArray[np.float64],
    front_grid: NDArray[np.float64],
    fp: NDArray[np.float64],
    scales: NDArray[np.float64],
    scaling: NDArray[np.float64],
    sum_scores: bool,
    flags: NDArray[np.bool_],
    prune: bool,
    out: NDArray[np.float64],
    window: NDArray[np.int64],
) -> int:
    """Score every velocity sample (the generation checks, then the critics of the module
    docstring), writing the total cost (``< 0``: rejected; -100: not generated) to ``out``.

    The grid critics and the cheap rejections are computed for every sample first; with
    ``prune`` the obstacle critic then runs in increasing order of that partial cost and
    is skipped for samples whose partial cost already exceeds the best total, or stopped
    along a trajectory as soon as the cost so far exceeds it (their ``out`` is that cost
    so far, a lower bound): the choice is the same as scoring every critic of every
    sample, as SimpleScoredSamplingPlanner's early break.

    Args:
        samples: ``(K, 3)`` target velocities ``vx, vy, vth``.
        pos, vel: the robot's pose (global frame) and velocity (robot frame).
        gen: ``sim_time, sim_granularity, angular_sim_granularity, min_vel_trans,
            max_vel_trans, min_vel_theta, stop_time_buffer``.
        acc: acceleration limits (for ``continued_acceleration``, i.e. ``use_dwa: false``).
        costs, res, ox, oy: the local costmap.
        path_grid, goal_grid, front_grid: the map grids (cells; obstacle = size, unreachable
            = size + 1).
        fp: ``(M, 2)`` footprint (M < 3: a point / circular robot).
        scales: ``occdist, goal_front, alignment, path, goal, twirling,
            forward_point_distance``.
        scaling: ``scaling_speed, max_vel_trans, max_scaling_factor`` (the footprint grows by
            up to ``max_scaling_factor`` from ``scaling_speed`` to ``max_vel_trans``).
        flags: oscillation ``forward_pos_only, forward_neg_only, strafe_pos_only,
            strafe_neg_only, rot_pos_only, rot_neg_only``.
        window: the cells whose grid values are final (``x0, y0, x1, y1``, inclusive;
            :func:`target_distance_window`).

    Returns:
        The index of the best sample (first of equal costs), -1 if none is valid, -2 if
        a rollout read a grid outside ``window`` (nothing scored: widen the window).
    """
    h, w = costs.shape
    size = float(h * w)
    twirl_s = scales[5]
    occ_s = scales[0]
    nk = samples.shape[0]
    cap = 8
    for k in range(nk):
        cap = max(cap, _rollout_cap(samples[k, 0], samples[k, 1], samples[k, 2], gen))
    traj = np.empty((cap, 5))
    keys = np.empty((nk, 2))
    nkeys = np.zeros(1, dtype=np.int64)
    heads = np.empty((nk, cap, 3))
    buf = np.empty((w + h + 4, 2), dtype=np.int64)
    partial = np.empty(nk)
    for k in range(nk):
        vx = samples[k, 0]
        vy = samples[k, 1]
        vth = samples[k, 2]
        if not _gen_ok(vx, vy, vth, gen):
            out[k] = -100.0
            continue
        num, _extra = shared_rollout(
            k, samples, pos, vel, gen, acc, continued_acceleration, 0.0, keys, nkeys, heads, traj
        )
        if num == 0:
            out[k] = -100.0
            continue
        if (flags[0] and vx < 0.0) or (flags[1] and vx > 0.0):
            out[k] = -5.0
            continue
        if (flags[2] and vy < 0.0) or (flags[3] and vy > 0.0):
            out[k] = -7.0
            continue
        if (flags[4] and vth < 0.0) or (flags[5] and vth > 0.0):
            out[k] = -6.0
            continue
        failed, total = _grid_critics(
            traj, num, res, ox, oy, size, path_grid, goal_grid, front_grid, scales, window
        )
        if failed == OUTSIDE_WINDOW:
            return -2
        if failed < 0:
            out[k] = failed
            continue
        if twirl_s != 0.0 and vth != 0.0:
            total += abs(vth) * twirl_s
        partial[k] = total
        out[k] = total
    if occ_s == 0.0:
        best = -1
        for k in range(nk):
            if out[k] >= 0 and (best < 0 or out[k] < out[best]):
                best = k
        return best
    order = np.argsort(np.where(out >= 0, out, np.inf), kind="mergesort")
    ncells = fp.shape[0] + 1 if fp.shape[0] >= 3 else 1
    cells = np.empty((fp.shape[0] + 1, 2), dtype=np.int64)
    last = np.empty_like(cells)
    best = -1
    best_cost = np.inf
    for q in range(nk):
        k = order[q]
        if out[k] < 0:
            break
        if prune and partial[k] > best_cost:
            continue
        vx = samples[k, 0]
        vy = samples[k, 1]
        num, extra = shared_rollout(
            k, samples, pos, vel, gen, acc, continued_acceleration, gen[6], keys, nkeys, heads,
            traj,
        )  # fmt: skip
        vmag = math.hypot(vx, vy)
        scale = 1.0
        if vmag > scaling[0] and scaling[1] > scaling[0]:
            scale = scaling[2] * (vmag - scaling[0]) / (scaling[1] - scaling[0]) + 1.0
        oc = 0.0
        bad = 0.0
        known = False
        fc = 0.0
        beaten = False
        for i in range(num + extra):
            # footprint_cost, reusing the last pose's cost when the centre and vertex
            # cells are the same (the cost is a function of those cells)
            if not footprint_cells(
                w, h, res, ox, oy, traj[i, 0], traj[i, 1], traj[i, 3], traj[i, 4], fp, scale,
                cells,
            ):  # fmt: skip
                bad = -6.0
                break
            if not (known and _same_rows(cells, last, ncells)):
                fc = cells_cost(costs, cells, fp.shape[0], buf)
                last[:ncells] = cells[:ncells]
                known = True
            if fc < 0:
                bad = fc
                break
            if i < num:
                oc = oc + fc if sum_scores else max(oc, fc)
                if prune and partial[k] + oc * occ_s > best_cost:
                    beaten = True  # the cost only grows from here: this sample cannot win
                    break
        if bad < 0:
            out[k] = bad
            continue
        out[k] = partial[k] + oc * occ_s
        if beaten:
            continue  # out[k]: a lower bound, above the best
        if out[k] < best_cost or (out[k] == best_cost and k < best):
            best_cost = out[k]
            best = k
    return best
