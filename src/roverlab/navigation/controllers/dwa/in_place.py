"""base_local_planner's TrajectoryPlanner rotations in place, for TrajectoryPlannerROS.

TrajectoryPlanner::createTrajectories samples, after the forward trajectories, rotations
in place at the theta window's ``vtheta_samples`` speeds (each at least
``min_in_place_vel_theta``; those within one step of 0 left out), whatever ``min_vel_x``
is. A legal rotation replaces the best trajectory when its cost is not higher; among
those, the one whose end pose looks (``heading_lookahead`` m ahead) at the cell nearest
the local goal wins, unless the robot is stuck in that direction: once a rotation one way
follows one the other way, that first way is refused (``stuck_left`` / ``stuck_right``)
until the robot has moved ``oscillation_reset_dist`` from where it last rotated. When
every forward and rotation sample is refused the robot backs up (escape, in the planner).
Used with TrajectoryPlannerROS's ``in_place_rotations: true`` (roverlab's parameter; off
by default, see :class:`~roverlab.navigation.controllers.dwa.params.DWAParams`).
ROS's flag names are kept with its pairing (a negative speed sets ``rotating_left`` and is
refused by ``stuck_left``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2

__all__ = ["InPlaceRotations", "ProgressCheck", "in_place_samples"]


def in_place_samples(lo: float, hi: float, num: int, min_in_place: float) -> NDArray[np.float64]:
    """The rotation samples ``(0, 0, vth)`` over the theta window ``[lo, hi]``."""
    n = max(2, num)
    step = (hi - lo) / (n - 1)
    ths = lo + step * np.arange(n)
    ths = ths[(ths > step) | (ths < -step)]
    ths = np.where(ths > 0, np.maximum(ths, min_in_place), np.minimum(ths, -min_in_place))
    out = np.zeros((len(ths), 3))
    out[:, 2] = ths
    return out


class InPlaceRotations:
    """TrajectoryPlanner's choice between the best forward sample and a rotation, with
    its ``rotating_*`` / ``stuck_*`` flags."""

    def __init__(self, heading_lookahead: float, oscillation_reset_dist: float) -> None:
        self.heading_lookahead = heading_lookahead
        self.reset_dist = oscillation_reset_dist
        self.reset(SE2())

    def reset(self, pose: SE2) -> None:
        """Clears the flags (a new plan, or the robot moved far enough)."""
        self.rotating_left = self.rotating_right = False
        self.stuck_left = self.stuck_right = False
        self._prev = pose

    def pick(
        self,
        pose: SE2,
        samples: NDArray[np.float64],
        costs: NDArray[np.float64],
        ends: NDArray[np.float64],
        goal_dist: NDArray[np.float64],
        origin: tuple[float, float, float],
    ) -> int:
        """The chosen sample's index (-1: none legal) and the flags updated.

        ``ends``: each sample's last pose (x, y, theta); ``goal_dist``: the local goal's
        distance grid; ``origin``: the grid's ``(resolution, origin_x, origin_y)``."""
        rot = (samples[:, 0] == 0.0) & (samples[:, 1] == 0.0) & (samples[:, 2] != 0.0)
        fwd = np.flatnonzero(~rot & (costs >= 0))
        best = int(fwd[np.argmin(costs[fwd])]) if len(fwd) else -1
        heading = math.inf
        res, ox, oy = origin
        h, w = goal_dist.shape
        for k in np.flatnonzero(rot):  # in increasing speed, as ROS samples them
            c = costs[k]
            if c < 0 or (best >= 0 and c > costs[best]):
                continue
            x, y, th = ends[k]
            cx = math.floor((x + self.heading_lookahead * math.cos(th) - ox) / res)
            cy = math.floor((y + self.heading_lookahead * math.sin(th) - oy) / res)
            if not (0 <= cx < w and 0 <= cy < h) or goal_dist[cy, cx] >= heading:
                continue
            vth = samples[k, 2]
            if (vth < 0 and not self.stuck_left) or (vth > 0 and not self.stuck_right):
                best, heading = int(k), float(goal_dist[cy, cx])
        if best < 0:
            return -1
        if not samples[best, 0] > 0:
            vth = samples[best, 2]
            if vth < 0:
                self.stuck_right |= self.rotating_right
                self.rotating_left = True
            elif vth > 0:
                self.stuck_left |= self.rotating_left
                self.rotating_right = True
            self._prev = pose
        if math.hypot(pose.x - self._prev.x, pose.y - self._prev.y) > self.reset_dist:
            self.reset(self._prev)
        return best


class ProgressCheck:
    """Nav2's SimpleProgressChecker on the control cycles: the robot is stalled once it
    has stayed within ``radius`` m of where the window began for more than
    ``allowance`` s (cycles x ``period``), and stays stalled until it is ``radius`` m
    from there. ``allowance`` 0: never stalled."""

    def __init__(self, radius: float, allowance: float, period: float) -> None:
        self.radius, self.allowance, self.period = radius, allowance, period
        self._anchor: SE2 | None = None
        self._cycles = 0
        self.is_stalled = False

    def stalled(self, pose: SE2) -> bool:
        """Called once per control cycle with the robot's pose."""
        if self.allowance <= 0:
            return False
        a = self._anchor
        if a is None or math.hypot(pose.x - a.x, pose.y - a.y) > self.radius:
            self._anchor, self._cycles, self.is_stalled = pose, 0, False
            return False
        self._cycles += 1
        if self._cycles * self.period > self.allowance:
            self.is_stalled = True
        return self.is_stalled
