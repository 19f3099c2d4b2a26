"""The global planner interface (nav2_core's ``GlobalPlanner``, ROS 1's
``nav_core::BaseGlobalPlanner``) and what the planners share.

``plan(start, goal, costmap) -> path``: ``start`` and ``goal`` are :class:`SE2` poses in the
costmap's global frame, ``path`` an ``(N, 3)`` float64 array of ``x, y, yaw`` rows from the
start to the goal (the goal pose last). Failures raise the typed errors of
:mod:`roverlab.navigation.errors`.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import (
    INSCRIBED_INFLATED_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from roverlab.navigation.errors import (
    GoalOccupiedError,
    NoValidPathCouldBeFoundError,
    PlannerError,
    StartOccupiedError,
)

__all__ = ["Path2D", "PlannerProtocol", "diagnose_failure", "tolerance_candidates"]

#: ``(N, 3)`` float64 ``x, y, yaw`` rows.
Path2D = NDArray[np.float64]


class PlannerProtocol(Protocol):
    """What move_base needs of a global planner."""

    def plan(self, start: SE2, goal: SE2, costmap: Costmap2D) -> Path2D:
        """A path from ``start`` to ``goal`` in ``costmap``'s frame."""
        ...


def diagnose_failure(
    costmap: Costmap2D,
    start_cell: tuple[int, int],
    goal_cell: tuple[int, int],
    allow_unknown: bool,
    what: str,
) -> PlannerError:
    """The typed error for a search that found no path: the start or the goal in an
    obstacle (inscribed or lethal, or unknown when it is not allowed), else no path."""

    def blocked(c: tuple[int, int]) -> bool:
        v = costmap.get_cost(*c)
        if v == NO_INFORMATION:
            return not allow_unknown
        return v >= INSCRIBED_INFLATED_OBSTACLE

    if blocked(start_cell):
        return StartOccupiedError(
            f"{what}: the robot's start cell {start_cell} is in an obstacle "
            f"(cost {costmap.get_cost(*start_cell)}); no path out"
        )
    if blocked(goal_cell):
        return GoalOccupiedError(
            f"{what}: the goal cell {goal_cell} is in an obstacle "
            f"(cost {costmap.get_cost(*goal_cell)}) and no free cell is within the tolerance"
        )
    return NoValidPathCouldBeFoundError(f"{what}: failed to get a plan (no path to the goal)")


def tolerance_candidates(goal: SE2, tolerance: float, resolution: float) -> NDArray[np.float64]:
    """NavfnROS's search grid around a goal: ``(x, y)`` points from ``goal - tolerance`` to
    ``goal + tolerance`` in steps of ``resolution`` (only the goal when tolerance is 0)."""
    steps = np.arange(-tolerance, tolerance + 1e-12, resolution) if tolerance > 0 else [0.0]
    off = np.asarray(steps, dtype=np.float64)
    xs, ys = np.meshgrid(goal.x + off, goal.y + off)
    return np.column_stack([xs.ravel(), ys.ravel()])
