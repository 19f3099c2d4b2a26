"""explore_lite's frontier search (m-explore ``frontier_search.cpp``), compiled.

From the free cell nearest the robot, a breadth-first search walks the free space (a cell
is entered from one of its 4 neighbours when its cost is not higher); every unknown cell
with a free 4-neighbour that it meets starts a frontier, grown over 8-connected unknown
cells with a free 4-neighbour. A frontier keeps its size (cells), its centroid, its cell
nearest to the robot (``middle``) and that distance; frontiers smaller than
``min_frontier_size`` metres are dropped, the rest sorted by cost::

    cost = potential_scale * min_distance * resolution
         + orientation_scale * |bearing of the centroid - robot heading|
         - gain_scale * size * resolution

(explore_lite's formula; its noetic version multiplies the orientation term by zero,
roverlab applies it, and the default ``orientation_scale`` 0 gives the same result).
Costs are costmap values (0 free, 253/254 obstacle, 255 unknown); an OccupancyGrid is
translated first with :func:`occupancy_to_costs`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.errors import NavigationParamsError

__all__ = ["Frontier", "FrontierSearch", "occupancy_to_costs"]

FREE = 0
NO_INFORMATION = 255
_jit = numba.njit(cache=True, nogil=True)


def occupancy_to_costs(data: NDArray[np.int8]) -> NDArray[np.uint8]:
    """explore_lite's translation of an OccupancyGrid: -1 unknown (255), 0 free, 100 lethal
    (254), 99 inscribed (253), 1..98 scaled to 1..252."""
    d = np.asarray(data).astype(np.int16)
    out = np.empty(d.shape, dtype=np.uint8)
    mid = (d >= 1) & (d <= 98)
    out[mid] = (1 + (d[mid] - 1) * 251 // 97).astype(np.uint8)
    out[d == 0] = FREE
    out[d == 99] = 253
    out[d >= 100] = 254
    out[d < 0] = NO_INFORMATION
    return out


@dataclass(frozen=True)
class Frontier:
    """One frontier: ``size`` cells, ``min_distance`` (m) from the robot to its nearest
    cell ``middle``, its ``centroid``, its first cell ``initial``, its cells' centres
    ``points`` ((N, 2), m) and its ``cost``."""

    size: int
    min_distance: float
    centroid: tuple[float, float]
    middle: tuple[float, float]
    initial: tuple[float, float]
    points: NDArray[np.float64]
    cost: float


@_jit
def _new_frontier_cell(costs: NDArray[np.uint8], flag: NDArray[np.uint8], x: int, y: int) -> bool:
    h, w = costs.shape
    if costs[y, x] != NO_INFORMATION or flag[y, x]:
        return False
    if x > 0 and costs[y, x - 1] == FREE:
        return True
    if x < w - 1 and costs[y, x + 1] == FREE:
        return True
    if y > 0 and costs[y - 1, x] == FREE:
        return True
    return y < h - 1 and costs[y + 1, x] == FREE


@_jit
def _search(
    costs: NDArray[np.uint8], sx: int, sy: int, rx: float, ry: float, cap: int, fcap: int
) -> tuple[NDArray[np.int32], NDArray[np.int64], NDArray[np.float64]]:
    """BFS from ``(sx, sy)``; returns each frontier cell's label (-1 none), each frontier's
    first cell (x, y), and per frontier (size, min distance, centroid x, y, middle x, y)
    in cell units. ``cap`` bounds the cells the search may enter, ``fcap`` the frontier
    cells."""
    h, w = costs.shape
    visited = np.zeros((h, w), np.uint8)
    flag = np.zeros((h, w), np.uint8)
    label = np.full((h, w), -1, np.int32)
    queue = np.empty(cap + 1, np.int64)
    fqueue = np.empty(fcap + 1, np.int64)
    firsts = np.empty((fcap + 1, 2), np.int64)
    stats = np.empty((fcap + 1, 6), np.float64)
    nfront = 0
    head, tail = 0, 0
    queue[tail] = sy * w + sx
    tail += 1
    visited[sy, sx] = 1
    dx4 = (1, -1, 0, 0)
    dy4 = (0, 0, 1, -1)
    while head < tail:
        idx = queue[head]
        head += 1
        x, y = idx % w, idx // w
        for k in range(4):
            nx, ny = x + dx4[k], y + dy4[k]
            if nx < 0 or ny < 0 or nx >= w or ny >= h:
                continue
            if costs[ny, nx] <= costs[y, x] and not visited[ny, nx]:
                visited[ny, nx] = 1
                queue[tail] = ny * w + nx
                tail += 1
            elif _new_frontier_cell(costs, flag, nx, ny):
                flag[ny, nx] = 1
                label[ny, nx] = nfront
                firsts[nfront, 0], firsts[nfront, 1] = nx, ny
                size = 1
                cx, cy = float(nx), float(ny)
                best = math.hypot(nx - rx, ny - ry)
                mx, my = float(nx), float(ny)
                fh, ft = 0, 0
                fqueue[ft] = ny * w + nx
                ft += 1
                while fh < ft:
                    fidx = fqueue[fh]
                    fh += 1
                    fx, fy = fidx % w, fidx // w
                    for ddy in range(-1, 2):
                        for ddx in range(-1, 2):
                            if ddx == 0 and ddy == 0:
                                continue
                            qx, qy = fx + ddx, fy + ddy
                            if qx < 0 or qy < 0 or qx >= w or qy >= h:
                                continue
                            if _new_frontier_cell(costs, flag, qx, qy):
                                flag[qy, qx] = 1
                                label[qy, qx] = nfront
                                size += 1
                                cx += qx
                                cy += qy
                                d = math.hypot(qx - rx, qy - ry)
                                if d < best:
                                    best = d
                                    mx, my = float(qx), float(qy)
                                fqueue[ft] = qy * w + qx
                                ft += 1
                stats[nfront, 0] = size
                stats[nfront, 1] = best
                stats[nfront, 2] = cx / size
                stats[nfront, 3] = cy / size
                stats[nfront, 4] = mx
                stats[nfront, 5] = my
                nfront += 1
    return label, firsts[:nfront].copy(), stats[:nfront].copy()


@_jit
def _nearest_free(costs: NDArray[np.uint8], sx: int, sy: int) -> tuple[int, int]:
    """The free cell nearest ``(sx, sy)`` by 4-connected BFS (explore's ``nearestCell``);
    ``(-1, -1)`` when there is none."""
    h, w = costs.shape
    seen = np.zeros((h, w), np.uint8)
    queue = np.empty(h * w + 1, np.int64)
    head, tail = 0, 0
    queue[tail] = sy * w + sx
    tail += 1
    seen[sy, sx] = 1
    while head < tail:
        idx = queue[head]
        head += 1
        x, y = idx % w, idx // w
        if costs[y, x] == FREE:
            return x, y
        for k in range(4):
            nx = x + (1, -1, 0, 0)[k]
            ny = y + (0, 0, 1, -1)[k]
            if 0 <= nx < w and 0 <= ny < h and not seen[ny, nx]:
                seen[ny, nx] = 1
                queue[tail] = ny * w + nx
                tail += 1
    return -1, -1


class FrontierSearch:
    """explore_lite's ``FrontierSearch`` over a cost grid.

    Args:
        potential_scale: weight of the distance to the frontier.
        gain_scale: weight of the frontier's size.
        orientation_scale: weight of the turn towards the frontier (rad).
        min_frontier_size: frontiers shorter than this (m) are ignored.
    """

    def __init__(
        self,
        *,
        potential_scale: float = 1e-3,
        gain_scale: float = 1.0,
        orientation_scale: float = 0.0,
        min_frontier_size: float = 0.5,
    ) -> None:
        for name, v in (
            ("potential_scale", potential_scale),
            ("gain_scale", gain_scale),
            ("orientation_scale", orientation_scale),
            ("min_frontier_size", min_frontier_size),
        ):
            if not (math.isfinite(v) and v >= 0):
                raise NavigationParamsError(f"explore: {name} must be >= 0, got {v}")
        self.potential_scale = potential_scale
        self.gain_scale = gain_scale
        self.orientation_scale = orientation_scale
        self.min_frontier_size = min_frontier_size

    def search(
        self,
        costs: NDArray[np.uint8],
        *,
        resolution: float,
        origin: tuple[float, float],
        robot: tuple[float, float, float],
    ) -> list[Frontier]:
        """The frontiers seen from ``robot`` ``(x, y, yaw)`` (world frame), cheapest first;
        empty when the robot is off the grid or no free cell is reachable."""
        full = np.asarray(costs, dtype=np.uint8)
        h, w = full.shape
        ox, oy = origin
        rx, ry, ryaw = robot
        cx, cy = int(math.floor((rx - ox) / resolution)), int(math.floor((ry - oy) / resolution))
        if not (0 <= cx < w and 0 <= cy < h):
            return []
        # the search never leaves the known cells by more than one: work on their box
        known_y, known_x = np.nonzero(full != NO_INFORMATION)
        x0 = max(0, min(int(known_x.min(initial=cx)), cx) - 2)
        y0 = max(0, min(int(known_y.min(initial=cy)), cy) - 2)
        x1 = min(w, max(int(known_x.max(initial=cx)), cx) + 3)
        y1 = min(h, max(int(known_y.max(initial=cy)), cy) + 3)
        grid = np.ascontiguousarray(full[y0:y1, x0:x1])
        ox, oy = ox + x0 * resolution, oy + y0 * resolution
        cx, cy = cx - x0, cy - y0
        sx, sy = _nearest_free(grid, cx, cy)
        if sx < 0:
            sx, sy = cx, cy
        n_free = int(np.count_nonzero(grid == FREE))
        cap = int(np.count_nonzero(grid <= grid[sy, sx]))
        fcap = min(int(np.count_nonzero(grid == NO_INFORMATION)), 4 * n_free + 4)
        rcx, rcy = (rx - ox) / resolution - 0.5, (ry - oy) / resolution - 0.5
        label, firsts, stats = _search(grid, sx, sy, rcx, rcy, cap, fcap)
        flat = label.ravel()
        cells = np.nonzero(flat >= 0)[0]
        order = cells[np.argsort(flat[cells], kind="stable")]
        bounds = np.searchsorted(flat[order], np.arange(len(stats) + 1))

        def world(px: float, py: float) -> tuple[float, float]:
            return float(ox + (px + 0.5) * resolution), float(oy + (py + 0.5) * resolution)

        out: list[Frontier] = []
        for i in range(len(stats)):
            size = int(stats[i, 0])
            if size * resolution < self.min_frontier_size:
                continue
            members = order[bounds[i] : bounds[i + 1]]
            ys, xs = np.divmod(members, grid.shape[1])
            pts = np.column_stack([ox + (xs + 0.5) * resolution, oy + (ys + 0.5) * resolution])
            centroid = world(stats[i, 2], stats[i, 3])
            dist = float(stats[i, 1]) * resolution
            bearing = math.atan2(centroid[1] - ry, centroid[0] - rx)
            turn = abs(math.remainder(bearing - ryaw, 2 * math.pi))
            cost = (
                self.potential_scale * dist * resolution
                + self.orientation_scale * turn
                - self.gain_scale * size * resolution
            )
            out.append(
                Frontier(
                    size=size,
                    min_distance=dist,
                    centroid=centroid,
                    middle=world(stats[i, 4], stats[i, 5]),
                    initial=world(float(firsts[i, 0]), float(firsts[i, 1])),
                    points=pts,
                    cost=cost,
                )
            )
        out.sort(key=lambda f: f.cost)
        return out
