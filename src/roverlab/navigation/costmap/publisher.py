"""Costmaps as messages, as costmap_2d's ``Costmap2DPublisher`` sends them.

Costs become ``OccupancyGrid`` values by costmap_2d's translation table: 0 -> 0,
253 (inscribed) -> 99, 254 (lethal) -> 100, 255 (unknown) -> -1 and 1..252 ->
``1 + 97 * (cost - 1) // 251`` (1..98). The first message, and every message after the
grid's size, resolution or origin changed (a rolling window moving), is the whole
``OccupancyGrid`` on ``NAME/costmap``; otherwise the window updated since the last
publication goes out as a ``map_msgs/OccupancyGridUpdate`` on ``NAME/costmap_updates``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.msgs import Point32, Polygon, PolygonStamped, array_to_occupancy_grid, make
from roverlab.msgs.convert import Stamp, stamp_to_msg
from roverlab.navigation.costmap.costmap_2d import Costmap2D

__all__ = [
    "COST_TRANSLATION_TABLE",
    "CostmapPublisherState",
    "costmap_to_occupancy_grid",
    "costmap_update_message",
    "footprint_message",
]


def _table() -> NDArray[np.int8]:
    t = np.zeros(256, dtype=np.int8)
    i = np.arange(1, 253)
    t[1:253] = 1 + (97 * (i - 1)) // 251
    t[253] = 99
    t[254] = 100
    t[255] = -1
    return t


#: costmap_2d's ``cost_translation_table_``: uint8 cost -> OccupancyGrid value.
COST_TRANSLATION_TABLE: NDArray[np.int8] = _table()


def costmap_to_occupancy_grid(costmap: Costmap2D, frame_id: str, stamp: Stamp = None) -> Any:
    """The whole costmap as a ``nav_msgs/OccupancyGrid`` (values translated)."""
    return array_to_occupancy_grid(
        COST_TRANSLATION_TABLE[costmap.costs],
        resolution=costmap.resolution,
        origin=(costmap.origin_x, costmap.origin_y, 0.0),
        frame_id=frame_id,
        stamp=stamp,
    )


def costmap_update_message(
    costmap: Costmap2D, x0: int, xn: int, y0: int, yn: int, frame_id: str, stamp: Stamp = None
) -> Any:
    """Cells ``[x0, xn) x [y0, yn)`` as a ``map_msgs/OccupancyGridUpdate``."""
    window = COST_TRANSLATION_TABLE[costmap.costs[y0:yn, x0:xn]]
    return make(
        "map_msgs/msg/OccupancyGridUpdate",
        header={"stamp": stamp_to_msg(stamp), "frame_id": frame_id},
        x=int(x0),
        y=int(y0),
        width=int(xn - x0),
        height=int(yn - y0),
        data=np.ascontiguousarray(window).reshape(-1),
    )


def footprint_message(polygon: ArrayLike, frame_id: str, stamp: Stamp = None) -> Any:
    """A footprint polygon ((N, 2) m, global frame) as a ``geometry_msgs/PolygonStamped``."""
    pts = np.asarray(polygon, dtype=np.float64).reshape(-1, 2)
    return PolygonStamped(
        header={"stamp": stamp_to_msg(stamp), "frame_id": frame_id},
        polygon=Polygon(points=[Point32(x=float(x), y=float(y), z=0.0) for x, y in pts]),
    )


class CostmapPublisherState:
    """Which message to send next: costmap_2d's full-map vs update decision.

    Args:
        always_send_full_costmap: never send updates.
    """

    def __init__(self, *, always_send_full_costmap: bool = False) -> None:
        self.always_full = always_send_full_costmap
        self._saved: tuple[int, int, float, float, float] | None = None
        self._bounds = [0, 0, 0, 0]  # x0, xn, y0, yn
        self._empty = True

    def update_bounds(self, x0: int, xn: int, y0: int, yn: int) -> None:
        """Grow the window to send with one update cycle's window."""
        if xn <= x0 or yn <= y0:
            return
        if self._empty:
            self._bounds = [x0, xn, y0, yn]
            self._empty = False
        else:
            b = self._bounds
            self._bounds = [min(b[0], x0), max(b[1], xn), min(b[2], y0), max(b[3], yn)]

    def next_message(
        self, costmap: Costmap2D, frame_id: str, stamp: Stamp = None
    ) -> tuple[str, Any]:
        """``("full", OccupancyGrid)``, ``("update", OccupancyGridUpdate)`` or
        ``("none", None)``; the window is reset."""
        geometry = (
            costmap.size_x,
            costmap.size_y,
            costmap.resolution,
            costmap.origin_x,
            costmap.origin_y,
        )
        out: tuple[str, Any]
        if self.always_full or geometry != self._saved:
            self._saved = geometry
            out = ("full", costmap_to_occupancy_grid(costmap, frame_id, stamp))
        elif not self._empty:
            x0, xn, y0, yn = self._bounds
            out = ("update", costmap_update_message(costmap, x0, xn, y0, yn, frame_id, stamp))
        else:
            out = ("none", None)
        self._empty = True
        return out

    def force_full(self) -> None:
        """Send the whole grid next time (a new subscriber)."""
        self._saved = None
