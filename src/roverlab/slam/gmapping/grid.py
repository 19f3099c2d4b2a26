"""The maps of all particles: one growable ``(particles, height, width, 4)`` uint16 block.

gmapping gives each particle its own map of hit/visit counters (see
:mod:`roverlab.slam.gmapping.kernels` for the cell layout). Here the maps of all
particles share one geometry and live in one array, 8 bytes per cell and particle, so that
one compiled kernel updates or searches every particle's map at once:

* the block covers only the area scans have reached so far (plus a margin) and grows by
  whole cells, keeping every cell's place on the lattice anchored at ``(xmin, ymin)``;
  gmapping's ``xmin .. ymax`` box is the *published* extent, allocated lazily;
* resampling copies maps in place: the slab of a particle that was not drawn is
  overwritten by a copy of one that was drawn more than once, so a resampling needs no
  second block.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from roverlab.msgs import array_to_occupancy_grid
from roverlab.msgs import classes as mc
from roverlab.slam.gmapping.errors import GMappingInputError
from roverlab.slam.gmapping.kernels import HITS, VISITS

__all__ = ["GMappingMap", "ParticleMaps"]

# When the block grows, the side that needed it grows this much further (m), so that
# exploring a building costs a handful of reallocations, not one per scan.
_GROW_MARGIN_M = 6.0
# A map larger than this many cells per particle is refused (a runaway pose or range).
_MAX_CELLS_PER_PARTICLE = 200_000_000


class GMappingMap(NamedTuple):
    """An occupancy grid as slam_gmapping publishes it.

    Attributes:
        data: ``(height, width)`` int8: -1 unknown (never seen), 100 occupied (hit ratio
            above ``occ_thresh``), 0 free; row 0 lies at the origin (``OccupancyGrid``).
        origin_xy: world ``(x, y)`` of the outer corner of cell ``[0, 0]`` (m).
        resolution: cell size (m).
    """

    data: NDArray[np.int8]
    origin_xy: tuple[float, float]
    resolution: float

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])

    def to_msg(self, *, frame_id: str = "map", stamp: object = None) -> mc.OccupancyGrid:
        """The map as a ``nav_msgs/OccupancyGrid``."""
        return array_to_occupancy_grid(
            self.data,
            resolution=self.resolution,
            origin=(self.origin_xy[0], self.origin_xy[1], 0.0),
            frame_id=frame_id,
            stamp=stamp,
        )


class ParticleMaps:
    """Hit/visit maps of ``particles`` particles on one lattice of cell size ``delta``.

    Args:
        particles: number of maps.
        delta: cell size (m).
        anchor_xy: a lattice corner (gmapping's ``(xmin, ymin)``): cell boundaries lie at
            ``anchor + k * delta``.
    """

    def __init__(self, particles: int, delta: float, anchor_xy: tuple[float, float]) -> None:
        self.delta = float(delta)
        self.anchor_xy = (float(anchor_xy[0]), float(anchor_xy[1]))
        self.cells: NDArray[np.uint16] = np.zeros((particles, 0, 0, 4), dtype=np.uint16)
        # Lattice index (relative to the anchor) of the block's cell [0, 0].
        self._ix0 = 0
        self._iy0 = 0

    @property
    def particles(self) -> int:
        return int(self.cells.shape[0])

    @property
    def origin_xy(self) -> tuple[float, float]:
        """World ``(x, y)`` of the outer corner of the block's cell ``[0, 0]``."""
        return (
            self.anchor_xy[0] + self._ix0 * self.delta,
            self.anchor_xy[1] + self._iy0 * self.delta,
        )

    @property
    def nbytes(self) -> int:
        return int(self.cells.nbytes)

    def _lattice(self, x: float, y: float) -> tuple[int, int]:
        return (
            math.floor((x - self.anchor_xy[0]) / self.delta),
            math.floor((y - self.anchor_xy[1]) / self.delta),
        )

    def ensure(self, xmin: float, ymin: float, xmax: float, ymax: float) -> bool:
        """Grow the block so that it covers the box ``[xmin, xmax] x [ymin, ymax]`` (m).

        Returns:
            Whether the block was reallocated.

        Raises:
            GMappingInputError: the box is not finite or would need an absurd map.
        """
        if not all(math.isfinite(v) for v in (xmin, ymin, xmax, ymax)):
            raise GMappingInputError("a scan or pose lies at a non-finite position")
        ax0, ay0 = self._lattice(xmin, ymin)
        ax1, ay1 = self._lattice(xmax, ymax)
        h, w = self.cells.shape[1], self.cells.shape[2]
        if (
            h
            and ax0 >= self._ix0
            and ay0 >= self._iy0
            and ax1 < self._ix0 + w
            and ay1 < self._iy0 + h
        ):
            return False
        m = int(math.ceil(_GROW_MARGIN_M / self.delta))
        if h == 0:
            nx0, ny0, nx1, ny1 = ax0 - m, ay0 - m, ax1 + m + 1, ay1 + m + 1
        else:
            nx0 = self._ix0 if ax0 >= self._ix0 else ax0 - m
            ny0 = self._iy0 if ay0 >= self._iy0 else ay0 - m
            nx1 = self._ix0 + w if ax1 < self._ix0 + w else ax1 + m + 1
            ny1 = self._iy0 + h if ay1 < self._iy0 + h else ay1 + m + 1
        nw, nh = nx1 - nx0, ny1 - ny0
        if nw * nh > _MAX_CELLS_PER_PARTICLE:
            raise GMappingInputError(
                f"the map would need {nw} x {nh} cells per particle; a pose or range is "
                "far off (check maxUrange, odometry units and delta)"
            )
        new = np.zeros((self.particles, nh, nw, 4), dtype=np.uint16)
        if h:
            dy, dx = self._iy0 - ny0, self._ix0 - nx0
            new[:, dy : dy + h, dx : dx + w] = self.cells
        self.cells = new
        self._ix0, self._iy0 = nx0, ny0
        return True

    def resample(self, counts: NDArray[np.int64]) -> NDArray[np.int64]:
        """Apply a resampling in place: particle ``i`` survives ``counts[i]`` times.

        Returns:
            ``source``: slot ``j`` now holds a copy of (old) particle ``source[j]``; the
            caller permutes every other per-particle array the same way.
        """
        counts = np.asarray(counts, dtype=np.int64)
        if counts.shape != (self.particles,) or counts.sum() != self.particles:
            raise GMappingInputError("resampling counts must sum to the number of particles")
        source = np.arange(self.particles, dtype=np.int64)
        free = [int(i) for i in np.flatnonzero(counts == 0)]
        for i in np.flatnonzero(counts > 1):
            for _ in range(int(counts[i]) - 1):
                j = free.pop()
                self.cells[j] = self.cells[i]
                source[j] = i
        return source

    def occupancy(
        self,
        particle: int,
        occ_thresh: float,
        extent: tuple[float, float, float, float] | None = None,
    ) -> GMappingMap:
        """A particle's map as int8 occupancy (see :class:`GMappingMap`).

        Args:
            particle: which map.
            occ_thresh: cells with ``hits / visits > occ_thresh`` are occupied.
            extent: ``(xmin, ymin, xmax, ymax)`` the result must cover besides the
                explored block (slam_gmapping publishes at least its configured box).
        """
        cells = self.cells[particle]
        hits = cells[..., HITS].astype(np.int64)
        visits = cells[..., VISITS].astype(np.int64)
        block = np.full(hits.shape, -1, dtype=np.int8)
        seen = visits > 0
        block[seen] = 0
        # hits / visits > occ_thresh, without dividing.
        block[seen & (hits > occ_thresh * visits)] = 100
        h, w = block.shape
        x0, y0, x1, y1 = self._ix0, self._iy0, self._ix0 + w, self._iy0 + h
        if extent is not None:
            ex0, ey0 = self._lattice(extent[0], extent[1])
            ex1 = math.ceil((extent[2] - self.anchor_xy[0]) / self.delta - 1e-9)
            ey1 = math.ceil((extent[3] - self.anchor_xy[1]) / self.delta - 1e-9)
            x0, y0 = min(x0, ex0), min(y0, ey0)
            x1, y1 = max(x1, ex1), max(y1, ey1)
        if (x0, y0, x1, y1) == (self._ix0, self._iy0, self._ix0 + w, self._iy0 + h):
            data = block
        else:
            data = np.full((y1 - y0, x1 - x0), -1, dtype=np.int8)
            dy, dx = self._iy0 - y0, self._ix0 - x0
            data[dy : dy + h, dx : dx + w] = block
        origin = (self.anchor_xy[0] + x0 * self.delta, self.anchor_xy[1] + y0 * self.delta)
        return GMappingMap(data=data, origin_xy=origin, resolution=self.delta)
