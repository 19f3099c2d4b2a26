"""dwa_local_planner: :class:`DWAPlanner` and :class:`DWAParams`."""

from roverlab.navigation.controllers.dwa.params import DWAParams
from roverlab.navigation.controllers.dwa.planner import DWAPlanner, velocity_iterator

__all__ = ["DWAParams", "DWAPlanner", "velocity_iterator"]
