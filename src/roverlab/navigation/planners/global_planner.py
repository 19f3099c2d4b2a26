"""global_planner (``global_planner/GlobalPlanner``): navfn's successor, configurable.

What GlobalPlanner does per ``makePlan``, with its parameters:

* start and goal in map coordinates whose integers are cell centres; the robot's cell is
  cleared; with ``outline_map`` the outer cells are lethal;
* the potential spreads from the **start**: Dijkstra (``use_dijkstra``, navfn's priority
  buffers, the start spread over its 2 x 2 block) or A* (a heap with the Manhattan
  heuristic), by ``min(neighbour) + cost`` or navfn's quadratic interpolation
  (``use_quadratic``), cell cost ``cost * cost_factor + neutral_cost`` below ``lethal_cost``;
* cells around the goal left unreached get a potential (``clearEndpoint``);
* the path runs from the goal down the potential: its interpolated gradient in half-cell
  steps, or the lowest of 8 neighbours (``use_grid_path``); reversed; the goal appended;
* yaws by ``orientation_mode`` / ``orientation_window_size``.

``default_tolerance`` (which ROS 1's GlobalPlanner reads but does not use) works as in
navfn: when the goal cannot be reached, the nearest reached point within the tolerance is
the goal. ``publish_potential`` keeps the potential in :attr:`GlobalPlanner.potential`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import FREE_SPACE, LETHAL_OBSTACLE, Costmap2D
from roverlab.navigation.errors import (
    GoalOutsideMapBoundsError,
    NoValidPathCouldBeFoundError,
    StartOutsideMapBoundsError,
)
from roverlab.navigation.params import build_params, check
from roverlab.navigation.planners.base import Path2D, diagnose_failure, tolerance_candidates
from roverlab.navigation.planners.gp_kernels import astar, clear_endpoint, dijkstra, grid_path
from roverlab.navigation.planners.navfn_kernels import POT_HIGH, calc_path
from roverlab.navigation.planners.orientation import orient_path

__all__ = ["GlobalPlanner", "GlobalPlannerParams"]


@dataclass(frozen=True, slots=True, kw_only=True)
class GlobalPlannerParams:
    """GlobalPlanner's parameters (ROS names and defaults)."""

    allow_unknown: bool = True
    default_tolerance: float = 0.0
    visualize_potential: bool = False
    use_dijkstra: bool = True
    use_quadratic: bool = True
    use_grid_path: bool = False
    old_navfn_behavior: bool = False
    lethal_cost: int = 253
    neutral_cost: int = 50
    cost_factor: float = 3.0
    publish_potential: bool = True
    publish_scale: int = 100
    orientation_mode: int = 0
    orientation_window_size: int = 1
    outline_map: bool = True

    def __post_init__(self) -> None:
        w = "global_planner"
        check(self.default_tolerance >= 0, f"{w}: default_tolerance must be >= 0")
        check(1 <= self.lethal_cost <= 255, f"{w}: lethal_cost must be in 1..255")
        check(0 <= self.neutral_cost <= 255, f"{w}: neutral_cost must be in 0..255")
        check(self.cost_factor >= 0, f"{w}: cost_factor must be >= 0")
        check(
            0 <= self.orientation_mode <= 6,
            f"{w}: orientation_mode must be 0..6, got {self.orientation_mode}",
        )
        check(self.orientation_window_size >= 1, f"{w}: orientation_window_size must be >= 1")
        check(1 <= self.publish_scale <= 100, f"{w}: publish_scale must be in 1..100")

    @classmethod
    def from_ros(cls, values: Mapping[str, Any]) -> tuple[GlobalPlannerParams, tuple[str, ...]]:
        """From ``GlobalPlanner/...`` parameters (ROS names).

        Raises:
            NavigationParamsError: an unknown name or a bad value.
        """
        # GlobalPlanner reads planner_window_x/y and never uses them
        ignored = ("planner_window_x", "planner_window_y")
        p, res = build_params(cls, values, where="global_planner", ignored=ignored)
        warnings = list(res.warnings)
        if p.visualize_potential:
            warnings.append(
                "global_planner: visualize_potential has no effect: the potential is the "
                "~GlobalPlanner/potential grid (publish_potential)"
            )
        return p, tuple(warnings)


