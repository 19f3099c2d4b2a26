"""navfn's compiled core: potential propagation and gradient-descent path extraction.

Arrays are flat ``ny * nx`` (index ``y * nx + x``). Costs are navfn's ``COSTTYPE`` values:
50 (``COST_NEUTRAL``) .. 253 traversable, 254 (``COST_OBS``) an obstacle. The potential
starts at 0 in the *goal* cell of the propagation and spreads by navfn's planar-wave
update (the quadratic interpolation of the two lowest neighbours) through three priority
buffers (current, next, overflow) with a threshold raised by ``2 * COST_NEUTRAL`` each time
the current buffer runs dry (Dijkstra), or with the Euclidean distance to the target cell
added to the threshold test (A*).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["POT_HIGH", "calc_path", "propagate"]

_jit = numba.njit(cache=True, nogil=True)

POT_HIGH = 1.0e10
COST_OBS = 254
COST_NEUTRAL = 50
_OSC_TOL = 0.25  # cells: the path's oscillation test
INVSQRT2 = 0.707106781


@_jit
def _push(
    buf: NDArray[np.int64],
    end: int,
    n: int,
    ns: int,
    pending: NDArray[np.bool_],
    cost: NDArray[np.uint8],
) -> int:
    if 0 <= n < ns and not pending[n] and cost[n] < COST_OBS:
        buf[end] = n
        pending[n] = True
        return end + 1
    return end


@_jit
def _update(
    n: int,
    pot: NDArray[np.float32],
    cost: NDArray[np.uint8],
    nx: int,
    cur_t: float,
    astar: bool,
    tx: int,
    ty: int,
    nxt: NDArray[np.int64],
    nxt_end: int,
    over: NDArray[np.int64],
    over_end: int,
    pending: NDArray[np.bool_],
) -> tuple[int, int]:
    ns = pot.shape[0]
    if n - nx < 0 or n + nx >= ns or cost[n] >= COST_OBS:
        return nxt_end, over_end
    left = pot[n - 1]
    right = pot[n + 1]
    up = pot[n - nx]
    down = pot[n + nx]
    tc = left if left < right else right
    ta = up if up < down else down
    hf = np.float32(cost[n])
    dc = tc - ta
    if dc < 0:
        dc = -dc
        ta = tc
    if dc >= hf:
        p = ta + hf
    else:
        d = dc / hf
        v = np.float32(-0.2301 * d * d + 0.5307 * d + 0.7040)
        p = ta + hf * v
    p = np.float32(p)
    if p < pot[n]:
        le = INVSQRT2 * np.float32(cost[n - 1])
        re = INVSQRT2 * np.float32(cost[n + 1])
        ue = INVSQRT2 * np.float32(cost[n - nx])
        de = INVSQRT2 * np.float32(cost[n + nx])
        pot[n] = p
        q = float(p)
        if astar:
            q += math.hypot(n % nx - tx, n // nx - ty) * COST_NEUTRAL
        if q < cur_t:
            if left > q + le:
                nxt_end = _push(nxt, nxt_end, n - 1, ns, pending, cost)
            if right > q + re:
                nxt_end = _push(nxt, nxt_end, n + 1, ns, pending, cost)
            if up > q + ue:
                nxt_end = _push(nxt, nxt_end, n - nx, ns, pending, cost)
            if down > q + de:
                nxt_end = _push(nxt, nxt_end, n + nx, ns, pending, cost)
        else:
            if left > q + le:
                over_end = _push(over, over_end, n - 1, ns, pending, cost)
            if right > q + re:
                over_end = _push(over, over_end, n + 1, ns, pending, cost)
            if up > q + ue:
                over_end = _push(over, over_end, n - nx, ns, pending, cost)
            if down > q + de:
                over_end = _push(over, over_end, n + nx, ns, pending, cost)
    return nxt_end, over_end


@_jit
def propagate(
    cost: NDArray[np.uint8],
    nx: int,
    ny: int,
    goal: int,
    target: int,
    cycles: int,
    at_target: bool,
    astar: bool,
    pot: NDArray[np.float32],
) -> int:
    """navfn's ``setupNavFn`` + ``propNavFnDijkstra`` / ``propNavFnAstar``.

    Args:
        cost: flat navfn costs (the outer cells are set to ``COST_OBS`` here).
        nx, ny: grid size.
        goal: cell where the potential is 0 (NavfnROS puts the robot here).
        target: cell whose potential stops the propagation (NavfnROS: the goal).
        cycles: at most this many buffer swaps.
        at_target: stop once ``target`` has a potential (always with A*).
        astar: A* priorities (Euclidean distance to ``target`` times ``COST_NEUTRAL``).
        pot: out, the potential of every cell (``POT_HIGH`` where not reached).

    Returns:
        The number of cycles used (``cycles`` if it ran out).
    """
    ns = nx * ny
    for i in range(nx):
        cost[i] = COST_OBS
        cost[(ny - 1) * nx + i] = COST_OBS
    for j in range(ny):
        cost[j * nx] = COST_OBS
        cost[j * nx + nx - 1] = COST_OBS
    pot[:] = POT_HIGH
    pending = np.zeros(ns, dtype=np.bool_)
    cur = np.empty(ns, dtype=np.int64)
    nxt = np.empty(ns, dtype=np.int64)
    over = np.empty(ns, dtype=np.int64)
    cur_end = 0
    nxt_end = 0
    over_end = 0
    cur_t = float(COST_OBS)
    pri_inc = 2.0 * COST_NEUTRAL
    pot[goal] = 0.0
    cur_end = _push(cur, cur_end, goal + 1, ns, pending, cost)
    cur_end = _push(cur, cur_end, goal - 1, ns, pending, cost)
    cur_end = _push(cur, cur_end, goal - nx, ns, pending, cost)
    cur_end = _push(cur, cur_end, goal + nx, ns, pending, cost)
    tx = target % nx
    ty = target // nx
    if astar:
        cur_t += math.hypot(goal % nx - tx, goal // nx - ty) * COST_NEUTRAL
    cycle = 0
    while cycle < cycles:
        if cur_end == 0 and nxt_end == 0:
            break
        for i in range(cur_end):
            pending[cur[i]] = False
        for i in range(cur_end):
            nxt_end, over_end = _update(
                cur[i], pot, cost, nx, cur_t, astar, tx, ty, nxt, nxt_end, over, over_end, pending
            )
        cur, nxt = nxt, cur
        cur_end = nxt_end
        nxt_end = 0
        if cur_end == 0:
            cur_t += pri_inc
            cur, over = over, cur
            cur_end = over_end
            over_end = 0
        cycle += 1
        if (at_target or astar) and pot[target] < POT_HIGH:
            break
    return cycle


@_jit
def _p(pot: NDArray[np.float32], n: int) -> float:
    if n < 0 or n >= pot.shape[0]:
        return POT_HIGH
    return float(pot[n])


@_jit
def _grad(
    pot: NDArray[np.float32],
    n: int,
    nx: int,
    gx: NDArray[np.float32],
    gy: NDArray[np.float32],
    obs_grad: float,
) -> None:
    """navfn's ``gradCell`` (cached in ``gx``, ``gy``)."""
    ns = pot.shape[0]
    if n < 0 or n >= ns or gx[n] + gy[n] > 0.0:
        return
    if n < nx or n > ns - nx:
        return
    cv = float(pot[n])
    dx = 0.0
    dy = 0.0
    if cv >= POT_HIGH:
        if _p(pot, n - 1) < POT_HIGH:
            dx = -obs_grad
        elif _p(pot, n + 1) < POT_HIGH:
            dx = obs_grad
        if _p(pot, n - nx) < POT_HIGH:
            dy = -obs_grad
        elif _p(pot, n + nx) < POT_HIGH:
            dy = obs_grad
    else:
        if _p(pot, n - 1) < POT_HIGH:
            dx += _p(pot, n - 1) - cv
        if _p(pot, n + 1) < POT_HIGH:
            dx += cv - _p(pot, n + 1)
        if _p(pot, n - nx) < POT_HIGH:
            dy += _p(pot, n - nx) - cv
        if _p(pot, n + nx) < POT_HIGH:
            dy += cv - _p(pot, n + nx)
    norm = math.hypot(dx, dy)
    if norm > 0:
        gx[n] = dx / norm
        gy[n] = dy / norm


