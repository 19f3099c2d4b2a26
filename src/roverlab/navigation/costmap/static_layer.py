"""costmap_2d's ``StaticLayer``: the costs of a map from ``map_server`` (or a SLAM node).

Map values (``nav_msgs/OccupancyGrid``: -1 unknown, 0..100) become costs by costmap_2d's
``interpretValue``: the ``unknown_cost_value`` (-1) is unknown (255) with
``track_unknown_space`` and free otherwise; values ``>= lethal_cost_threshold`` are lethal;
the rest are free with ``trinary_costmap``, else scaled ``value / threshold * 254``.

Not rolling: a map of another size, resolution or origin resizes the master grid (and
locks its size), and the layer overwrites the master in the update window (max with
``use_maximum``). Rolling: the layer keeps the map at its own geometry and each master cell
of the window looks its cost up through ``map_to_global`` (the TF of the map frame in the
costmap's global frame, set by the node).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import (
    FREE_SPACE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from roverlab.navigation.costmap.layered import Bounds, CostmapLayer
from roverlab.navigation.errors import CostmapError
from roverlab.navigation.params import check

__all__ = ["StaticLayer", "StaticLayerParams", "interpret_values"]


@dataclass(frozen=True, slots=True, kw_only=True)
class StaticLayerParams:
    """The static layer's parameters (ROS names and defaults)."""

    enabled: bool = True
    map_topic: str = "map"
    first_map_only: bool = False
    subscribe_to_updates: bool = False
    track_unknown_space: bool = True
    use_maximum: bool = False
    unknown_cost_value: int = -1
    trinary_costmap: bool = True
    lethal_cost_threshold: int = 100

    def __post_init__(self) -> None:
        check(bool(self.map_topic), "static_layer: map_topic must not be empty")
        check(
            -1 <= self.unknown_cost_value <= 255,
            f"static_layer: unknown_cost_value must be in -1..255, got {self.unknown_cost_value}",
        )
        check(
            0 <= self.lethal_cost_threshold <= 255,
            "static_layer: lethal_cost_threshold must be in 0..255, got "
            f"{self.lethal_cost_threshold}",
        )


def interpret_values(values: ArrayLike, p: StaticLayerParams) -> NDArray[np.uint8]:
    """costmap_2d's ``StaticLayer::interpretValue`` over an array of map values (-1..100;
    compared as the unsigned bytes ROS reads them)."""
    v = np.asarray(values).astype(np.int16) & 0xFF  # int8 -1 -> 255 as in ROS
    unknown = p.unknown_cost_value & 0xFF
    thresh = p.lethal_cost_threshold
    if p.trinary_costmap:
        out = np.full(v.shape, FREE_SPACE, dtype=np.uint8)
    else:
        scaled = np.floor(v.astype(np.float64) / max(thresh, 1) * LETHAL_OBSTACLE)
        out = np.clip(scaled, 0, LETHAL_OBSTACLE).astype(np.uint8)
    out[v >= thresh] = LETHAL_OBSTACLE
    out[v == unknown] = NO_INFORMATION if p.track_unknown_space else FREE_SPACE
    return out


