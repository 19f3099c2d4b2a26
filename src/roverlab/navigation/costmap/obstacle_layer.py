"""costmap_2d's ``ObstacleLayer``: obstacles marked and cleared from sensor observations.

Each observation source (``observation_sources: "scan bump"``) keeps an
:class:`ObservationBuffer` of point clouds in the costmap's global frame, each with the
sensor origin, filtered to ``[min_obstacle_height, max_obstacle_height]``. At every update
(:meth:`ObstacleLayer.update_bounds`):

1. the layer's grid follows the robot (rolling window);
2. every *clearing* observation frees the cells along the ray from the sensor origin to
   each point, up to ``raytrace_range`` (roverlab's shared compiled grid tracer; ROS uses
   Bresenham);
3. every *marking* observation marks as lethal the cell of each point lower than the
   layer's ``max_obstacle_height`` and closer (3-D) than ``obstacle_range`` to the sensor;
4. the robot's footprint is cleared (``footprint_clearing_enabled``).

The layer's costs go to the master by ``combination_method`` (0 overwrite, 1 maximum, any
other value: not at all). ``observation_persistence`` keeps observations that long (0: only
the latest); ``expected_update_rate`` makes the layer not current when a source is late.

An observation may be buffered as a function that makes its points: it is called only
when an update uses the observation, so a 50 Hz laser read by a 5 Hz costmap with
``observation_persistence`` 0 is projected 5 times a second, not 50 (the points are the
same as if projected on arrival; ROS projects every scan as it comes).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.navigation.costmap.costmap_2d import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from roverlab.navigation.costmap.footprint import transform_footprint
from roverlab.navigation.costmap.kernels import (
    height_filter,
    mark_observation,
    raytrace_freespace,
)
from roverlab.navigation.costmap.layered import Bounds, CostmapLayer
from roverlab.navigation.errors import CostmapError
from roverlab.navigation.params import check

__all__ = [
    "DATA_TYPES",
    "Observation",
    "ObservationBuffer",
    "ObservationSourceParams",
    "ObstacleLayer",
    "ObstacleLayerParams",
    "project_scan",
]

#: The ``data_type`` values an observation source may have.
DATA_TYPES = ("LaserScan", "PointCloud2", "PointCloud")


@dataclass(frozen=True, slots=True, kw_only=True)
class ObservationSourceParams:
    """One observation source (ROS names and defaults of costmap_2d's obstacle layer)."""

    name: str
    topic: str = ""
    sensor_frame: str = ""
    observation_persistence: float = 0.0
    expected_update_rate: float = 0.0
    data_type: str = "PointCloud"
    min_obstacle_height: float = 0.0
    max_obstacle_height: float = 2.0
    inf_is_valid: bool = False
    clearing: bool = False
    marking: bool = True
    obstacle_range: float = 2.5
    raytrace_range: float = 3.0

    def __post_init__(self) -> None:
        w = f"obstacle_layer source {self.name}"
        check(
            self.data_type in DATA_TYPES,
            f"{w}: data_type must be one of {', '.join(DATA_TYPES)}, got {self.data_type!r}",
        )
        check(self.observation_persistence >= 0, f"{w}: observation_persistence must be >= 0")
        check(self.expected_update_rate >= 0, f"{w}: expected_update_rate must be >= 0")
        check(
            self.min_obstacle_height <= self.max_obstacle_height,
            f"{w}: min_obstacle_height must be <= max_obstacle_height",
        )
        check(self.obstacle_range >= 0, f"{w}: obstacle_range must be >= 0")
        check(self.raytrace_range >= 0, f"{w}: raytrace_range must be >= 0")

    @property
    def topic_name(self) -> str:
        """The topic (the source's name when ``topic`` is not set)."""
        return self.topic or self.name


@dataclass(frozen=True, slots=True, kw_only=True)
class ObstacleLayerParams:
    """The obstacle layer's parameters (ROS names and defaults).

    ``track_unknown_space`` None means the costmap's own setting, as costmap_2d.
    ``transform_tolerance`` (s): how long an observation may wait for its transform before
    it is dropped (ROS: the observation buffers' TF tolerance; None, the default here:
    it waits as long as the queue allows, as before).
    """

    enabled: bool = True
    track_unknown_space: bool | None = None
    max_obstacle_height: float = 2.0
    transform_tolerance: float | None = None
    footprint_clearing_enabled: bool = True
    combination_method: int = 1
    observation_sources: tuple[ObservationSourceParams, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        names = [s.name for s in self.observation_sources]
        check(len(set(names)) == len(names), "obstacle_layer: observation source listed twice")
        check(
            self.transform_tolerance is None or self.transform_tolerance >= 0,
            "obstacle_layer: transform_tolerance must be >= 0",
        )


@dataclass(frozen=True, slots=True)
class Observation:
    """Points seen by one sensor at one time, in the costmap's global frame.

    Attributes:
        origin: ``(x, y, z)`` of the sensor, m.
        points: ``(N, 3)`` float64 points, m.
        obstacle_range: marking range of the source, m.
        raytrace_range: clearing range of the source, m.
        stamp_s: the sensor data's time, s.
    """

    origin: NDArray[np.float64]
    points: NDArray[np.float64]
    obstacle_range: float
    raytrace_range: float
    stamp_s: float


def project_scan(
    ranges: ArrayLike,
    angles: ArrayLike,
    range_min: float,
    range_max: float,
    *,
    inf_is_valid: bool = False,
) -> NDArray[np.float64]:
    """laser_geometry's projection of a LaserScan: ``(N, 3)`` points in the laser frame.

    Readings in ``[range_min, range_max)`` are kept (NaN dropped). With ``inf_is_valid``
    an infinite reading counts as ``range_max - 0.0001`` (costmap_2d's
    ``laserScanValidInfCallback``): it clears but does not mark.
    """
    r = np.asarray(ranges, dtype=np.float64).ravel()
    a = np.asarray(angles, dtype=np.float64).ravel()
    if r.shape != a.shape:
        raise CostmapError(f"laser scan: {r.size} ranges but {a.size} angles")
    if inf_is_valid:
        r = np.where(np.isposinf(r), range_max - 1e-4, r)
    with np.errstate(invalid="ignore"):
        keep = (r >= range_min) & (r < range_max)
    r, a = r[keep], a[keep]
    return np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)])


