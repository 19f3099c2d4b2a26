"""Errors of the navigation stack, typed as navigation2's (``nav2_core`` exceptions).

Algorithms raise these; only a node or an action server turns them into a result code or
a log line. Every message is one line naming the problem.
"""

from __future__ import annotations

from roverlab.errors import RoverlabError


class NavigationError(RoverlabError):
    """Base class of every navigation error."""


class NavigationParamsError(NavigationError, ValueError):
    """A parameter of the wrong type, out of range or unknown (the message names it)."""


class CostmapError(NavigationError):
    """A costmap input that cannot be used (bad map, bad observation)."""


class PlannerError(NavigationError):
    """A global planner could not produce a plan."""


class StartOutsideMapBoundsError(PlannerError):
    """The robot's start position is off the costmap."""


class GoalOutsideMapBoundsError(PlannerError):
    """The goal is off the costmap."""


class StartOccupiedError(PlannerError):
    """No plan: the start cell is an obstacle."""


class GoalOccupiedError(PlannerError):
    """No plan: the goal lies in an obstacle (and no free cell within the tolerance)."""


class NoValidPathCouldBeFoundError(PlannerError):
    """Start and goal are free but not connected (or the search ran out of cycles)."""


class ControllerError(NavigationError):
    """A local planner could not produce a velocity command."""


class InvalidPathError(ControllerError):
    """The plan given to a controller is empty or has no point in the local costmap."""


class NoValidControlError(ControllerError):
    """Every candidate command collides or leaves the map (the robot must stop)."""
