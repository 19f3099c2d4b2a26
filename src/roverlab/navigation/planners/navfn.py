"""navfn (``navfn/NavfnROS``): a navigation function by potential propagation.

What NavfnROS does per ``makePlan``, with its parameters:

* the robot's cell is cleared; costmap costs become navfn costs ``50 + 0.8 * cost``
  (253, 254 and, unless ``allow_unknown``, 255 are obstacles; unknown is 253 when allowed);
  the outer cells of the grid are obstacles;
* the potential spreads from the **robot** (navfn plans backwards: ``setStart(goal)``,
  ``setGoal(start)``) by the planar-wave update with the quadratic interpolation, through
  navfn's priority buffers, until it reaches the goal (Dijkstra; with
  ``use_dijkstra: false``, navfn's A* priorities, as nav2's navfn ``use_astar``);
* the goal is the point nearest to the requested goal, within ``default_tolerance`` (a
  grid of ``resolution`` steps), that the potential reached;
* the path follows the interpolated gradient of the potential down from that goal in
  half-cell steps (``calcPath``), reversed; the goal pose is appended. (NavfnROS allows
  ``4 * nx`` steps, which fails long winding paths; roverlab allows ``nx * ny / 2``.)

``planner_window_x/y`` (> 0) make the planner work on that window of the costmap centred
on the robot. ``visualize_potential`` keeps the potential in :attr:`NavfnPlanner.potential`
for the node to publish. Path points are cell centres (NavfnROS leaves them half a cell
towards the origin).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import FREE_SPACE, Costmap2D
from roverlab.navigation.errors import (
    GoalOutsideMapBoundsError,
    NoValidPathCouldBeFoundError,
    StartOutsideMapBoundsError,
)
from roverlab.navigation.params import build_params, check
from roverlab.navigation.planners.base import Path2D, diagnose_failure, tolerance_candidates
from roverlab.navigation.planners.navfn_kernels import POT_HIGH, calc_path, propagate

__all__ = ["NavfnParams", "NavfnPlanner", "navfn_costs"]


@dataclass(frozen=True, slots=True, kw_only=True)
class NavfnParams:
    """NavfnROS's parameters (ROS names and defaults); ``use_dijkstra`` picks A* when
    false."""

    allow_unknown: bool = True
    default_tolerance: float = 0.0
    visualize_potential: bool = False
    planner_window_x: float = 0.0
    planner_window_y: float = 0.0
    use_dijkstra: bool = True

    def __post_init__(self) -> None:
        check(self.default_tolerance >= 0, "navfn: default_tolerance must be >= 0")
        check(self.planner_window_x >= 0, "navfn: planner_window_x must be >= 0")
        check(self.planner_window_y >= 0, "navfn: planner_window_y must be >= 0")

    @classmethod
    def from_ros(cls, values: Mapping[str, Any]) -> tuple[NavfnParams, tuple[str, ...]]:
        """From ``NavfnROS/...`` parameters (ROS names).

        Raises:
            NavigationParamsError: an unknown name or a bad value.
        """
        p, res = build_params(cls, values, where="navfn")
        return p, res.warnings


def navfn_costs(costs: NDArray[np.uint8], allow_unknown: bool) -> NDArray[np.uint8]:
    """navfn's ``setCostmap`` for a ROS costmap: ``int(50 + 0.8 * c)`` below 253 (at most
    253), 253 for unknown when allowed, 254 (obstacle) otherwise."""
    c = costs.astype(np.int32)
    out = np.full(c.shape, 254, dtype=np.uint8)
    low = c < 253
    out[low] = np.minimum((50 + 0.8 * c[low]).astype(np.int32), 253).astype(np.uint8)
    if allow_unknown:
        out[c == 255] = 253
    return out


class NavfnPlanner:
    """NavfnROS as a pure planner.

    Args:
        params: its parameters.

    Attributes:
        potential: the last potential, ``(ny, nx)`` float32 (``POT_HIGH`` unreached), with
            the origin of its window (``potential_origin``).
        cycles: buffer cycles the last propagation used.
    """

    name = "navfn/NavfnROS"

    def __init__(self, params: NavfnParams | None = None) -> None:
        self.params = params or NavfnParams()
        self.potential: NDArray[np.float32] | None = None
        self.potential_origin = (0.0, 0.0)
        self.cycles = 0

    def _window(self, start: SE2, costmap: Costmap2D) -> Costmap2D:
        p = self.params
        if p.planner_window_x <= 0 and p.planner_window_y <= 0:
            return costmap
        res = costmap.resolution
        wx = p.planner_window_x if p.planner_window_x > 0 else costmap.size_x * res
        wy = p.planner_window_y if p.planner_window_y > 0 else costmap.size_y * res
        cx, cy = costmap.world_to_map_no_bounds(start.x - wx / 2, start.y - wy / 2)
        x0, y0 = max(0, cx), max(0, cy)
        x1 = min(costmap.size_x, cx + max(1, round(wx / res)))
        y1 = min(costmap.size_y, cy + max(1, round(wy / res)))
        win = Costmap2D(
            size_x=max(1, x1 - x0),
            size_y=max(1, y1 - y0),
            resolution=res,
            origin_x=costmap.origin_x + x0 * res,
            origin_y=costmap.origin_y + y0 * res,
        )
        win.costs[:] = costmap.costs[y0:y1, x0:x1]
        return win

    def plan(self, start: SE2, goal: SE2, costmap: Costmap2D) -> Path2D:
        """A path from ``start`` to ``goal`` (see the module docstring).

        Raises:
            StartOutsideMapBoundsError, GoalOutsideMapBoundsError: off the costmap (window).
            StartOccupiedError, GoalOccupiedError, NoValidPathCouldBeFoundError: no path.
        """
        p = self.params
        cm = self._window(start, costmap)
        sc = cm.world_to_map(start.x, start.y)
        if sc is None:
            raise StartOutsideMapBoundsError(
                "navfn: the robot's start position is off the global costmap. Planning will "
                "always fail, are you sure the robot has been properly localized?"
            )
        gc = cm.world_to_map(goal.x, goal.y)
        if gc is None:
            raise GoalOutsideMapBoundsError(
                "navfn: the goal sent to the navfn planner is off the global costmap. "
                "Planning will always fail to this goal."
            )
        nx, ny = cm.size_x, cm.size_y
        grid = cm.costs.copy()
        grid[sc[1], sc[0]] = FREE_SPACE  # clearRobotCell
        cost = navfn_costs(grid, p.allow_unknown).reshape(-1)
        pot = np.empty(nx * ny, dtype=np.float32)
        robot = sc[1] * nx + sc[0]
        target = gc[1] * nx + gc[0]
        self.cycles = int(
            propagate(
                cost, nx, ny, robot, target, max(nx * ny // 20, nx + ny), True,
                not p.use_dijkstra, pot,
            )
        )  # fmt: skip
        self.potential = pot.reshape(ny, nx)
        self.potential_origin = (cm.origin_x, cm.origin_y)
        best: tuple[float, float] | None = None
        best_d = math.inf
        for x, y in tolerance_candidates(goal, p.default_tolerance, cm.resolution):
            c = cm.world_to_map(float(x), float(y))
            if c is None or pot[c[1] * nx + c[0]] >= POT_HIGH:
                continue
            d = (x - goal.x) ** 2 + (y - goal.y) ** 2
            if d < best_d:
                best_d, best = d, (float(x), float(y))
        if best is None:
            raise diagnose_failure(cm, sc, gc, p.allow_unknown, "navfn")
        bc = cm.world_to_map(*best)
        assert bc is not None
        steps = max(nx * 4, nx * ny // 2)
        out = np.empty((steps + 2, 2), dtype=np.float64)
        n = calc_path(
            pot, nx, float(bc[0]), float(bc[1]), float(sc[0]), float(sc[1]), steps, True,
            254.0, out,
        )  # fmt: skip
        if n == 0:
            raise NoValidPathCouldBeFoundError(
                "navfn: failed to get a plan from potential when a legal potential was found"
            )
        cells = out[:n][::-1]
        xy = np.column_stack(
            [
                cm.origin_x + (cells[:, 0] + 0.5) * cm.resolution,
                cm.origin_y + (cells[:, 1] + 0.5) * cm.resolution,
            ]
        )
        path = np.zeros((n + 1, 3))
        path[:n, :2] = xy
        path[n] = (best[0], best[1], goal.theta)
        return path
