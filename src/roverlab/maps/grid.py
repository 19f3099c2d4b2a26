"""Occupancy grids built from laser scans: the one shared implementation.

Two grids share one geometry and one compiled ray tracer:

* :class:`LogOddsGrid`: a float32 log-odds value per cell (hector_mapping, Cartographer,
  the textbook inverse sensor model). A scan changes each cell at most once: ``+l_occ``
  when a beam ends in it, otherwise ``+l_free`` when a beam passes through it; the result
  is clamped to ``[l_min, l_max]``. The order of the beams does not matter.
* :class:`CountGrid`: hits and visits per cell (gmapping's ``PointAccumulator``). Every
  beam visits each cell it passes through and hits its end cell; a cell's occupancy is
  ``hits / visits``.

Layout (``nav_msgs/OccupancyGrid``'s): cell ``[iy, ix]`` covers
``x in origin_x + [ix, ix + 1) * resolution`` and ``y in origin_y + [iy, iy + 1) * resolution``;
row 0 lies at the origin, rows grow along +y. A beam marks exactly the cells its segment
crosses (Amanatides-Woo DDA, every crossing parameter computed from the start point, so
there is no drift); a segment through a cell corner also visits the side cell it reaches
first along x.

Beams (gmapping's ``maxRange`` / ``maxUrange`` semantics), for a laser at ``pose``:

* NaN readings, readings ``<= 0`` or below ``range_min`` are skipped;
* a reading below the usable range (``usable_range``, default ``range_max``) marks the
  cells before its end free and its end cell occupied;
* a reading at or beyond the usable range, or at or beyond ``range_max`` (``inf``
  included), marks the cells up to the usable range free and no end point. With
  ``clear_max_range=False`` readings at or beyond ``range_max`` are skipped instead,
  as gmapping does.

The hot loops (tracing, updating) are numba-compiled (:mod:`roverlab.maps.raytrace`); there
is no Python loop over beams or cells. Grids grow (:meth:`ensure_contains`,
``update_scan(..., grow=True)``) by whole cells, keeping their content and cell alignment,
so a SLAM map can start small.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Generic, NamedTuple, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.maps.errors import GridError
from roverlab.maps.raytrace import (
    integrate_counts,
    integrate_log_odds,
    trace_cells,
    trace_segment_cells,
)
from roverlab.msgs import array_to_occupancy_grid
from roverlab.msgs import classes as mc

__all__ = [
    "CountGrid",
    "LogOddsGrid",
    "ScanRays",
    "scan_arrays",
    "trace_cells",
    "trace_segment_cells",
]

_R = TypeVar("_R")  # what a grid's update_scan returns


# ------------------------------------------------------------------------------- geometry
def scan_arrays(
    ranges: ArrayLike, angles: ArrayLike, error: type[Exception]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A scan's ranges and beam angles as flat float64 arrays.

    Raises:
        error: ``"<n> ranges but <m> angles"`` or ``"beam angles must be finite"``.
    """
    r = np.asarray(ranges, dtype=np.float64).ravel()
    a = np.asarray(angles, dtype=np.float64).ravel()
    if r.shape != a.shape:
        raise error(f"{r.size} ranges but {a.size} angles")
    if not np.all(np.isfinite(a)):
        raise error("beam angles must be finite")
    return r, a