#: Points of an observation, or a function making them (called once, when first used).
PointSource = ArrayLike | Callable[[], ArrayLike]


@dataclass(frozen=True, slots=True)
class _Pending:
    """An observation whose points are not made yet (see the module docstring)."""

    origin: NDArray[np.float64]
    make: Callable[[], ArrayLike]
    stamp_s: float


class ObservationBuffer:
    """costmap_2d's ``ObservationBuffer`` for one source."""

    def __init__(self, params: ObservationSourceParams) -> None:
        self.params = params
        self.observations: list[Observation | _Pending] = []
        self.last_updated_s: float | None = None

    def buffer_points(
        self, origin: ArrayLike, points: PointSource, stamp_s: float, now_s: float
    ) -> None:
        """Add a cloud (global frame) seen from ``origin`` at ``stamp_s``; ``now_s`` is the
        clock time (for ``expected_update_rate``). ``points`` may be a function returning
        the cloud: it is called when an update first uses the observation (never, when a
        newer one replaces it first)."""
        o = np.asarray(origin, dtype=np.float64).reshape(3)
        if not (math.isfinite(o[0]) and math.isfinite(o[1]) and math.isfinite(o[2])):
            raise CostmapError(f"observation {self.params.name}: sensor origin is not finite")
        if callable(points):
            obs: Observation | _Pending = _Pending(o, points, float(stamp_s))
        else:
            obs = self._observation(o, points, float(stamp_s))
        self.observations.insert(0, obs)
        self.last_updated_s = float(now_s)
        self._purge()

    def _observation(
        self, origin: NDArray[np.float64], points: ArrayLike, stamp_s: float
    ) -> Observation:
        pts = np.ascontiguousarray(np.asarray(points, dtype=np.float64).reshape(-1, 3))
        p = self.params
        kept = height_filter(pts, p.min_obstacle_height, p.max_obstacle_height)  # compiled
        return Observation(origin, kept, p.obstacle_range, p.raytrace_range, stamp_s)

    def _purge(self) -> None:
        if not self.observations:
            return
        keep = self.params.observation_persistence
        if keep == 0.0:
            del self.observations[1:]
            return
        latest = self.last_updated_s if self.last_updated_s is not None else 0.0
        self.observations = [o for o in self.observations if latest - o.stamp_s <= keep]

    def get_observations(self) -> list[Observation]:
        """The observations kept (newest first); points still to be made are made now.

        Raises:
            CostmapError: an observation whose points could not be made (it is dropped).
        """
        self._purge()
        obs = self.observations
        for i, o in enumerate(obs):
            if isinstance(o, _Pending):
                try:
                    obs[i] = self._observation(o.origin, o.make(), o.stamp_s)
                except (CostmapError, ValueError) as err:
                    del obs[i]
                    raise CostmapError(f"{self.params.name} dropped: {err}") from err
        return list(obs)  # type: ignore[arg-type]  # every entry made above

    def is_current(self, now_s: float) -> bool:
        """Updated within ``expected_update_rate`` (always, when it is 0)."""
        rate = self.params.expected_update_rate
        if rate == 0.0:
            return True
        return self.last_updated_s is not None and now_s - self.last_updated_s <= rate

    def clear(self) -> None:
        self.observations.clear()


