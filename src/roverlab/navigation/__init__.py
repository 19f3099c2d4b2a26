"""Navigation: costmap_2d, global planners (navfn, global_planner) and local planners
(dwa_local_planner, teb_local_planner), as pure algorithms (nav2's layout).

* :mod:`.costmap`: layered costmaps; ``costmap/node.py`` has ``Costmap2DROS``;
* :mod:`.planners`: ``plan(start, goal, costmap) -> path`` (:class:`NavfnPlanner`,
  :class:`GlobalPlanner`);
* :mod:`.controllers`: ``compute_velocity(pose, twist, plan, costmap) -> twist``
  (:class:`DWAPlanner`, :class:`TebPlanner`).

Errors are typed (:mod:`.errors`, navigation2's names); only a node turns them into
result codes.
"""

from roverlab.navigation.errors import (
    ControllerError,
    CostmapError,
    GoalOccupiedError,
    GoalOutsideMapBoundsError,
    InvalidPathError,
    NavigationError,
    NavigationParamsError,
    NoValidControlError,
    NoValidPathCouldBeFoundError,
    PlannerError,
    StartOccupiedError,
    StartOutsideMapBoundsError,
)

__all__ = [
    "ControllerError",
    "CostmapError",
    "GoalOccupiedError",
    "GoalOutsideMapBoundsError",
    "InvalidPathError",
    "NavigationError",
    "NavigationParamsError",
    "NoValidControlError",
    "NoValidPathCouldBeFoundError",
    "PlannerError",
    "StartOccupiedError",
    "StartOutsideMapBoundsError",
]
