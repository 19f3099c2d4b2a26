"""``Costmap2D``: a grid of uint8 costs with costmap_2d's cost values and geometry.

Cost values (``costmap_2d/cost_values.h``): :data:`FREE_SPACE` 0, :data:`LETHAL_OBSTACLE`
254, :data:`INSCRIBED_INFLATED_OBSTACLE` 253, :data:`NO_INFORMATION` 255; 1..252 are costs
decaying with the distance to the nearest obstacle.

Layout: ``costs[my, mx]`` (row = y, the ``nav_msgs/OccupancyGrid`` order); cell ``(mx, my)``
covers ``[origin_x + mx * resolution, origin_x + (mx + 1) * resolution)`` in x, likewise in
y. :meth:`Costmap2D.world_to_map` truncates as ROS does (a point left of or below the origin
is off the map); :meth:`Costmap2D.map_to_world` gives the cell centre.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.navigation.costmap.kernels import convex_fill
from roverlab.navigation.errors import CostmapError

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "Costmap2D",
]

FREE_SPACE = 0
INSCRIBED_INFLATED_OBSTACLE = 253
LETHAL_OBSTACLE = 254
NO_INFORMATION = 255


class Costmap2D:
    """A 2-D costmap (costmap_2d's ``Costmap2D``).

    Args:
        size_x: cells along x (``width``).
        size_y: cells along y (``height``).
        resolution: cell side, m.
        origin_x, origin_y: world coordinates of the outer corner of cell ``(0, 0)``, m.
        default_value: the cost of a reset cell (0, or 255 when unknown space is tracked).

    Raises:
        CostmapError: a non-positive size or resolution, a non-finite origin.
    """

    def __init__(
        self,
        *,
        size_x: int,
        size_y: int,
        resolution: float,
        origin_x: float = 0.0,
        origin_y: float = 0.0,
        default_value: int = FREE_SPACE,
    ) -> None:
        self.default_value = int(default_value)
        self.costs: NDArray[np.uint8] = np.zeros((0, 0), dtype=np.uint8)
        self.resize_map(size_x, size_y, resolution, origin_x, origin_y)

    # ------------------------------------------------------------------ geometry
    def resize_map(
        self, size_x: int, size_y: int, resolution: float, origin_x: float, origin_y: float
    ) -> None:
        """Re-allocate the grid (every cell reset to the default value)."""
        if isinstance(size_x, bool) or int(size_x) != size_x or size_x < 1:
            raise CostmapError(f"costmap width must be a positive number of cells, got {size_x}")
        if isinstance(size_y, bool) or int(size_y) != size_y or size_y < 1:
            raise CostmapError(f"costmap height must be a positive number of cells, got {size_y}")
        if not (math.isfinite(resolution) and resolution > 0.0):
            raise CostmapError(f"costmap resolution must be > 0 m, got {resolution}")
        if not (math.isfinite(origin_x) and math.isfinite(origin_y)):
            raise CostmapError(f"costmap origin must be finite, got ({origin_x}, {origin_y})")
        self.size_x = int(size_x)
        self.size_y = int(size_y)
        self.resolution = float(resolution)
        self.origin_x = float(origin_x)
        self.origin_y = float(origin_y)
        self.costs = np.full((self.size_y, self.size_x), self.default_value, dtype=np.uint8)

    def copy(self) -> Costmap2D:
        """A deep copy."""
        out = Costmap2D(
            size_x=self.size_x,
            size_y=self.size_y,
            resolution=self.resolution,
            origin_x=self.origin_x,
            origin_y=self.origin_y,
            default_value=self.default_value,
        )
        out.costs[:] = self.costs
        return out

    @property
    def size_in_meters_x(self) -> float:
        """``(size_x - 1 + 0.5) * resolution``, costmap_2d's ``getSizeInMetersX``."""
        return (self.size_x - 1 + 0.5) * self.resolution

    @property
    def size_in_meters_y(self) -> float:
        """``(size_y - 1 + 0.5) * resolution``, costmap_2d's ``getSizeInMetersY``."""
        return (self.size_y - 1 + 0.5) * self.resolution

    def cell_distance(self, world_dist: float) -> int:
        """costmap_2d's ``cellDistance``: ``ceil(world_dist / resolution)`` cells, >= 0."""
        return int(max(0.0, math.ceil(world_dist / self.resolution)))

    def world_to_map(self, wx: float, wy: float) -> tuple[int, int] | None:
        """The cell holding ``(wx, wy)``, or None off the map (ROS's truncation)."""
        if wx < self.origin_x or wy < self.origin_y:
            return None
        mx = int((wx - self.origin_x) / self.resolution)
        my = int((wy - self.origin_y) / self.resolution)
        if mx < self.size_x and my < self.size_y:
            return mx, my
        return None

    def world_to_map_no_bounds(self, wx: float, wy: float) -> tuple[int, int]:
        """The cell coordinates of ``(wx, wy)``, possibly outside the grid."""
        return (
            math.floor((wx - self.origin_x) / self.resolution),
            math.floor((wy - self.origin_y) / self.resolution),
        )

    def world_to_map_enforce_bounds(self, wx: float, wy: float) -> tuple[int, int]:
        """The cell of ``(wx, wy)`` clamped to the grid (ROS's ``worldToMapEnforceBounds``)."""
        if wx < self.origin_x:
            mx = 0
        elif wx >= self.resolution * self.size_x + self.origin_x:
            mx = self.size_x - 1
        else:
            mx = int((wx - self.origin_x) / self.resolution)
        if wy < self.origin_y:
            my = 0
        elif wy >= self.resolution * self.size_y + self.origin_y:
            my = self.size_y - 1
        else:
            my = int((wy - self.origin_y) / self.resolution)
        return mx, my

    def map_to_world(self, mx: float, my: float) -> tuple[float, float]:
        """The centre of cell ``(mx, my)``."""
        return (
            self.origin_x + (mx + 0.5) * self.resolution,
            self.origin_y + (my + 0.5) * self.resolution,
        )

    def get_cost(self, mx: int, my: int) -> int:
        """The cost of cell ``(mx, my)``."""
        return int(self.costs[my, mx])

    def set_cost(self, mx: int, my: int, cost: int) -> None:
        """Set the cost of cell ``(mx, my)``."""
        self.costs[my, mx] = cost

    # ------------------------------------------------------------------ edits
    def reset_map(self, x0: int, y0: int, xn: int, yn: int) -> None:
        """Cells ``[x0, xn) x [y0, yn)`` back to the default value."""
        self.costs[y0:yn, x0:xn] = self.default_value

    def reset_maps(self) -> None:
        """Every cell back to the default value."""
        self.costs[:] = self.default_value

    def update_origin(self, new_origin_x: float, new_origin_y: float) -> None:
        """Move the grid by whole cells towards ``(new_origin_x, new_origin_y)``, keeping
        the overlapping content and resetting the rest (the rolling window's shift)."""
        cell_ox = int((new_origin_x - self.origin_x) / self.resolution)
        cell_oy = int((new_origin_y - self.origin_y) / self.resolution)
        if cell_ox == 0 and cell_oy == 0:
            return
        sx, sy = self.size_x, self.size_y
        llx = min(max(cell_ox, 0), sx)
        lly = min(max(cell_oy, 0), sy)
        urx = min(max(cell_ox + sx, 0), sx)
        ury = min(max(cell_oy + sy, 0), sy)
        window = self.costs[lly:ury, llx:urx].copy()
        self.costs[:] = self.default_value
        self.origin_x += cell_ox * self.resolution
        self.origin_y += cell_oy * self.resolution
        start_x = llx - cell_ox
        start_y = lly - cell_oy
        self.costs[start_y : start_y + window.shape[0], start_x : start_x + window.shape[1]] = (
            window
        )

    def set_convex_polygon_cost(self, polygon: ArrayLike, cost: int) -> bool:
        """Give ``cost`` to every cell of the convex ``polygon`` ((N, 2) world points).

        Returns:
            False (and changes nothing) if a vertex lies off the map, as costmap_2d.
        """
        pts = np.ascontiguousarray(np.asarray(polygon, dtype=np.float64).reshape(-1, 2))
        if len(pts) < 3:
            return False
        return _fill_world_polygon(
            self.costs, pts, self.origin_x, self.origin_y, self.resolution, int(cost)
        )


@numba.njit(cache=True, nogil=True)
def _fill_world_polygon(
    costs: NDArray[np.uint8], pts: NDArray[np.float64], ox: float, oy: float, res: float,
    value: int,
) -> bool:  # fmt: skip
    """:meth:`Costmap2D.set_convex_polygon_cost` in one compiled call: each vertex's cell
    as :meth:`Costmap2D.world_to_map` gives it (False, nothing changed, when one is off
    the map), then :func:`convex_fill`."""
    h, w = costs.shape
    cells = np.empty((pts.shape[0], 2), dtype=np.int64)
    for k in range(pts.shape[0]):
        wx = pts[k, 0]
        wy = pts[k, 1]
        if wx < ox or wy < oy:
            return False
        mx = int((wx - ox) / res)
        my = int((wy - oy) / res)
        if not (mx < w and my < h):
            return False
        cells[k, 0] = mx
        cells[k, 1] = my
    convex_fill(costs, cells, value)
    return True
