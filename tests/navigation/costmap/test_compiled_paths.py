"""The costmaps' compiled passes against plain versions, bit for bit, so a speed-up
changes no cost: the inflation layer's ordered propagation (``InflationLayer::updateCosts``),
the footprint placed at a pose, and the footprint's cells filled on the grid."""

from __future__ import annotations

import math

import numpy as np

from roverlab.navigation.costmap import Costmap2D
from roverlab.navigation.costmap.footprint import transform_footprint
from roverlab.navigation.costmap.kernels import convex_fill, inflate

LETHAL, INSCRIBED, UNKNOWN = 254, 253, 255


def _plain_inflate(
    grid: np.ndarray, window: tuple[int, int, int, int], bins: np.ndarray, cost_of: np.ndarray,
    nbins: int, inflate_unknown: bool,
) -> int:  # fmt: skip
    """Lethal cells of the window in bin 0, then bin by bin: a cell is taken once, takes
    its source's cost (max with its own; unknown only inscribed and up, or any with
    ``inflate_unknown``) and offers its four neighbours within the radius to their bins."""
    h, w = grid.shape
    x0, y0, xn, yn = window
    queues: list[list[tuple[int, int, int, int]]] = [[] for _ in range(nbins)]
    queues[0] = [(x, y, x, y) for y in range(y0, yn) for x in range(x0, xn) if grid[y, x] == LETHAL]
    seen = np.zeros((h, w), dtype=bool)
    taken = 0
    for b in range(nbins):
        for x, y, sx, sy in queues[b]:  # the list grows while it is read
            if seen[y, x]:
                continue
            seen[y, x] = True
            taken += 1
            cost = int(cost_of[abs(x - sx), abs(y - sy)])
            old = int(grid[y, x])
            if old == UNKNOWN and ((inflate_unknown and cost > 0) or cost >= INSCRIBED):
                grid[y, x] = cost
            else:
                grid[y, x] = max(old, cost)
            for nx, ny in ((x - 1, y), (x, y - 1), (x + 1, y), (x, y + 1)):
                if 0 <= nx < w and 0 <= ny < h and not seen[ny, nx]:
                    nb = int(bins[abs(nx - sx), abs(ny - sy)])
                    if nb >= 0:
                        queues[nb].append((nx, ny, sx, sy))
    return taken


def test_inflate_is_the_plain_ordered_propagation_bit_for_bit() -> None:
    rng = np.random.default_rng(11)
    r = 5
    dist = np.hypot(*np.meshgrid(np.arange(r + 2), np.arange(r + 2), indexing="ij"))
    within = dist <= r
    levels = np.unique(dist[within])
    bins = np.full(dist.shape, -1, dtype=np.int64)
    bins[within] = np.searchsorted(levels, dist[within])
    cost_of = np.where(dist == 0, LETHAL, np.where(dist <= 2, INSCRIBED, 200 // (dist + 1)))
    cost_of = cost_of.astype(np.uint8)
    for trial in range(25):
        h, w = (int(v) for v in rng.integers(8, 45, 2))
        grid = rng.choice(np.array([0, 0, 0, 0, 30, LETHAL, UNKNOWN], dtype=np.uint8), size=(h, w))
        x0, xn = sorted(int(v) for v in rng.integers(0, w + 1, 2))
        y0, yn = sorted(int(v) for v in rng.integers(0, h + 1, 2))
        unknown = trial % 2 == 1
        want = grid.copy()
        n_want = _plain_inflate(want, (x0, y0, xn, yn), bins, cost_of, len(levels), unknown)
        got = grid.copy()
        cap = 5 * h * w + 16
        # ``seen`` as an earlier call left it (only the cells near the window are cleared)
        seen = rng.random(h * w) < 0.5
        n_got = inflate(
            got, x0, y0, xn, yn, r, bins, cost_of, len(levels), unknown, seen,
            *(np.empty(cap, dtype=np.int64) for _ in range(3)),
            np.empty(len(levels), dtype=np.int64), np.empty(len(levels), dtype=np.int64),
        )  # fmt: skip
        assert n_got == n_want
        assert got.tobytes() == want.tobytes()


def test_the_footprint_placed_and_filled_is_numpys_and_world_to_maps() -> None:
    rng = np.random.default_rng(12)
    cm = Costmap2D(size_x=60, size_y=50, resolution=0.05, origin_x=-1.3, origin_y=0.7)
    for _ in range(300):
        fp = rng.uniform(-0.4, 0.4, (int(rng.integers(3, 9)), 2))
        x, y, yaw = rng.uniform(-1.5, 2.0), rng.uniform(0.5, 3.5), rng.uniform(-4, 4)
        c, s = math.cos(yaw), math.sin(yaw)
        want = np.column_stack([x + fp[:, 0] * c - fp[:, 1] * s, y + fp[:, 0] * s + fp[:, 1] * c])
        placed = transform_footprint(x, y, yaw, fp)
        assert placed.tobytes() == want.tobytes()
        hull = placed[np.argsort(np.arctan2(*(placed - placed.mean(axis=0)).T[::-1]))]
        cells = [cm.world_to_map(float(px), float(py)) for px, py in hull]
        ref = cm.costs.copy()
        if all(cell is not None for cell in cells):
            convex_fill(ref, np.array(cells, dtype=np.int64), 77)
        before = cm.costs.copy()
        assert cm.set_convex_polygon_cost(hull, 77) == all(cell is not None for cell in cells)
        assert cm.costs.tobytes() == ref.tobytes()
        cm.costs[:] = before
