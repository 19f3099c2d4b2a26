"""``LayeredCostmap``: plugins updated in order into one master grid (costmap_2d's).

Each update (:meth:`LayeredCostmap.update_map`) runs in two steps, as costmap_2d and
nav2_costmap_2d do:

1. every enabled layer grows a bounding box (:meth:`Layer.update_bounds`) with the area it
   changed since the last update (and may update its own grid);
2. the master cells in that window are reset, and every enabled layer writes its costs into
   the window (:meth:`Layer.update_costs`), in plugin order, with its combination rule.

The combination rules of :class:`CostmapLayer`: *true overwrite* (every cell), *overwrite*
(cells the layer knows), *max* (the larger cost; an unknown master cell takes the layer's),
*addition* (sum, kept below inscribed).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.navigation.costmap.costmap_2d import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.costmap.kernels import combine_max

__all__ = ["Bounds", "CostmapLayer", "Layer", "LayeredCostmap"]


@dataclass(slots=True)
class Bounds:
    """A world-frame box that layers grow (``min_x, min_y, max_x, max_y``, m)."""

    min_x: float = 1e30
    min_y: float = 1e30
    max_x: float = -1e30
    max_y: float = -1e30

    def touch(self, x: float, y: float) -> None:
        """Grow to contain ``(x, y)``."""
        self.min_x = min(self.min_x, x)
        self.min_y = min(self.min_y, y)
        self.max_x = max(self.max_x, x)
        self.max_y = max(self.max_y, y)

    def empty(self) -> bool:
        return self.min_x > self.max_x or self.min_y > self.max_y


class Layer:
    """A costmap plugin (costmap_2d's ``Layer``).

    Attributes:
        name: the plugin name (its parameter namespace).
        enabled: disabled layers are skipped by both update steps.
        layered: the :class:`LayeredCostmap` it belongs to (set by ``add_plugin``).
    """

    def __init__(self, name: str, *, enabled: bool = True) -> None:
        self.name = name
        self.enabled = enabled
        self._layered: LayeredCostmap | None = None

    @property
    def layered(self) -> LayeredCostmap:
        if self._layered is None:
            raise RuntimeError(f"layer {self.name} is not part of a LayeredCostmap")
        return self._layered

    def attach(self, layered: LayeredCostmap) -> None:
        """Called once by :meth:`LayeredCostmap.add_plugin`."""
        self._layered = layered
        self.on_initialize()

    def on_initialize(self) -> None:
        """Set up after joining the layered costmap."""

    def update_bounds(
        self, robot_x: float, robot_y: float, robot_yaw: float, bounds: Bounds, now_s: float
    ) -> None:
        """Step 1: grow ``bounds`` with the area this layer changed."""
        raise NotImplementedError

    def update_costs(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        """Step 2: write costs into ``master`` cells ``[x0, xn) x [y0, yn)``."""
        raise NotImplementedError

    def match_size(self) -> None:
        """The master grid was resized."""

    def on_footprint_changed(self) -> None:
        """The robot footprint changed."""

    def reset(self) -> None:
        """Forget what the layer holds (clear_costmaps)."""

    def is_current(self, now_s: float) -> bool:
        """Whether the layer's inputs are up to date."""
        return True


class CostmapLayer(Layer):
    """A layer with its own grid of the master's geometry and the combination rules."""

    def __init__(self, name: str, *, enabled: bool = True) -> None:
        super().__init__(name, enabled=enabled)
        self.grid = Costmap2D(size_x=1, size_y=1, resolution=1.0)
        self._extra: Bounds | None = None

    def match_size(self) -> None:
        m = self.layered.costmap
        self.grid.resize_map(m.size_x, m.size_y, m.resolution, m.origin_x, m.origin_y)

    def add_extra_bounds(self, min_x: float, min_y: float, max_x: float, max_y: float) -> None:
        """Ask for a window to be updated at the next cycle (costmap_2d's extra bounds)."""
        if self._extra is None:
            self._extra = Bounds()
        self._extra.touch(min_x, min_y)
        self._extra.touch(max_x, max_y)

    def use_extra_bounds(self, bounds: Bounds) -> None:
        if self._extra is not None:
            bounds.touch(self._extra.min_x, self._extra.min_y)
            bounds.touch(self._extra.max_x, self._extra.max_y)
            self._extra = None

    def _windows(
        self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int
    ) -> tuple[NDArray[np.uint8], NDArray[np.uint8]]:
        return master.costs[y0:yn, x0:xn], self.grid.costs[y0:yn, x0:xn]

    def update_with_true_overwrite(
        self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int
    ) -> None:
        """Every master cell of the window takes the layer's cost."""
        m, own = self._windows(master, x0, y0, xn, yn)
        m[:] = own

    def update_with_overwrite(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        """Master cells take the layer's cost where the layer knows it."""
        m, own = self._windows(master, x0, y0, xn, yn)
        known = own != NO_INFORMATION
        m[known] = own[known]

    def update_with_max(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        """Master cells take the larger cost; an unknown master cell takes the layer's."""
        combine_max(master.costs, self.grid.costs, x0, y0, xn, yn)

    def update_with_addition(self, master: Costmap2D, x0: int, y0: int, xn: int, yn: int) -> None:
        """Sum of the costs, kept below inscribed; an unknown master cell takes the layer's."""
        m, own = self._windows(master, x0, y0, xn, yn)
        known = own != NO_INFORMATION
        unknown_master = known & (m == NO_INFORMATION)
        both = known & ~unknown_master
        total = m.astype(np.int32) + own.astype(np.int32)
        total = np.where(
            total >= INSCRIBED_INFLATED_OBSTACLE, INSCRIBED_INFLATED_OBSTACLE - 1, total
        )
        m[unknown_master] = own[unknown_master]
        m[both] = total[both].astype(np.uint8)

    def reset(self) -> None:
        self.grid.reset_maps()

    def clear_area(self, start_x: int, start_y: int, end_x: int, end_y: int, invert: bool) -> None:
        """costmap_2d's ``CostmapLayer::clearArea``: reset the cells outside the cell box
        ``(start_x, end_x) x (start_y, end_y)`` (bounds excluded) when ``invert`` is False,
        or inside it when ``invert`` is True (as ROS: a cell is kept when its being inside
        differs from ``invert``), then ask for the whole layer to be redrawn at the next
        update. move_base's clear_costmap recovery (``invert_area_to_clear`` False by
        default) so clears everything farther than ``reset_distance / 2`` from the robot."""
        g = self.grid
        xs = np.arange(g.size_x)
        ys = np.arange(g.size_y)
        inside = ((ys > start_y) & (ys < end_y))[:, None] & ((xs > start_x) & (xs < end_x))[None, :]
        g.costs[inside == invert] = g.default_value
        self.add_extra_bounds(
            g.origin_x,
            g.origin_y,
            g.origin_x + g.size_in_meters_x,
            g.origin_y + g.size_in_meters_y,
        )


class LayeredCostmap:
    """The master costmap and its plugins (costmap_2d's ``LayeredCostmap``).

    Args:
        global_frame: the frame of the master grid.
        rolling_window: the grid follows the robot.
        track_unknown_space: reset cells are unknown (255) instead of free (0).
    """

    def __init__(
        self, *, global_frame: str, rolling_window: bool, track_unknown_space: bool
    ) -> None:
        self.global_frame = global_frame
        self.rolling_window = bool(rolling_window)
        self.track_unknown_space = bool(track_unknown_space)
        self.costmap = Costmap2D(
            size_x=1,
            size_y=1,
            resolution=1.0,
            default_value=NO_INFORMATION if track_unknown_space else FREE_SPACE,
        )
        self.plugins: list[Layer] = []
        self.size_locked = False
        self.initialized = False
        self.footprint: NDArray[np.float64] = np.zeros((0, 2))
        self.inscribed_radius = 0.0
        self.circumscribed_radius = 0.0
        self.bounds_cells = (0, 0, 0, 0)  # x0, xn, y0, yn of the last update
        self.last_bounds = Bounds()

    def add_plugin(self, layer: Layer) -> None:
        """Append a plugin (updated after the ones before it)."""
        self.plugins.append(layer)
        layer.attach(self)
        layer.match_size()

    def resize_map(
        self,
        size_x: int,
        size_y: int,
        resolution: float,
        origin_x: float,
        origin_y: float,
        *,
        size_locked: bool = False,
    ) -> None:
        """Resize the master grid and every plugin (costmap_2d's ``resizeMap``)."""
        self.size_locked = size_locked
        self.costmap.resize_map(size_x, size_y, resolution, origin_x, origin_y)
        for layer in self.plugins:
            layer.match_size()

    def set_footprint(self, footprint: ArrayLike) -> None:
        """Set the (padded) footprint; layers are told (the inflation layer re-inflates)."""
        self.footprint = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        self.inscribed_radius, self.circumscribed_radius = footprint_radii(self.footprint)
        for layer in self.plugins:
            layer.on_footprint_changed()

    def update_map(
        self, robot_x: float, robot_y: float, robot_yaw: float, now_s: float = 0.0
    ) -> None:
        """One update cycle at the robot pose (global frame), ``now_s`` the clock time."""
        if self.rolling_window:
            cm = self.costmap
            cm.update_origin(
                robot_x - cm.size_in_meters_x / 2.0, robot_y - cm.size_in_meters_y / 2.0
            )
        if not self.plugins:
            return
        b = Bounds()
        for layer in self.plugins:
            if layer.enabled:
                layer.update_bounds(robot_x, robot_y, robot_yaw, b, now_s)
        self.last_bounds = b
        cm = self.costmap
        x0, y0 = cm.world_to_map_enforce_bounds(b.min_x, b.min_y)
        xn, yn = cm.world_to_map_enforce_bounds(b.max_x, b.max_y)
        x0 = max(0, x0)
        xn = min(cm.size_x, xn + 1)
        y0 = max(0, y0)
        yn = min(cm.size_y, yn + 1)
        if b.empty() or xn < x0 or yn < y0:
            self.bounds_cells = (0, 0, 0, 0)
            self.initialized = True
            return
        cm.reset_map(x0, y0, xn, yn)
        for layer in self.plugins:
            if layer.enabled:
                layer.update_costs(cm, x0, y0, xn, yn)
        self.bounds_cells = (x0, xn, y0, yn)
        self.initialized = True

    def is_current(self, now_s: float) -> bool:
        """Whether every enabled layer's inputs are up to date."""
        return all(layer.is_current(now_s) for layer in self.plugins if layer.enabled)

    def reset(self) -> None:
        """Clear the master grid and every layer (the clear_costmaps service)."""
        self.costmap.reset_maps()
        for layer in self.plugins:
            layer.reset()

    def plugin(self, name: str) -> Layer:
        """The plugin called ``name``."""
        for layer in self.plugins:
            if layer.name == name:
                return layer
        raise KeyError(name)
