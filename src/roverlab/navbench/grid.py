"""Grid geometry of the benchmark: the inflated grid, clearance, reachability, seeded
goals and the shortest path a goal is measured against.

Every grid is row = y, column = x (``nav_msgs/OccupancyGrid`` order); a cell's centre is
``origin + (index + 0.5) * resolution``.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from roverlab.errors import RoverlabError

__all__ = ["BenchGrid", "GoalSamplingError", "sample_goals"]

_SQRT2 = math.sqrt(2.0)


class GoalSamplingError(RoverlabError):
    """No goal satisfies the benchmark's conditions in this map."""


@numba.njit(cache=True, nogil=True)
def _dijkstra(
    free: NDArray[np.bool_], r0: int, c0: int
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """8-connected Dijkstra over ``free`` cells from ``(r0, c0)`` in cells; a diagonal
    step needs both side cells free (no corner cutting). Returns the distances (inf where
    unreached) and each cell's predecessor (flat index, -1 at the start)."""
    h, w = free.shape
    dist = np.full((h, w), np.inf)
    parent = np.full(h * w, -1, dtype=np.int64)
    dist[r0, c0] = 0.0
    heap = [(0.0, r0 * w + c0)]
    diag = math.sqrt(2.0)
    while heap:
        d, k = heapq.heappop(heap)
        r, c = k // w, k % w
        if d > dist[r, c]:
            continue
        for dr in range(-1, 2):
            for dc in range(-1, 2):
                if dr == 0 and dc == 0:
                    continue
                rr, cc = r + dr, c + dc
                if rr < 0 or cc < 0 or rr >= h or cc >= w or not free[rr, cc]:
                    continue
                step = 1.0
                if dr != 0 and dc != 0:
                    if not (free[r + dr, c] and free[r, c + dc]):
                        continue
                    step = diag
                nd = d + step
                if nd < dist[rr, cc]:
                    dist[rr, cc] = nd
                    parent[rr * w + cc] = k
                    heapq.heappush(heap, (nd, rr * w + cc))
    return dist, parent


@numba.njit(cache=True, nogil=True)
def _visible(free: NDArray[np.bool_], r0: int, c0: int, r1: int, c1: int) -> bool:
    """Every cell the segment between two cell centres passes through is free (the cells
    of a supercover: sampled at a tenth of a cell, both neighbours at a corner)."""
    n = int(max(abs(r1 - r0), abs(c1 - c0)) * 10) + 1
    for i in range(n + 1):
        t = i / n
        y = r0 + 0.5 + t * (r1 - r0)
        x = c0 + 0.5 + t * (c1 - c0)
        r = int(math.floor(y))
        c = int(math.floor(x))
        if not free[r, c]:
            return False
    return True


@numba.njit(cache=True, nogil=True)
def _string_pull(free: NDArray[np.bool_], cells: NDArray[np.int64]) -> float:
    """Length (cells) of the grid path ``cells`` ((N, 2) rows, cols) shortened by
    line of sight: from each kept cell on, the farthest later cell it sees."""
    n = cells.shape[0]
    total = 0.0
    i = 0
    while i < n - 1:
        j = n - 1
        while j > i + 1 and not _visible(free, cells[i, 0], cells[i, 1], cells[j, 0], cells[j, 1]):
            j -= 1
        total += math.hypot(cells[j, 0] - cells[i, 0], cells[j, 1] - cells[i, 1])
        i = j
    return total


@dataclass
class BenchGrid:
    """The global costmap's grid without sensor data (the map through the costmap's
    static and inflation layers): ``costs`` uint8, ROS values.

    Attributes:
        free: cells the robot's centre may occupy (cost below 253, inscribed).
        clearance: metres from each cell centre to the nearest lethal or unknown cell.
    """

    costs: NDArray[np.uint8]
    resolution: float
    origin: tuple[float, float]

    def __post_init__(self) -> None:
        self.free = self.costs < 253
        blocked = (self.costs == 254) | (self.costs == 255)
        self.clearance = ndimage.distance_transform_edt(~blocked) * self.resolution

    def cell(self, x: float, y: float) -> tuple[int, int] | None:
        """The (row, col) of a world point, None off the grid."""
        c = math.floor((x - self.origin[0]) / self.resolution)
        r = math.floor((y - self.origin[1]) / self.resolution)
        if 0 <= r < self.costs.shape[0] and 0 <= c < self.costs.shape[1]:
            return r, c
        return None

    def centre(self, r: int, c: int) -> tuple[float, float]:
        return (
            self.origin[0] + (c + 0.5) * self.resolution,
            self.origin[1] + (r + 0.5) * self.resolution,
        )

    def _nearest_free(self, x: float, y: float) -> tuple[int, int] | None:
        rc = self.cell(x, y)
        if rc is None:
            return None
        if self.free[rc]:
            return rc
        rows, cols = np.nonzero(self.free)
        if len(rows) == 0:
            return None
        k = int(np.argmin((rows - rc[0]) ** 2 + (cols - rc[1]) ** 2))
        return int(rows[k]), int(cols[k])

    def reachable(self, x: float, y: float) -> NDArray[np.bool_]:
        """Free cells connected to ``(x, y)`` (all false when it is off the grid)."""
        rc = self._nearest_free(x, y)
        if rc is None:
            return np.zeros_like(self.free)
        dist, _ = _dijkstra(self.free, rc[0], rc[1])
        return np.isfinite(dist)

    def shortest_path(self, start: tuple[float, float], goal: tuple[float, float]) -> float:
        """Length (m) of the shortest path between two points through free cells: an
        8-connected Dijkstra, shortened by line of sight (within a few per cent of the
        any-angle path); from the nearest free cell when a point is in a blocked one.
        ``inf`` when they are not connected."""
        a = self._nearest_free(*start)
        b = self._nearest_free(*goal)
        if a is None or b is None:
            return math.inf
        dist, parent = _dijkstra(self.free, a[0], a[1])
        if not math.isfinite(dist[b]):
            return math.inf
        w = self.free.shape[1]
        cells = []
        k = b[0] * w + b[1]
        while k >= 0:
            cells.append((k // w, k % w))
            k = int(parent[k])
        path = np.array(cells[::-1], dtype=np.int64)
        length = _string_pull(self.free, path) * self.resolution
        # the points' offsets from their cells' centres
        ca, cb = self.centre(*a), self.centre(*b)
        return (
            length
            + math.hypot(start[0] - ca[0], start[1] - ca[1])
            + math.hypot(goal[0] - cb[0], goal[1] - cb[1])
        )


def sample_goals(
    grid: BenchGrid,
    spawn: tuple[float, float],
    n: int,
    rng: np.random.Generator,
    *,
    clearance: float,
    min_separation: float = 2.0,
) -> NDArray[np.float64]:
    """``n`` goals ``(x, y, yaw)``: cell centres reachable from ``spawn`` with at least
    ``clearance`` m to the nearest obstacle, each at least ``min_separation`` m (straight
    line) from the one before (the first from the spawn), yaw uniform.

    Raises:
        GoalSamplingError: no cell qualifies, or none is far enough from a goal.
    """
    ok = grid.reachable(*spawn) & (grid.clearance >= clearance)
    rows, cols = np.nonzero(ok)
    if len(rows) == 0:
        raise GoalSamplingError(
            f"no reachable cell with {clearance:.2f} m clearance: the robot's spawn is "
            "enclosed or the map has no room for it"
        )
    xs = grid.origin[0] + (cols + 0.5) * grid.resolution
    ys = grid.origin[1] + (rows + 0.5) * grid.resolution
    out = np.empty((n, 3))
    px, py = spawn
    for i in range(n):
        far = np.nonzero(np.hypot(xs - px, ys - py) >= min_separation)[0]
        if len(far) == 0:
            raise GoalSamplingError(
                f"no goal {min_separation:.1f} m from ({px:.2f}, {py:.2f}) with "
                f"{clearance:.2f} m clearance: the reachable space is too small"
            )
        k = int(far[rng.integers(len(far))])
        px, py = float(xs[k]), float(ys[k])
        out[i] = (px, py, rng.uniform(-math.pi, math.pi))
    return out
