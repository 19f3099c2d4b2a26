"""costmap_2d's ``InflationLayer``: costs that decay with the distance to obstacles.

A cell at distance ``d`` (m) from the nearest lethal cell costs (``computeCost``)::

    254                                                    d == 0
    253                                                    d <= inscribed_radius
    floor(252 * exp(-cost_scaling_factor * (d - inscribed_radius)))   otherwise

for cells within ``ceil(inflation_radius / resolution)`` cells of an obstacle; distances are
measured between cell indices (``hypot(dx, dy) * resolution``) and cached in a kernel of
``(r + 2) x (r + 2)`` cells, as costmap_2d does. The propagation (compiled,
:func:`~roverlab.navigation.costmap.kernels.inflate`) visits cells by increasing distance
to their source obstacle, each cell once. The inscribed radius is the footprint's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.costmap.costmap_2d import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    Costmap2D,
)
from roverlab.navigation.costmap.kernels import inflate
from roverlab.navigation.costmap.layered import Bounds, Layer
from roverlab.navigation.params import check

__all__ = ["InflationLayer", "InflationLayerParams", "compute_cost"]


@dataclass(frozen=True, slots=True, kw_only=True)
class InflationLayerParams:
    """The inflation layer's parameters (ROS names and defaults)."""

    enabled: bool = True
    inflation_radius: float = 0.55
    cost_scaling_factor: float = 10.0
    inflate_unknown: bool = False

    def __post_init__(self) -> None:
        check(self.inflation_radius >= 0, "inflation_layer: inflation_radius must be >= 0")
        check(self.cost_scaling_factor >= 0, "inflation_layer: cost_scaling_factor must be >= 0")


def compute_cost(
    distance_cells: float, resolution: float, inscribed_radius: float, cost_scaling_factor: float
) -> int:
    """costmap_2d's ``InflationLayer::computeCost`` of a distance in cells."""
    if distance_cells == 0:
        return LETHAL_OBSTACLE
    d = distance_cells * resolution
    if d <= inscribed_radius:
        return INSCRIBED_INFLATED_OBSTACLE
    factor = math.exp(-1.0 * cost_scaling_factor * (d - inscribed_radius))
    return int((INSCRIBED_INFLATED_OBSTACLE - 1) * factor)


class InflationLayer(Layer):
    """The inflation layer.

    Args:
        name: plugin name (``inflation_layer``).
        params: its parameters.

    Attributes:
        cell_inflation_radius: the radius in cells.
        cached_costs: ``(r + 2, r + 2)`` cost of each ``(|dx|, |dy|)``.
    """

    def __init__(self, name: str, params: InflationLayerParams) -> None:
        super().__init__(name, enabled=params.enabled)
        self.params = params
        self.inscribed_radius = 0.0
        self.resolution = 0.0
        self.cell_inflation_radius = 0
        self.cached_costs: NDArray[np.uint8] = np.zeros((2, 2), dtype=np.uint8)
        self._bin_of: NDArray[np.int64] = np.full((2, 2), -1, dtype=np.int64)
        self._nbins = 0
        self._need_reinflation = True
        self._last = Bounds()
        self._seen: NDArray[np.bool_] = np.zeros(0, dtype=np.bool_)
        self._nodes: tuple[NDArray[np.int64], ...] = ()
        self.cells_visited = 0

    def on_initialize(self) -> None:
        self._need_reinflation = True

    def match_size(self) -> None:
        m = self.layered.costmap
        self.resolution = m.resolution
        self._seen = np.zeros(m.size_x * m.size_y, dtype=np.bool_)
        self._compute_caches()
        self._need_reinflation = True

    def on_footprint_changed(self) -> None:
        self.inscribed_radius = self.layered.inscribed_radius
        self._compute_caches()
        self._need_reinflation = True

    def reset(self) -> None:
        self._need_reinflation = True

    def _compute_caches(self) -> None:
        if self.resolution <= 0:
            return
        r = int(max(0.0, math.ceil(self.params.inflation_radius / self.resolution)))
        self.cell_inflation_radius = r
        ij = np.arange(r + 2, dtype=np.float64)
        dist = np.hypot(ij[:, None], ij[None, :])
        costs = np.array(
            [
                [
                    compute_cost(
                        float(dist[i, j]),
                        self.resolution,
                        self.inscribed_radius,
                        self.params.cost_scaling_factor,
                    )
                    for j in range(r + 2)
                ]
                for i in range(r + 2)
            ],
            dtype=np.uint8,
        )
        self.cached_costs = costs
        within = dist <= r
        levels = np.unique(dist[within])
        bins = np.full(dist.shape, -1, dtype=np.int64)
        bins[within] = np.searchsorted(levels, dist[within])
        self._bin_of = bins
        self._nbins = len(levels)

    # ------------------------------------------------------------------ updates
    def update_bounds(
        self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds, now_s: float
    ) -> None:
        if self._need_reinflation:
            self._last = Bounds(bounds.min_x, bounds.min_y, bounds.max_x, bounds.max_y)
            big = float(np.finfo(np.float32).max)
            bounds.min_x, bounds.min_y, bounds.max_x, bounds.max_y = -big, -big, big, big
            self._need_reinflation = False
            return
        last = self._last
        self._last = Bounds(bounds.min_x, bounds.min_y, bounds.max_x, bounds.max_y)
        r = self.params.inflation_radius
        bounds.min_x = min(last.min_x, bounds.min_x) - r
        bounds.min_y = min(last.min_y, bounds.min_y) - r
        bounds.max_x = max(last.max_x, bounds.max_x) + r
        bounds.max_y = max(last.max_y, bounds.max_y) + r

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        r = self.cell_inflation_radius
        if r == 0 or self._nbins == 0:
            return
        sx, sy = master.size_x, master.size_y
        x0, y0 = max(0, x0 - r), max(0, y0 - r)
        xn, yn = min(sx, xn + r), min(sy, yn + r)
        # cells reachable: the window grown by r + 1 more; every taken cell offers <= 4
        area = (min(sx, xn + r + 1) - max(0, x0 - r - 1)) * (
            min(sy, yn + r + 1) - max(0, y0 - r - 1)
        )
        cap = 5 * area + 16
        if not self._nodes or self._nodes[0].shape[0] < cap:
            self._nodes = tuple(np.empty(cap, dtype=np.int64) for _ in range(3))
        if self._seen.shape[0] != sx * sy:
            self._seen = np.zeros(sx * sy, dtype=np.bool_)
        heads = np.empty(self._nbins, dtype=np.int64)
        tails = np.empty(self._nbins, dtype=np.int64)
        self.cells_visited = inflate(
            master.costs,
            x0,
            y0,
            xn,
            yn,
            r,
            self._bin_of,
            self.cached_costs,
            self._nbins,
            self.params.inflate_unknown,
            self._seen,
            self._nodes[0],
            self._nodes[1],
            self._nodes[2],
            heads,
            tails,
        )