class GlobalPlanner:
    """GlobalPlanner as a pure planner.

    Args:
        params: its parameters.

    Attributes:
        potential: the last potential, ``(ny, nx)`` float32 (``POT_HIGH`` unreached).
    """

    name = "global_planner/GlobalPlanner"

    def __init__(self, params: GlobalPlannerParams | None = None) -> None:
        self.params = params or GlobalPlannerParams()
        self.potential: NDArray[np.float32] | None = None
        self.potential_origin = (0.0, 0.0)

    def _to_map(self, cm: Costmap2D, wx: float, wy: float) -> tuple[float, float] | None:
        off = 0.0 if self.params.old_navfn_behavior else 0.5
        if wx < cm.origin_x or wy < cm.origin_y:
            return None
        mx = (wx - cm.origin_x) / cm.resolution - off
        my = (wy - cm.origin_y) / cm.resolution - off
        if mx < cm.size_x and my < cm.size_y:
            return mx, my
        return None

    def _expand(
        self, cost: NDArray[np.uint8], nx: int, s: tuple[float, float], g: tuple[float, float],
        stop: bool, pot: NDArray[np.float32],
    ) -> bool:  # fmt: skip
        p = self.params
        args = (p.lethal_cost, float(p.neutral_cost), p.cost_factor, p.allow_unknown)
        sx, sy = max(s[0], 0.0), max(s[1], 0.0)
        gx, gy = max(g[0], 0.0), max(g[1], 0.0)
        cycles = 2 * cost.size
        if p.use_dijkstra:
            return bool(
                dijkstra(
                    cost, nx, sx, sy, gx, gy, cycles, *args, p.use_quadratic,
                    not p.old_navfn_behavior, stop, pot,
                )
            )  # fmt: skip
        return bool(astar(cost, nx, sx, sy, gx, gy, cycles, *args, p.use_quadratic, stop, pot))

    def plan(self, start: SE2, goal: SE2, costmap: Costmap2D) -> Path2D:
        """A path from ``start`` to ``goal`` (see the module docstring).

        Raises:
            StartOutsideMapBoundsError, GoalOutsideMapBoundsError: off the costmap.
            StartOccupiedError, GoalOccupiedError, NoValidPathCouldBeFoundError: no path.
        """
        p = self.params
        cm = costmap
        sci = cm.world_to_map(start.x, start.y)
        if sci is None or self._to_map(cm, start.x, start.y) is None:
            raise StartOutsideMapBoundsError(
                "global_planner: the robot's start position is off the global costmap. "
                "Planning will always fail, are you sure the robot has been properly localized?"
            )
        gci = cm.world_to_map(goal.x, goal.y)
        if gci is None or self._to_map(cm, goal.x, goal.y) is None:
            raise GoalOutsideMapBoundsError(
                "global_planner: the goal sent to the global planner is off the global "
                "costmap. Planning will always fail to this goal."
            )
        if p.old_navfn_behavior:
            s = (float(sci[0]), float(sci[1]))
            g = (float(gci[0]), float(gci[1]))
        else:
            s = self._to_map(cm, start.x, start.y) or (0.0, 0.0)
            g = self._to_map(cm, goal.x, goal.y) or (0.0, 0.0)
        nx, ny = cm.size_x, cm.size_y
        grid = cm.costs.copy()
        grid[sci[1], sci[0]] = FREE_SPACE  # clearRobotCell
        if p.outline_map:
            grid[0, :] = grid[-1, :] = LETHAL_OBSTACLE
            grid[:, 0] = grid[:, -1] = LETHAL_OBSTACLE
        cost = grid.reshape(-1)
        pot = np.empty(nx * ny, dtype=np.float32)
        found = self._expand(cost, nx, s, g, True, pot)
        target = g
        if not found and p.default_tolerance > 0:
            self._expand(cost, nx, s, g, False, pot)
            best, best_d = None, math.inf
            for x, y in tolerance_candidates(goal, p.default_tolerance, cm.resolution):
                c = self._to_map(cm, float(x), float(y))
                if c is None or c[0] < 0 or c[1] < 0:
                    continue
                if pot[int(c[1]) * nx + int(c[0])] >= POT_HIGH:
                    continue
                d = (x - goal.x) ** 2 + (y - goal.y) ** 2
                if d < best_d:
                    best_d, best = d, c
            if best is not None:
                found, target = True, best
        self.potential = pot.reshape(ny, nx)
        self.potential_origin = (cm.origin_x, cm.origin_y)
        if not found:
            raise diagnose_failure(cm, sci, gci, p.allow_unknown, "global_planner")
        tx, ty = max(target[0], 0.0), max(target[1], 0.0)
        if not p.old_navfn_behavior:
            clear_endpoint(
                cost, pot, nx, int(tx), int(ty), 2, float(p.neutral_cost), p.use_quadratic
            )
        out = np.empty((nx * ny + 2, 2))
        if p.use_grid_path:
            n = grid_path(pot, nx, s[0], s[1], tx, ty, out)
        else:
            n = calc_path(
                pot, nx, tx, ty, max(s[0], 0.0), max(s[1], 0.0), nx * ny * 4, False,
                float(p.lethal_cost), out,
            )  # fmt: skip
        if n == 0:
            raise NoValidPathCouldBeFoundError(
                "global_planner: failed to get a plan from potential when a legal potential "
                "was found"
            )
        off = 0.0 if p.old_navfn_behavior else 0.5
        cells = out[:n][::-1]
        path = np.zeros((n + 1, 3))
        path[:n, 0] = cm.origin_x + (cells[:, 0] + off) * cm.resolution
        path[:n, 1] = cm.origin_y + (cells[:, 1] + off) * cm.resolution
        if target is g:
            path[n] = (goal.x, goal.y, goal.theta)
        else:
            path[n] = (
                cm.origin_x + (target[0] + off) * cm.resolution,
                cm.origin_y + (target[1] + off) * cm.resolution,
                goal.theta,
            )
        return orient_path(path, start.theta, p.orientation_mode, p.orientation_window_size)