class ObstacleLayer(CostmapLayer):
    """The obstacle layer.

    Args:
        name: plugin name (``obstacle_layer``).
        params: its parameters (with its observation sources).

    Attributes:
        buffers: the observation buffer of each source, by source name.
        sensor_warnings: messages about observations that could not be used (the node
            logs and clears them).
    """

    def __init__(self, name: str, params: ObstacleLayerParams) -> None:
        super().__init__(name, enabled=params.enabled)
        self.params = params
        self.buffers = {s.name: ObservationBuffer(s) for s in params.observation_sources}
        self.sensor_warnings: list[str] = []
        self._footprint = np.zeros((0, 2))
        self._trace_buf = np.empty(0, dtype=np.int64)
        self._box = np.zeros(4)  # min x, min y, max x, max y of a kernel's cells

    def on_initialize(self) -> None:
        track = self.params.track_unknown_space
        if track is None:
            track = self.layered.track_unknown_space
        self.grid.default_value = NO_INFORMATION if track else FREE_SPACE

    def reset(self) -> None:
        super().reset()
        for b in self.buffers.values():
            b.clear()

    def is_current(self, now_s: float) -> bool:
        return all(
            b.is_current(now_s)
            for b in self.buffers.values()
            if b.params.marking or b.params.clearing
        )

    def add_observation(
        self, source: str, origin: ArrayLike, points: PointSource, stamp_s: float, now_s: float
    ) -> None:
        """Buffer a cloud of source ``source`` (global frame, seen from ``origin``; or a
        function making it, see :meth:`ObservationBuffer.buffer_points`)."""
        try:
            buf = self.buffers[source]
        except KeyError:
            raise CostmapError(f"{self.name}: no observation source {source!r}") from None
        buf.buffer_points(origin, points, stamp_s, now_s)

    # ------------------------------------------------------------------ updates
    def update_bounds(
        self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds, now_s: float
    ) -> None:
        g = self.grid
        if self.layered.rolling_window:
            g.update_origin(robot_x - g.size_in_meters_x / 2.0, robot_y - g.size_in_meters_y / 2.0)
        self.use_extra_bounds(bounds)
        for buf in self.buffers.values():
            if buf.params.clearing:
                for obs in self._observations(buf):
                    self._raytrace_freespace(obs, bounds)
        for buf in self.buffers.values():
            if buf.params.marking:
                for obs in self._observations(buf):
                    self._mark(obs, bounds)
        if self.params.footprint_clearing_enabled and len(self.layered.footprint) >= 3:
            self._footprint = transform_footprint(
                robot_x, robot_y, robot_yaw, self.layered.footprint
            )
            for x, y in self._footprint:
                bounds.touch(float(x), float(y))

    def _observations(self, buf: ObservationBuffer) -> list[Observation]:
        """The buffer's observations; one whose points cannot be made is dropped (told in
        ``sensor_warnings``), as the node drops a message it cannot convert."""
        while True:
            try:
                return buf.get_observations()
            except CostmapError as err:
                self.sensor_warnings.append(str(err))

    def _mark(self, obs: Observation, bounds: Bounds) -> None:
        pts = obs.points
        if len(pts) == 0:
            return
        g = self.grid
        box = self._box
        if mark_observation(
            g.costs, pts, obs.origin, self.params.max_obstacle_height, obs.obstacle_range,
            g.origin_x, g.origin_y, g.resolution, LETHAL_OBSTACLE, box,
        ):  # fmt: skip
            bounds.touch(float(box[0]), float(box[1]))
            bounds.touch(float(box[2]), float(box[3]))

    def _raytrace_freespace(self, obs: Observation, bounds: Bounds) -> None:
        g = self.grid
        ox, oy = float(obs.origin[0]), float(obs.origin[1])
        if g.world_to_map(ox, oy) is None:
            self.sensor_warnings.append(
                f"The origin for the sensor at ({ox:.2f}, {oy:.2f}) is out of map bounds. "
                "So, the costmap cannot raytrace for it."
            )
            return
        bounds.touch(ox, oy)
        pts = obs.points
        if len(pts) == 0:
            return
        x0, y0 = g.origin_x, g.origin_y
        x1 = x0 + g.size_x * g.resolution
        y1 = y0 + g.size_y * g.resolution
        need = g.size_x + g.size_y + 4
        if self._trace_buf.shape[0] < need:
            self._trace_buf = np.empty(need, dtype=np.int64)
        box = self._box
        if raytrace_freespace(
            g.costs, pts, ox, oy, x0, y0, x1, y1, g.resolution, obs.raytrace_range,
            FREE_SPACE, self._trace_buf, box,
        ):  # fmt: skip
            bounds.touch(float(box[0]), float(box[1]))
            bounds.touch(float(box[2]), float(box[3]))

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        if self.params.footprint_clearing_enabled and len(self._footprint) >= 3:
            self.grid.set_convex_polygon_cost(self._footprint, FREE_SPACE)
        method = self.params.combination_method
        if method == 0:
            self.update_with_overwrite(master, x0, y0, xn, yn)
        elif method == 1:
            self.update_with_max(master, x0, y0, xn, yn)
