"""amcl's map: free cells, the likelihood field and the per-cell tables the kernels read.

amcl reads a ``nav_msgs/OccupancyGrid`` as three states: ``0`` is free, ``100`` occupied,
anything else unknown. The likelihood field is the distance from each cell centre to the
nearest occupied cell centre, capped at ``laser_likelihood_max_dist`` (amcl's
``occ_dist``); here it is an exact Euclidean distance transform (``scipy.ndimage``).

Cell ``(row, col)`` covers ``origin + [col, col + 1) * resolution`` in x and
``[row, row + 1) * resolution`` in y (the ``OccupancyGrid`` layout). ROS 1 amcl rounds
world coordinates to the nearest cell *corner* instead (``MAP_GXWX``), which shifts every
lookup by half a cell; roverlab uses the cell the point lies in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import ndimage

from roverlab.localization.amcl.errors import AmclMapError
from roverlab.maps.map_io import GridShape

__all__ = ["FREE", "OCCUPIED", "AmclMap"]

#: ``OccupancyGrid`` value of a free cell.
FREE: Final = 0
#: ``OccupancyGrid`` value of an occupied cell (amcl: only exactly 100 is an obstacle).
OCCUPIED: Final = 100

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False, kw_only=True)
class AmclMap(GridShape):
    """A map for amcl, validated, with its likelihood field.

    Args:
        data: ``(height, width)`` occupancy values (``OccupancyGrid.data`` reshaped, row 0
            at the origin): 0 free, 100 occupied, others unknown.
        resolution_m: cell side (m).
        origin_xy: world ``(x, y)`` of the outer corner of cell ``(0, 0)`` (m).
        max_dist_m: the likelihood field's cap, amcl's ``laser_likelihood_max_dist`` (m).

    Attributes:
        distance: ``(height, width)`` float64 distance from each cell to the nearest
            occupied cell, capped at ``max_dist_m`` (m).
        free_cells: ``(K, 2)`` int64 ``(row, col)`` of the free cells.
        blocked: ``(height, width)`` uint8, 1 where a ray stops (occupied or unknown: amcl's
            ``map_calc_range``), for the beam model.

    Raises:
        AmclMapError: a map that is empty, not 2-D, has a bad resolution or origin, or has
            no free cell (nowhere to put a particle).
    """

    data: NDArray[np.int8]
    resolution_m: float
    origin_xy: tuple[float, float]
    max_dist_m: float = 2.0
    distance: FloatArray = field(init=False, repr=False)
    free_cells: NDArray[np.int64] = field(init=False, repr=False)
    blocked: NDArray[np.uint8] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        d = np.asarray(self.data)
        if d.ndim != 2 or d.shape[0] == 0 or d.shape[1] == 0:
            raise AmclMapError(f"the map must be a non-empty 2-D grid, got shape {d.shape}")
        d = np.ascontiguousarray(d, dtype=np.int8)
        d.setflags(write=False)
        res = float(self.resolution_m)
        if not (math.isfinite(res) and res > 0.0):
            raise AmclMapError(f"map resolution must be a positive number, got {res}")
        ox, oy = (float(v) for v in self.origin_xy)
        if not (math.isfinite(ox) and math.isfinite(oy)):
            raise AmclMapError(f"map origin must be finite, got {self.origin_xy}")
        cap = float(self.max_dist_m)
        if not (math.isfinite(cap) and cap > 0.0):
            raise AmclMapError(f"laser_likelihood_max_dist must be > 0, got {cap}")
        free = np.argwhere(d == FREE).astype(np.int64)
        if free.shape[0] == 0:
            raise AmclMapError(
                f"the map ({d.shape[1]} x {d.shape[0]} cells) has no free cell (value 0): "
                "amcl has nowhere to put a particle"
            )
        occupied = d == OCCUPIED
        if occupied.any():
            dist = ndimage.distance_transform_edt(~occupied) * res
            np.minimum(dist, cap, out=dist)
        else:
            dist = np.full(d.shape, cap)
        dist = np.ascontiguousarray(dist, dtype=np.float64)
        blocked = np.ascontiguousarray(d != FREE, dtype=np.uint8)
        for arr in (dist, free, blocked):
            arr.setflags(write=False)
        object.__setattr__(self, "data", d)
        object.__setattr__(self, "resolution_m", res)
        object.__setattr__(self, "origin_xy", (ox, oy))
        object.__setattr__(self, "max_dist_m", cap)
        object.__setattr__(self, "distance", dist)
        object.__setattr__(self, "free_cells", free)
        object.__setattr__(self, "blocked", blocked)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the map's area (m)."""
        ox, oy = self.origin_xy
        return (
            ox,
            oy,
            ox + self.width * self.resolution_m,
            oy + self.height * self.resolution_m,
        )

    def contains(self, x: float, y: float) -> bool:
        """``(x, y)`` lies on the map (not necessarily on a free cell)."""
        xmin, ymin, xmax, ymax = self.bounds
        return xmin <= x < xmax and ymin <= y < ymax

    def cell_of(self, xy: ArrayLike) -> NDArray[np.int64]:
        """``(..., 2)`` ``(row, col)`` of world points (may lie off the map)."""
        p = np.asarray(xy, dtype=np.float64)
        col = np.floor((p[..., 0] - self.origin_xy[0]) / self.resolution_m)
        row = np.floor((p[..., 1] - self.origin_xy[1]) / self.resolution_m)
        return np.stack([row, col], axis=-1).astype(np.int64)

    def likelihood_table(
        self, *, z_hit: float, z_rand: float, sigma_hit: float, range_max: float
    ) -> tuple[NDArray[np.float64], float]:
        """The likelihood-field model's per-beam term ``pz^3`` of every cell, and its
        value off the map (amcl: the capped distance).

        ``pz = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max``, as amcl's
        ``LikelihoodFieldModel``; a particle's weight is multiplied by
        ``1 + sum over beams of pz^3``.
        """
        pz = self._pz(z_hit=z_hit, z_rand=z_rand, sigma_hit=sigma_hit, range_max=range_max)
        table = np.ascontiguousarray(pz**3)
        off = float(self._pz_off(z_hit, z_rand, sigma_hit, range_max) ** 3)
        return table, off

    def log_likelihood_table(
        self, *, z_hit: float, z_rand: float, sigma_hit: float, range_max: float
    ) -> tuple[NDArray[np.float64], float]:
        """The ``likelihood_field_prob`` model's per-beam ``log(pz)`` of every cell, and its
        value off the map (amcl: ``z_hit * exp(-max_dist^2 / ...) + z_rand / range_max``).
        """
        pz = self._pz(z_hit=z_hit, z_rand=z_rand, sigma_hit=sigma_hit, range_max=range_max)
        with np.errstate(divide="ignore"):
            table = np.ascontiguousarray(np.log(pz))
            off = float(np.log(self._pz_off(z_hit, z_rand, sigma_hit, range_max)))
        return table, off

    def _pz(self, *, z_hit: float, z_rand: float, sigma_hit: float, range_max: float) -> FloatArray:
        denom = 2.0 * sigma_hit * sigma_hit
        out: FloatArray = z_hit * np.exp(-(self.distance**2) / denom) + z_rand / range_max
        return out

    def _pz_off(self, z_hit: float, z_rand: float, sigma_hit: float, range_max: float) -> float:
        cap = self.max_dist_m
        return z_hit * math.exp(-(cap * cap) / (2.0 * sigma_hit * sigma_hit)) + z_rand / range_max