class StaticLayer(CostmapLayer):
    """The static map layer.

    Args:
        name: plugin name (``static_layer``).
        params: its parameters.

    Attributes:
        map_to_global: pose of the map frame in the costmap's global frame (rolling only).
        map_frame: the ``header.frame_id`` of the last map.
        map_received: whether a map arrived.
    """

    def __init__(self, name: str, params: StaticLayerParams) -> None:
        super().__init__(name, enabled=params.enabled)
        self.params = params
        self.map_to_global = SE2()
        self.map_frame = ""
        self.map_received = False
        self._has_updated_data = False
        self._window = (0, 0, 0, 0)  # x, y, width, height of the last change (cells)

    def match_size(self) -> None:
        if not self.layered.rolling_window:
            super().match_size()

    def reset(self) -> None:
        # ROS re-subscribes and waits for the map again; the map we hold is that map
        self._has_updated_data = self.map_received

    # ------------------------------------------------------------------ inputs
    def incoming_map(
        self,
        data: ArrayLike,
        *,
        resolution: float,
        origin_x: float,
        origin_y: float,
        frame_id: str = "map",
    ) -> bool:
        """A whole map: ``data`` is ``(height, width)`` OccupancyGrid values.

        Returns:
            False if ignored (``first_map_only`` and a map was already received).

        Raises:
            CostmapError: not a 2-D array or a bad geometry.
        """
        if self.params.first_map_only and self.map_received:
            return False
        values = np.asarray(data)
        if values.ndim != 2 or values.size == 0:
            raise CostmapError(f"static_layer: map data must be a 2-D array, got {values.shape}")
        if not (math.isfinite(resolution) and resolution > 0):
            raise CostmapError(f"static_layer: map resolution must be > 0, got {resolution}")
        size_y, size_x = values.shape
        layered = self.layered
        master = layered.costmap
        if not layered.rolling_window and (
            master.size_x != size_x
            or master.size_y != size_y
            or master.resolution != resolution
            or master.origin_x != origin_x
            or master.origin_y != origin_y
        ):
            layered.resize_map(size_x, size_y, resolution, origin_x, origin_y, size_locked=True)
        elif (
            self.grid.size_x != size_x
            or self.grid.size_y != size_y
            or self.grid.resolution != resolution
            or self.grid.origin_x != origin_x
            or self.grid.origin_y != origin_y
        ):
            self.grid.resize_map(size_x, size_y, resolution, origin_x, origin_y)
        self.grid.costs[:] = interpret_values(values, self.params)
        self.map_frame = frame_id.lstrip("/")
        self.map_received = True
        self._has_updated_data = True
        self._window = (0, 0, size_x, size_y)
        return True

    def incoming_update(self, x: int, y: int, width: int, height: int, data: ArrayLike) -> None:
        """A ``map_msgs/OccupancyGridUpdate``: ``data`` holds ``width * height`` values of the
        cells ``[x, x + width) x [y, y + height)``.

        Raises:
            CostmapError: no map yet, a size mismatch, or a window off the map.
        """
        if not self.map_received:
            raise CostmapError("static_layer: a map update arrived before the map")
        vals = np.asarray(data).reshape(-1)
        if vals.size != width * height:
            raise CostmapError(
                f"static_layer: map update holds {vals.size} cells for {width}x{height}"
            )
        g = self.grid
        if x < 0 or y < 0 or x + width > g.size_x or y + height > g.size_y:
            raise CostmapError(
                f"static_layer: map update [{x}, {x + width}) x [{y}, {y + height}) is off the "
                f"{g.size_x}x{g.size_y} map"
            )
        g.costs[y : y + height, x : x + width] = interpret_values(
            vals.reshape(height, width), self.params
        )
        self._window = (x, y, width, height)
        self._has_updated_data = True

    # ------------------------------------------------------------------ updates
    def update_bounds(
        self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds, now_s: float
    ) -> None:
        if not self.layered.rolling_window and (
            not self.map_received or not (self._has_updated_data or self._extra is not None)
        ):
            return
        self.use_extra_bounds(bounds)
        if not self.map_received:
            return
        x, y, w, h = self._window
        g = self.grid
        if self.layered.rolling_window:
            x, y, w, h = 0, 0, g.size_x, g.size_y
            corners = np.array(
                [[x, y], [x + w, y], [x, y + h], [x + w, y + h]], dtype=np.float64
            ) * g.resolution + np.array([g.origin_x, g.origin_y])
            for cx, cy in self.map_to_global.apply(corners):
                bounds.touch(float(cx), float(cy))
        else:
            bounds.touch(g.origin_x + x * g.resolution, g.origin_y + y * g.resolution)
            bounds.touch(g.origin_x + (x + w) * g.resolution, g.origin_y + (y + h) * g.resolution)
        self._has_updated_data = False

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        if not self.map_received:
            return
        if not self.layered.rolling_window:
            if self.params.use_maximum:
                self.update_with_max(master, x0, y0, xn, yn)
            else:
                self.update_with_true_overwrite(master, x0, y0, xn, yn)
            return
        # rolling: look each master cell up in the map through map_to_global
        res = master.resolution
        ix = np.arange(x0, xn)
        iy = np.arange(y0, yn)
        wx = master.origin_x + (ix + 0.5) * res
        wy = master.origin_y + (iy + 0.5) * res
        gx, gy = np.meshgrid(wx, wy)
        pts = (~self.map_to_global).apply(np.column_stack([gx.ravel(), gy.ravel()]))
        g = self.grid
        fx = (pts[:, 0] - g.origin_x) / g.resolution
        fy = (pts[:, 1] - g.origin_y) / g.resolution
        inside = (fx >= 0) & (fy >= 0) & (fx < g.size_x) & (fy < g.size_y)
        mx = fx[inside].astype(np.int64)
        my = fy[inside].astype(np.int64)
        window = master.costs[y0:yn, x0:xn].reshape(-1)
        cost = g.costs[my, mx]
        if self.params.use_maximum:
            cost = np.maximum(cost, window[inside])
        window[inside] = cost
        master.costs[y0:yn, x0:xn] = window.reshape(yn - y0, xn - x0)