class ScanRays:
    """The beams of one scan that update a grid, in world coordinates.

    Attributes:
        origin: ``(x, y)`` of the laser, m.
        ends: ``(N, 2)`` end points of the used beams, m.
        hit: ``(N,)`` True where the end point is an obstacle.
    """

    __slots__ = ("ends", "hit", "origin")

    def __init__(
        self,
        pose: ArrayLike,
        ranges: ArrayLike,
        angles: ArrayLike,
        range_max: float,
        *,
        range_min: float = 0.0,
        usable_range: float | None = None,
        clear_max_range: bool = True,
    ) -> None:
        p = np.asarray(pose, dtype=np.float64).ravel()
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise GridError(f"pose must be three finite numbers (x, y, theta), got {pose!r}")
        r, a = scan_arrays(ranges, angles, GridError)
        if not (math.isfinite(range_max) and range_max > 0):
            raise GridError(f"range_max must be a positive number of metres, got {range_max}")
        if not (math.isfinite(range_min) and range_min >= 0):
            raise GridError(f"range_min must be >= 0 m, got {range_min}")
        usable = float(range_max)
        if usable_range is not None:
            if not (usable_range > 0):
                raise GridError(f"usable_range must be > 0 m, got {usable_range}")
            usable = min(usable, float(usable_range))
        with np.errstate(invalid="ignore"):
            valid = (r > 0.0) & (r >= range_min)  # NaN compares False: skipped
            if not clear_max_range:
                valid &= r < range_max
        r = r[valid]
        theta = p[2] + a[valid]
        length = np.minimum(r, usable)
        self.origin = (float(p[0]), float(p[1]))
        self.hit: NDArray[np.bool_] = r < usable
        self.ends: NDArray[np.float64] = np.stack(
            [p[0] + length * np.cos(theta), p[1] + length * np.sin(theta)], axis=1
        )

    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the laser and every end point."""
        xs = np.append(self.ends[:, 0], self.origin[0])
        ys = np.append(self.ends[:, 1], self.origin[1])
        return float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max())


class _CellBeams(NamedTuple):
    """A scan's beams in a grid's cell units, in the order the kernels take them."""

    gx0: float  #: the laser
    gy0: float
    gxe: NDArray[np.float64]  #: the end points
    gye: NDArray[np.float64]
    hit: NDArray[np.bool_]  #: True where the end point is an obstacle


class _Grid(Generic[_R]):
    """Geometry, conversions and growth shared by the grids."""

    _layer_fill: ClassVar[dict[str, Any]] = {}

    def __init__(
        self, width: int, height: int, resolution: float, origin_xy: tuple[float, float]
    ) -> None:
        if isinstance(width, bool) or int(width) != width or width < 1:
            raise GridError(f"width must be a positive number of cells, got {width!r}")
        if isinstance(height, bool) or int(height) != height or height < 1:
            raise GridError(f"height must be a positive number of cells, got {height!r}")
        if not (math.isfinite(resolution) and resolution > 0):
            raise GridError(f"resolution must be a positive number of metres, got {resolution}")
        ox, oy = (float(v) for v in origin_xy)
        if not (math.isfinite(ox) and math.isfinite(oy)):
            raise GridError(f"origin_xy must be finite, got {origin_xy!r}")
        self._w = int(width)
        self._h = int(height)
        self._res = float(resolution)
        self._ox = ox
        self._oy = oy
        self._buf = np.empty(0, dtype=np.int64)

    # ----------------------------------------------------------------- geometry
    @property
    def width(self) -> int:
        """Cells along x."""
        return self._w

    @property
    def height(self) -> int:
        """Cells along y."""
        return self._h

    @property
    def shape(self) -> tuple[int, int]:
        """``(height, width)``, the shape of the cell arrays."""
        return (self._h, self._w)

    @property
    def resolution(self) -> float:
        """Cell side, m."""
        return self._res

    @property
    def origin_xy(self) -> tuple[float, float]:
        """World ``(x, y)`` of the outer corner of cell ``[0, 0]``, m."""
        return (self._ox, self._oy)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of the covered area, m."""
        return (
            self._ox,
            self._oy,
            self._ox + self._w * self._res,
            self._oy + self._h * self._res,
        )

    def world_to_cell(self, x: float, y: float) -> tuple[int, int]:
        """``(ix, iy)`` of the cell holding world point ``(x, y)`` (may lie outside)."""
        return (
            math.floor((x - self._ox) / self._res),
            math.floor((y - self._oy) / self._res),
        )

    def world_to_cells(self, xy: ArrayLike) -> NDArray[np.int64]:
        """:meth:`world_to_cell` of an ``(N, 2)`` array of points: ``(N, 2)`` ``(ix, iy)``."""
        pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        origin = np.array([self._ox, self._oy])
        return np.floor((pts - origin) / self._res).astype(np.int64)

    def cell_to_world(self, ix: float, iy: float) -> tuple[float, float]:
        """World ``(x, y)`` of the centre of cell ``(ix, iy)``."""
        return (self._ox + (ix + 0.5) * self._res, self._oy + (iy + 0.5) * self._res)

    def contains(self, x: float, y: float) -> bool:
        """Whether world point ``(x, y)`` lies in a cell of the grid."""
        ix, iy = self.world_to_cell(x, y)
        return 0 <= ix < self._w and 0 <= iy < self._h

    # ----------------------------------------------------------------- growth
    def ensure_contains(self, x: float, y: float, *, padding_m: float | None = None) -> bool:
        """Grow the grid, if needed, so that ``(x, y)`` lies inside it.

        Content and cell alignment are kept; the origin moves by whole cells. A side that
        grows gets ``padding_m`` more (default: a quarter of the current size, at least
        1 m) so repeated growth stays cheap.

        Returns:
            Whether the grid grew.

        Raises:
            GridError: a non-finite point.
        """
        return self._ensure_box(x, y, x, y, padding_m)

    def _ensure_box(
        self, xmin: float, ymin: float, xmax: float, ymax: float, padding_m: float | None
    ) -> bool:
        if not all(math.isfinite(v) for v in (xmin, ymin, xmax, ymax)):
            raise GridError("cannot grow a grid to a non-finite point")
        ix0, iy0 = self.world_to_cell(xmin, ymin)
        ix1, iy1 = self.world_to_cell(xmax, ymax)
        if ix0 >= 0 and iy0 >= 0 and ix1 < self._w and iy1 < self._h:
            return False
        if padding_m is None:
            pad_x = max(math.ceil(1.0 / self._res), self._w // 4)
            pad_y = max(math.ceil(1.0 / self._res), self._h // 4)
        else:
            pad_x = pad_y = max(0, math.ceil(padding_m / self._res))
        left = -ix0 + pad_x if ix0 < 0 else 0
        bottom = -iy0 + pad_y if iy0 < 0 else 0
        right = ix1 - self._w + 1 + pad_x if ix1 >= self._w else 0
        top = iy1 - self._h + 1 + pad_y if iy1 >= self._h else 0
        self._grow(left, bottom, right, top)
        return True

    def _grow(self, left: int, bottom: int, right: int, top: int) -> None:
        w, h = self._w, self._h
        nw, nh = w + left + right, h + bottom + top
        for name, fill in self._layer_fill.items():
            old = getattr(self, name)
            new = np.full((nh, nw), fill, dtype=old.dtype)
            new[bottom : bottom + h, left : left + w] = old
            setattr(self, name, new)
        self._w, self._h = nw, nh
        self._ox -= left * self._res
        self._oy -= bottom * self._res
        self._on_resize()

    def _on_resize(self) -> None:
        """Re-allocate scratch space after growth."""

    # ----------------------------------------------------------------- scans
    def update_scan(
        self,
        pose: ArrayLike,
        ranges: ArrayLike,
        angles: ArrayLike,
        range_max: float,
        *,
        range_min: float = 0.0,
        usable_range: float | None = None,
        clear_max_range: bool = True,
        grow: bool = False,
    ) -> _R:
        """Integrate one scan.

        Args:
            pose: ``(x, y, theta)`` of the laser in the map frame, m and rad.
            ranges: ``(N,)`` readings, m (``inf`` = nothing within range).
            angles: ``(N,)`` beam angles in the laser frame, rad.
            range_max: the sensor's maximum range, m.
            range_min: readings below it are skipped, m.
            usable_range: beams are used up to this range (gmapping's ``maxUrange``), m.
            clear_max_range: free the cells along beams at or beyond ``range_max``.
            grow: first grow the grid to hold the laser and every end point.

        Returns:
            :class:`LogOddsGrid`: how many cells changed; :class:`CountGrid`: None.

        Raises:
            GridError: mismatched or non-finite inputs.
        """
        rays = ScanRays(
            pose,
            ranges,
            angles,
            range_max,
            range_min=range_min,
            usable_range=usable_range,
            clear_max_range=clear_max_range,
        )
        if grow:
            self._ensure_box(*rays.bounds(), None)
        need = self._w + self._h + 2
        if self._buf.shape[0] < need:
            self._buf = np.empty(need, dtype=np.int64)
        return self._integrate(
            _CellBeams(
                (rays.origin[0] - self._ox) / self._res,
                (rays.origin[1] - self._oy) / self._res,
                np.ascontiguousarray((rays.ends[:, 0] - self._ox) / self._res),
                np.ascontiguousarray((rays.ends[:, 1] - self._oy) / self._res),
                np.ascontiguousarray(rays.hit),
            )
        )

    def _integrate(self, beams: _CellBeams) -> _R:  # pragma: no cover - overridden
        """Apply the beams of one scan to the cells."""
        raise NotImplementedError

    def to_occupancy(self) -> NDArray[np.int8]:  # pragma: no cover - overridden
        raise NotImplementedError

    def to_msg(self, *, frame_id: str = "map", stamp: Any = None) -> mc.OccupancyGrid:
        """The grid as a ``nav_msgs/OccupancyGrid`` (default thresholds of
        :meth:`to_occupancy`)."""
        return array_to_occupancy_grid(
            self.to_occupancy(),
            resolution=self._res,
            origin=(self._ox, self._oy, 0.0),
            frame_id=frame_id,
            stamp=stamp,
        )


def _logit(p: float) -> float:
    if p <= 0.0:
        return -math.inf
    if p >= 1.0:
        return math.inf
    return math.log(p / (1.0 - p))


def _check_thresholds(occupied_thresh: float, free_thresh: float) -> None:
    if not (0.0 <= free_thresh <= occupied_thresh <= 1.0):
        raise GridError(
            "thresholds must satisfy 0 <= free_thresh <= occupied_thresh <= 1, got "
            f"free_thresh={free_thresh}, occupied_thresh={occupied_thresh}"
        )


# --------------------------------------------------------------------------------- grids
class LogOddsGrid(_Grid[int]):
    """An occupancy grid of clamped log-odds values (0 = unknown, p = 0.5).

    Args:
        width, height: size in cells.
        resolution: cell side, m.
        origin_xy: world ``(x, y)`` of the outer corner of cell ``[0, 0]``, m.
        l_occ: log-odds added to a cell a beam ends in (> 0); the default is
            ``log(0.7 / 0.3)``, hector_mapping's ``update_factor_occupied`` of 0.7.
        l_free: log-odds added to a cell a beam passes through (< 0); the default is
            ``log(0.4 / 0.6)``, hector_mapping's ``update_factor_free`` of 0.4.
        l_min, l_max: clamp of every cell (``l_min < 0 < l_max``), so the map can change
            its mind.

    Raises:
        GridError: a bad size, resolution, origin or log-odds setting.
    """

    _layer_fill: ClassVar[dict[str, Any]] = {"_lo": 0.0}

    def __init__(
        self,
        width: int,
        height: int,
        resolution: float,
        origin_xy: tuple[float, float] = (0.0, 0.0),
        *,
        l_occ: float = 0.8472978603872037,
        l_free: float = -0.4054651081081644,
        l_min: float = -4.0,
        l_max: float = 4.0,
    ) -> None:
        super().__init__(width, height, resolution, origin_xy)
        if not (math.isfinite(l_occ) and l_occ > 0):
            raise GridError(f"l_occ must be a positive log-odds value, got {l_occ}")
        if not (math.isfinite(l_free) and l_free < 0):
            raise GridError(f"l_free must be a negative log-odds value, got {l_free}")
        if not (math.isfinite(l_min) and math.isfinite(l_max) and l_min < 0 < l_max):
            raise GridError(f"need l_min < 0 < l_max, got l_min={l_min}, l_max={l_max}")
        self.l_occ = float(l_occ)
        self.l_free = float(l_free)
        self.l_min = float(l_min)
        self.l_max = float(l_max)
        self._lo = np.zeros((self._h, self._w), dtype=np.float32)
        self._mark = np.zeros(self._h * self._w, dtype=np.uint8)

    def _on_resize(self) -> None:
        self._mark = np.zeros(self._h * self._w, dtype=np.uint8)

    @property
    def log_odds(self) -> NDArray[np.float32]:
        """The ``(height, width)`` float32 cells (a live view: writes change the grid)."""
        return self._lo

    def _integrate(self, beams: _CellBeams) -> int:
        gx0, gy0, gxe, gye, _ = beams
        bound = int(np.sum(np.ceil(np.abs(gxe - gx0)) + np.ceil(np.abs(gye - gy0)) + 5.0))
        touched = np.empty(min(bound, self._w * self._h), dtype=np.int64)
        return int(
            integrate_log_odds(
                self._lo.reshape(-1),
                self._mark,
                *beams,
                self._w,
                self._h,
                self.l_occ,
                self.l_free,
                self.l_min,
                self.l_max,
                touched,
                self._buf,
            )
        )

    def probabilities(self) -> NDArray[np.float64]:
        """Occupancy probability of every cell, ``1 / (1 + exp(-l))`` (0.5 = unknown)."""
        return 1.0 / (1.0 + np.exp(-self._lo.astype(np.float64)))

    def to_occupancy(
        self, occupied_thresh: float = 0.65, free_thresh: float = 0.196
    ) -> NDArray[np.int8]:
        """``OccupancyGrid`` cells: 100 where p > ``occupied_thresh``, 0 where
        p < ``free_thresh``, -1 otherwise (map_server's trinary rule and defaults)."""
        _check_thresholds(occupied_thresh, free_thresh)
        out = np.full(self._lo.shape, -1, dtype=np.int8)
        out[self._lo < _logit(free_thresh)] = 0
        out[self._lo > _logit(occupied_thresh)] = 100
        return out


class CountGrid(_Grid[None]):
    """An occupancy grid of hit and visit counts (gmapping's map).

    Args:
        width, height: size in cells.
        resolution: cell side, m.
        origin_xy: world ``(x, y)`` of the outer corner of cell ``[0, 0]``, m.

    Raises:
        GridError: a bad size, resolution or origin.
    """

    _layer_fill: ClassVar[dict[str, Any]] = {"_hits": 0, "_visits": 0}

    def __init__(
        self,
        width: int,
        height: int,
        resolution: float,
        origin_xy: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        super().__init__(width, height, resolution, origin_xy)
        self._hits = np.zeros((self._h, self._w), dtype=np.int32)
        self._visits = np.zeros((self._h, self._w), dtype=np.int32)

    @property
    def hits(self) -> NDArray[np.int32]:
        """``(height, width)`` count of beams that ended in each cell (live view)."""
        return self._hits

    @property
    def visits(self) -> NDArray[np.int32]:
        """``(height, width)`` count of beams that passed through or ended in each cell."""
        return self._visits

    def _integrate(self, beams: _CellBeams) -> None:
        integrate_counts(
            self._hits.reshape(-1),
            self._visits.reshape(-1),
            *beams,
            self._w,
            self._h,
            self._buf,
        )

    def probabilities(self) -> NDArray[np.float64]:
        """``hits / visits`` per cell; NaN where no beam came (unknown)."""
        out = np.full(self._hits.shape, np.nan)
        np.divide(self._hits, self._visits, out=out, where=self._visits > 0)
        return out

    def to_occupancy(
        self, occupied_thresh: float = 0.25, free_thresh: float | None = None
    ) -> NDArray[np.int8]:
        """``OccupancyGrid`` cells as slam_gmapping publishes them: -1 where no beam came,
        100 where ``hits / visits > occupied_thresh`` (gmapping's ``occ_thresh``, 0.25),
        otherwise 0 — or, given ``free_thresh``, 0 only where the ratio is below it and
        -1 in between."""
        ft = 0.0 if free_thresh is None else free_thresh
        _check_thresholds(occupied_thresh, ft)
        p = self.probabilities()
        seen = self._visits > 0
        out = np.full(p.shape, -1, dtype=np.int8)
        with np.errstate(invalid="ignore"):
            if free_thresh is None:
                out[seen] = 0
            else:
                out[seen & (p < free_thresh)] = 0
            out[seen & (p > occupied_thresh)] = 100
        return out
