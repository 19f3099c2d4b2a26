"""Global planners behind ``plan(start, goal, costmap) -> path``.

* :class:`NavfnPlanner` (``navfn/NavfnROS``) and :class:`GlobalPlanner`
  (``global_planner/GlobalPlanner``), with their parameter sets;
* :func:`orient_path`: global_planner's orientation filter;
* :mod:`.ros`: ``nav_msgs/Path`` and potential messages.
"""

from roverlab.navigation.planners.base import Path2D, PlannerProtocol
from roverlab.navigation.planners.global_planner import GlobalPlanner, GlobalPlannerParams
from roverlab.navigation.planners.navfn import NavfnParams, NavfnPlanner, navfn_costs
from roverlab.navigation.planners.orientation import ORIENTATION_MODES, orient_path
from roverlab.navigation.planners.ros import (
    path_from_msg,
    path_to_msg,
    potential_to_grid,
    potential_to_pointcloud,
)

__all__ = [
    "ORIENTATION_MODES",
    "GlobalPlanner",
    "GlobalPlannerParams",
    "NavfnParams",
    "NavfnPlanner",
    "Path2D",
    "PlannerProtocol",
    "navfn_costs",
    "orient_path",
    "path_from_msg",
    "path_to_msg",
    "potential_to_grid",
    "potential_to_pointcloud",
]