@_jit
def calc_path(
    pot: NDArray[np.float32],
    nx: int,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    max_steps: int,
    navfn_stop: bool,
    obs_grad: float,
    out: NDArray[np.float64],
) -> int:
    """Gradient descent on the potential from ``(start_x, start_y)`` (cell units) down to
    the potential's zero at ``(end_x, end_y)``, steps of half a cell (navfn's ``calcPath``
    and global_planner's ``GradientPath``).

    Where one of the 8 neighbours is unreached (or the path oscillates: a point within a
    quarter of a cell of the one two steps back) it steps to the lowest neighbour
    instead. ``navfn_stop``: stop when the nearest cell's potential is
    below ``COST_NEUTRAL`` (navfn); otherwise when within half a cell of the end
    (global_planner) or in one of the four cells of the end's 2 x 2 block, the cells
    global_planner's precise start seeds. global_planner's test alone misses the end when
    the descent arrives at a seeded cell more than half a cell from it: the seeds are the
    potential's minima (with the end on a cell boundary two of them are 0), so the grid
    descent stays in that cell until it gives up ("failed to get a plan from potential
    when a legal potential was found", from a robot standing in inflated cost). Writes
    ``(x, y)`` rows into ``out``; returns the count, 0 on failure.
    """
    ns = pot.shape[0]
    gx = np.zeros(ns, dtype=np.float32)
    gy = np.zeros(ns, dtype=np.float32)
    stc = int(start_y) * nx + int(start_x)
    dx = start_x - int(start_x)
    dy = start_y - int(start_y)
    npath = 0
    cap = out.shape[0]
    end_cell = int(end_y) * nx + int(end_x)  # the 2 x 2 block: end_cell, +1, +nx, +nx + 1
    for _ in range(max_steps):
        if navfn_stop:
            near = stc + int(round(dx)) + nx * int(round(dy))
            near = max(0, min(ns - 1, near))
            if pot[near] < COST_NEUTRAL:
                if npath < cap:
                    out[npath, 0] = end_x
                    out[npath, 1] = end_y
                    npath += 1
                return npath
        else:
            px = stc % nx + dx
            py = stc // nx + dy
            d = stc - end_cell
            if (abs(px - end_x) < 0.5 and abs(py - end_y) < 0.5) or (d in (0, 1, nx, nx + 1)):
                if npath < cap:
                    out[npath, 0] = end_x
                    out[npath, 1] = end_y
                    npath += 1
                return npath
        if stc < nx or stc > ns - nx or npath >= cap:
            return 0
        out[npath, 0] = stc % nx + dx
        out[npath, 1] = stc // nx + dy
        npath += 1
        # navfn / global_planner test for exact equality; a descent caught between two
        # points (a saddle of the potential, near the start's 2 x 2 block) repeats them
        # only approximately, for dozens of cycles, each one a zig-zag in the plan; two
        # half-cell steps of a real descent are about a cell apart
        osc = (
            npath > 2
            and abs(out[npath - 1, 0] - out[npath - 3, 0]) < _OSC_TOL
            and abs(out[npath - 1, 1] - out[npath - 3, 1]) < _OSC_TOL
        )
        stcnx = stc + nx
        stcpx = stc - nx
        if (
            osc
            or _p(pot, stc) >= POT_HIGH
            or _p(pot, stc + 1) >= POT_HIGH
            or _p(pot, stc - 1) >= POT_HIGH
            or _p(pot, stcnx) >= POT_HIGH
            or _p(pot, stcnx + 1) >= POT_HIGH
            or _p(pot, stcnx - 1) >= POT_HIGH
            or _p(pot, stcpx) >= POT_HIGH
            or _p(pot, stcpx + 1) >= POT_HIGH
            or _p(pot, stcpx - 1) >= POT_HIGH
        ):
            minc = stc
            minp = float(int(_p(pot, stc))) if _p(pot, stc) < POT_HIGH else POT_HIGH
            for c in (
                stcpx - 1,
                stcpx,
                stcpx + 1,
                stc - 1,
                stc + 1,
                stcnx - 1,
                stcnx,
                stcnx + 1,
            ):
                if _p(pot, c) < minp:
                    minp = _p(pot, c)
                    minc = c
            stc = minc
            dx = 0.0
            dy = 0.0
            if _p(pot, stc) >= POT_HIGH:
                return 0
        else:
            _grad(pot, stc, nx, gx, gy, obs_grad)
            _grad(pot, stc + 1, nx, gx, gy, obs_grad)
            _grad(pot, stcnx, nx, gx, gy, obs_grad)
            _grad(pot, stcnx + 1, nx, gx, gy, obs_grad)
            x1 = (1.0 - dx) * gx[stc] + dx * gx[stc + 1]
            x2 = (1.0 - dx) * gx[stcnx] + dx * gx[stcnx + 1]
            x = (1.0 - dy) * x1 + dy * x2
            y1 = (1.0 - dx) * gy[stc] + dx * gy[stc + 1]
            y2 = (1.0 - dx) * gy[stcnx] + dx * gy[stcnx + 1]
            y = (1.0 - dy) * y1 + dy * y2
            if x == 0.0 and y == 0.0:
                return 0
            ss = 0.5 / math.hypot(x, y)
            dx += x * ss
            dy += y * ss
            if dx > 1.0:
                stc += 1
                dx -= 1.0
            if dx < -1.0:
                stc -= 1
                dx += 1.0
            if dy > 1.0:
                stc += nx
                dy -= 1.0
            if dy < -1.0:
                stc -= nx
                dy += 1.0
    return 0
