"""Local planners behind ``compute_velocity(pose, twist, plan, costmap) -> twist``.

* :class:`DWAPlanner` (``dwa_local_planner/DWAPlannerROS``; TrajectoryPlannerROS names
  through :meth:`DWAParams.from_trajectory_planner_ros`);
* :class:`TebPlanner` (``teb_local_planner/TebLocalPlannerROS``);
* :class:`Velocity2D` and the :class:`ControllerProtocol` they share.
"""

from roverlab.navigation.controllers.base import ControllerProtocol, Velocity2D
from roverlab.navigation.controllers.dwa import DWAParams, DWAPlanner
from roverlab.navigation.controllers.teb import FootprintModel, TebParams, TebPlanner

__all__ = [
    "ControllerProtocol",
    "DWAParams",
    "DWAPlanner",
    "FootprintModel",
    "TebParams",
    "TebPlanner",
    "Velocity2D",
]
