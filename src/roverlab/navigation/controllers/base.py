"""The local planner interface (nav2_core's ``Controller``, ROS 1's
``nav_core::BaseLocalPlanner``) and the plan handling the local planners share.

``compute_velocity(pose, twist, plan, costmap) -> twist``: ``pose`` is the robot's
:class:`SE2` in the local costmap's global frame, ``twist`` its velocity in its own frame
(odometry), ``plan`` an ``(N, 3)`` ``x, y, yaw`` global plan in that same frame (a new plan
resets the planner's latches, as ``setPlan``), ``costmap`` the local costmap. It returns the
command as a :class:`Velocity2D` or raises :class:`NoValidControlError` (the robot must
stop). ``is_goal_reached()`` tells whether the plan's goal is reached.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.errors import InvalidPathError

__all__ = [
    "ControllerProtocol",
    "Velocity2D",
    "as_plan",
    "local_plan_window",
    "prune_plan",
    "stopped",
]


@dataclass(frozen=True, slots=True)
class Velocity2D:
    """A planar velocity in the robot frame: ``vx``, ``vy`` (m/s), ``wz`` (rad/s)."""

    vx: float = 0.0
    vy: float = 0.0
    wz: float = 0.0

    def as_array(self) -> NDArray[np.float64]:
        return np.array([self.vx, self.vy, self.wz])


class ControllerProtocol(Protocol):
    """What move_base needs of a local planner."""

    def set_plan(self, plan: ArrayLike) -> None:
        """A new global plan (resets latches and oscillation memory)."""
        ...

    def compute_velocity(
        self, pose: SE2, twist: Velocity2D, plan: ArrayLike, costmap: Costmap2D
    ) -> Velocity2D:
        """The velocity command for this control cycle."""
        ...

    def is_goal_reached(self, pose: SE2 | None = None, twist: Velocity2D | None = None) -> bool:
        """Whether the goal is reached (at the last pose and velocity seen by default)."""
        ...


def as_plan(plan: ArrayLike, where: str) -> NDArray[np.float64]:
    """``plan`` as an ``(N, 3)`` float64 array.

    Raises:
        InvalidPathError: empty, badly shaped or non-finite.
    """
    p = np.asarray(plan, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] not in (2, 3) or len(p) == 0:
        raise InvalidPathError(f"{where}: the plan must be a non-empty (N, 3) x, y, yaw array")
    if p.shape[1] == 2:
        p = np.column_stack([p, np.zeros(len(p))])
    if not np.isfinite(p).all():
        raise InvalidPathError(f"{where}: the plan holds NaN or infinite values")
    return p


def stopped(twist: Velocity2D, rot_stopped_vel: float, trans_stopped_vel: float) -> bool:
    """base_local_planner's ``stopped``."""
    return (
        abs(twist.wz) <= rot_stopped_vel
        and abs(twist.vx) <= trans_stopped_vel
        and abs(twist.vy) <= trans_stopped_vel
    )


def prune_plan(pose: SE2, plan: NDArray[np.float64]) -> NDArray[np.float64]:
    """base_local_planner's ``prunePlan``: drop the points before the first one within 1 m
    of the robot (all of them if none is)."""
    d2 = (plan[:, 0] - pose.x) ** 2 + (plan[:, 1] - pose.y) ** 2
    near = np.nonzero(d2 < 1.0)[0]
    return plan[near[0] :] if len(near) else plan[:0]


def local_plan_window(
    pose: SE2, plan: NDArray[np.float64], costmap: Costmap2D
) -> NDArray[np.float64]:
    """base_local_planner's ``transformGlobalPlan`` (the plan is already in the costmap's
    frame): from the first point within half the costmap's size of the robot, the points
    until one is farther."""
    limit = max(costmap.size_x * costmap.resolution, costmap.size_y * costmap.resolution) / 2.0
    d2 = (plan[:, 0] - pose.x) ** 2 + (plan[:, 1] - pose.y) ** 2
    inside = d2 <= limit * limit
    first = np.nonzero(inside)[0]
    if len(first) == 0:
        return plan[:0]
    i = int(first[0])
    out = np.nonzero(~inside[i:])[0]
    # ROS adds the first point beyond the threshold too (its distance is checked after)
    end = len(plan) if len(out) == 0 else i + int(out[0]) + 1
    return plan[i:end]


def angle_diff(a: float, b: float) -> float:
    """``a - b`` wrapped to ``(-pi, pi]``."""
    d = math.fmod(a - b + math.pi, 2.0 * math.pi)
    if d <= 0:
        d += 2.0 * math.pi
    return d - math.pi
