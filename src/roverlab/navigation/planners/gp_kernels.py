"""global_planner's compiled core: Dijkstra and A* expansions, potential calculators,
grid path.

Cell costs go through global_planner's ``getCost``: a costmap cost ``c`` below
``lethal_cost - 1`` (or unknown, 255, when allowed) costs ``c * cost_factor +
neutral_cost``, at most ``lethal_cost - 1``; anything else is lethal. The potential of a
cell is ``min(neighbour) + cost`` (``use_quadratic: false``) or navfn's quadratic
interpolation of its two lowest neighbours (``use_quadratic: true``).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.planners.navfn_kernels import POT_HIGH

__all__ = ["astar", "clear_endpoint", "dijkstra", "grid_path"]

_jit = numba.njit(cache=True, nogil=True)
INVSQRT2 = 0.707106781


@_jit
def _cost(
    costs: NDArray[np.uint8], n: int, lethal: int, neutral: float, factor: float, unknown: bool
) -> float:
    c = float(costs[n])
    if c < lethal - 1 or (unknown and costs[n] == 255):
        c = c * factor + neutral
        if c >= lethal:
            c = lethal - 1.0
        return c
    return float(lethal)


@_jit
def _potential(
    pot: NDArray[np.float32], cost: float, n: int, nx: int, quadratic: bool, prev: float
) -> float:
    ns = pot.shape[0]
    left = pot[n - 1] if n - 1 >= 0 else POT_HIGH
    right = pot[n + 1] if n + 1 < ns else POT_HIGH
    up = pot[n - nx] if n - nx >= 0 else POT_HIGH
    down = pot[n + nx] if n + nx < ns else POT_HIGH
    hf = float(int(cost) & 0xFF)  # PotentialCalculator takes an unsigned char
    if not quadratic:
        if prev < 0:
            prev = min(min(left, right), min(up, down))
        return prev + hf
    tc = left if left < right else right
    ta = up if up < down else down
    dc = tc - ta
    if dc < 0:
        dc = -dc
        ta = tc
    if dc >= hf:
        return ta + hf
    d = dc / hf
    v = -0.2301 * d * d + 0.5307 * d + 0.7040
    return ta + hf * v


@_jit
def _push(
    buf: NDArray[np.int64],
    end: int,
    n: int,
    pending: NDArray[np.bool_],
    costs: NDArray[np.uint8],
    lethal: int,
    neutral: float,
    factor: float,
    unknown: bool,
) -> int:
    if (
        0 <= n < pending.shape[0]
        and not pending[n]
        and _cost(costs, n, lethal, neutral, factor, unknown) < lethal
    ):
        buf[end] = n
        pending[n] = True
        return end + 1
    return end


@_jit
def dijkstra(
    costs: NDArray[np.uint8],
    nx: int,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    cycles: int,
    lethal: int,
    neutral: float,
    factor: float,
    unknown: bool,
    quadratic: bool,
    precise: bool,
    stop_at_end: bool,
    pot: NDArray[np.float32],
) -> bool:
    """global_planner's ``DijkstraExpansion::calculatePotentials`` (potential 0 at the
    start, spreading until the end cell has a potential). ``precise``: the start's
    potential is spread over its 2 x 2 block by the fractional position (global_planner's
    ``setPreciseStart``). ``stop_at_end`` False spreads over everything reachable.

    Returns:
        Whether the end cell got a potential.
    """
    ns = pot.shape[0]
    pending = np.zeros(ns, dtype=np.bool_)
    cur = np.empty(ns, dtype=np.int64)
    nxt = np.empty(ns, dtype=np.int64)
    over = np.empty(ns, dtype=np.int64)
    ce = 0
    ne = 0
    oe = 0
    pot[:] = POT_HIGH
    k = int(start_y) * nx + int(start_x)
    a = (lethal, neutral, factor, unknown)
    if precise:
        dx = start_x - int(start_x)
        dy = start_y - int(start_y)
        dx = math.floor(dx * 100 + 0.5) / 100
        dy = math.floor(dy * 100 + 0.5) / 100
        for idx, val in (
            (k, neutral * 2 * dx * dy),
            (k + 1, neutral * 2 * (1 - dx) * dy),
            (k + nx, neutral * 2 * dx * (1 - dy)),
            (k + nx + 1, neutral * 2 * (1 - dx) * (1 - dy)),
        ):
            if 0 <= idx < ns:
                pot[idx] = val
        for idx in (
            k + 2,
            k - 1,
            k + nx - 1,
            k + nx + 2,
            k - nx,
            k - nx + 1,
            k + 2 * nx,
            k + 2 * nx + 1,
        ):
            ce = _push(cur, ce, idx, pending, costs, *a)
    else:
        pot[k] = 0.0
        for idx in (k + 1, k - 1, k - nx, k + nx):
            ce = _push(cur, ce, idx, pending, costs, *a)
    end = int(end_y) * nx + int(end_x)
    threshold = float(lethal)
    inc = 2.0 * neutral
    for _ in range(cycles):
        if ce == 0 and ne == 0:
            return pot[end] < POT_HIGH
        for i in range(ce):
            pending[cur[i]] = False
        for i in range(ce):
            n = cur[i]
            c = _cost(costs, n, *a)
            if c >= lethal:
                continue
            p = _potential(pot, c, n, nx, quadratic, -1.0)
            if p < pot[n]:
                le = INVSQRT2 * _cost(costs, n - 1, *a) if n - 1 >= 0 else 0.0
                re = INVSQRT2 * _cost(costs, n + 1, *a) if n + 1 < ns else 0.0
                ue = INVSQRT2 * _cost(costs, n - nx, *a) if n - nx >= 0 else 0.0
                de = INVSQRT2 * _cost(costs, n + nx, *a) if n + nx < ns else 0.0
                pot[n] = p
                p = float(pot[n])
                for nb, e in ((n - 1, le), (n + 1, re), (n - nx, ue), (n + nx, de)):
                    if 0 <= nb < ns and pot[nb] > p + e:
                        if p < threshold:
                            ne = _push(nxt, ne, nb, pending, costs, *a)
                        else:
                            oe = _push(over, oe, nb, pending, costs, *a)
        cur, nxt = nxt, cur
        ce = ne
        ne = 0
        if ce == 0:
            threshold += inc
            cur, over = over, cur
            ce = oe
            oe = 0
        if stop_at_end and pot[end] < POT_HIGH:
            return True
    return pot[end] < POT_HIGH


@_jit
def astar(
    costs: NDArray[np.uint8],
    nx: int,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    cycles: int,
    lethal: int,
    neutral: float,
    factor: float,
    unknown: bool,
    quadratic: bool,
    stop_at_end: bool,
    pot: NDArray[np.float32],
) -> bool:
    """global_planner's ``AStarExpansion``: a binary heap on ``potential + manhattan
    distance to the end * neutral_cost``; a cell's potential is set once, when first
    reached, from the cell it was reached from."""
    ns = pot.shape[0]
    pot[:] = POT_HIGH
    heap_v = np.empty(4 * ns + 4, dtype=np.float64)
    heap_i = np.empty(4 * ns + 4, dtype=np.int64)
    size = 0
    s = int(start_y) * nx + int(start_x)
    goal = int(end_y) * nx + int(end_x)
    ex = int(end_x)
    ey = int(end_y)
    pot[s] = 0.0
    heap_v[0] = 0.0
    heap_i[0] = s
    size = 1
    cycle = 0
    while size > 0 and cycle < cycles:
        top = heap_i[0]
        size -= 1
        if size > 0:
            # pop: move the last to the root and sift down
            v = heap_v[size]
            it = heap_i[size]
            j = 0
            while True:
                c = 2 * j + 1
                if c >= size:
                    break
                if c + 1 < size and heap_v[c + 1] < heap_v[c]:
                    c += 1
                if heap_v[c] < v:
                    heap_v[j] = heap_v[c]
                    heap_i[j] = heap_i[c]
                    j = c
                else:
                    break
            heap_v[j] = v
            heap_i[j] = it
        if top == goal and stop_at_end:
            return True
        for nb in (top + 1, top - 1, top + nx, top - nx):
            if nb < 0 or nb >= ns or pot[nb] < POT_HIGH:
                continue
            cn = _cost(costs, nb, lethal, neutral, factor, unknown)
            if cn >= lethal:
                continue
            pot[nb] = _potential(pot, cn, nb, nx, quadratic, float(pot[top]))
            key = float(pot[nb]) + (abs(ex - nb % nx) + abs(ey - nb // nx)) * neutral
            # push and sift up
            j = size
            size += 1
            while j > 0:
                par = (j - 1) // 2
                if heap_v[par] > key:
                    heap_v[j] = heap_v[par]
                    heap_i[j] = heap_i[par]
                    j = par
                else:
                    break
            heap_v[j] = key
            heap_i[j] = nb
        cycle += 1
    return pot[goal] < POT_HIGH


@_jit
def clear_endpoint(
    costs: NDArray[np.uint8],
    pot: NDArray[np.float32],
    nx: int,
    gx: int,
    gy: int,
    s: int,
    neutral: float,
    quadratic: bool,
) -> None:
    """global_planner's ``clearEndpoint``: unreached cells within ``s`` of the goal take a
    potential from their neighbours (cost ``costmap cost + neutral``, at most 255)."""
    ns = pot.shape[0]
    start = gy * nx + gx
    for i in range(-s, s + 1):
        for j in range(-s, s + 1):
            n = start + i + nx * j
            if n < 0 or n >= ns or pot[n] < POT_HIGH:
                continue
            c = min(float(costs[n]) + neutral, 255.0)
            pot[n] = _potential(pot, c, n, nx, quadratic, -1.0)


@_jit
def grid_path(
    pot: NDArray[np.float32],
    nx: int,
    start_x: float,
    start_y: float,
    end_x: float,
    end_y: float,
    out: NDArray[np.float64],
) -> int:
    """global_planner's ``GridPath``: from the end, step to the lowest of the 8 neighbours
    until the start cell. Returns the count of ``(x, y)`` rows in ``out``, 0 on failure."""
    ns = pot.shape[0]
    cx = end_x
    cy = end_y
    start = int(start_y) * nx + int(start_x)
    n = 0
    out[n, 0] = cx
    out[n, 1] = cy
    n += 1
    steps = 0
    while int(cy) * nx + int(cx) != start:
        best = 1e10
        bx = 0
        by = 0
        for xd in range(-1, 2):
            for yd in range(-1, 2):
                if xd == 0 and yd == 0:
                    continue
                x = int(cx) + xd
                y = int(cy) + yd
                idx = x + nx * y
                if idx < 0 or idx >= ns:
                    continue
                if pot[idx] < best:
                    best = pot[idx]
                    bx = x
                    by = y
        if bx == 0 and by == 0:
            return 0
        cx = float(bx)
        cy = float(by)
        if n >= out.shape[0]:
            return 0
        out[n, 0] = cx
        out[n, 1] = cy
        n += 1
        steps += 1
        if steps > ns * 4:
            return 0
    return n
