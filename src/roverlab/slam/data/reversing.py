"""Odometry that moved forward while the robot reversed: a fault of some CARMEN logs.

A CARMEN ``ODOM`` line carries the base's integrated pose *and* its translational
velocity ``tv``. Some bases integrate the speed without its sign: while ``tv`` is negative
(reversing) the logged pose still advances along the heading, so the odometry moves the
robot forwards when it drives backwards (the headings are right). In Freiburg's fr079 log
416 of 8,950 steps do this, and the log's ground-truth relations confirm the backward
motion; no step of fr079 or intel goes backwards while ``tv`` is positive.

:class:`ReversingRepair` re-integrates such a pose stream: a step whose forward component
disagrees with a negative ``tv`` is reversed (its translation in the previous pose's frame
negated, its rotation kept), and every later pose is moved with it. A scan between two
``ODOM`` lines is repaired the same way from the last line. A log without such a step
comes out unchanged, bit for bit.
"""

from __future__ import annotations

from typing import Final

from roverlab.geometry import SE2

__all__ = ["REVERSING_SPEED_M_S", "ReversingRepair"]

#: ``tv`` below minus this (m/s) is reversing.
REVERSING_SPEED_M_S: Final = 0.01
# a step shorter than this (m) is no motion (a scan logged at the last ODOM pose)
_NO_STEP_M: Final = 1e-9


class ReversingRepair:
    """Re-integrates an odometry stream whose steps went forward while ``tv`` < 0.

    Attributes:
        steps: odometry steps seen.
        reversed_steps: steps that were reversed.
    """

    def __init__(self) -> None:
        self._correction: SE2 | None = None  # repaired = correction * logged (None: identity)
        self._last: SE2 | None = None
        self._reversing = False
        self.steps = 0
        self.reversed_steps = 0

    def _apply(self, pose: SE2) -> SE2:
        return pose if self._correction is None else self._correction * pose

    def _reversed_from_last(self, pose: SE2) -> SE2 | None:
        """``pose`` with its step from the last ``ODOM`` pose reversed, or None when the
        step needs no repair."""
        if self._last is None or not self._reversing:
            return None
        step = ~self._last * pose
        if step.x <= _NO_STEP_M:
            return None
        return self._apply(self._last) * SE2(-step.x, -step.y, step.theta)

    def odom(self, pose: SE2, tv: float) -> SE2:
        """The repaired pose of an ``ODOM`` line (in file order) with velocity ``tv``."""
        self._reversing = tv < -REVERSING_SPEED_M_S
        fixed = self._reversed_from_last(pose)
        if self._last is not None:
            self.steps += 1
        if fixed is not None:
            self.reversed_steps += 1
            self._correction = fixed * ~pose
        self._last = pose
        return self._apply(pose)

    def scan(self, pose: SE2) -> SE2:
        """The repaired odometry pose of a scan logged after the last ``ODOM`` line."""
        fixed = self._reversed_from_last(pose)
        return self._apply(pose) if fixed is None else fixed
