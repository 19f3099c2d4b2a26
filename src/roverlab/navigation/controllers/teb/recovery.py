"""teb_local_planner's oscillation recovery: ``FailureDetector`` (recovery_behaviors.cpp)
and the oscillation part of TebLocalPlannerROS::configureBackupModes.

The last commands, normalised by the speed limits, fill a buffer of
``oscillation_filter_duration * controller_frequency`` entries; once it is at least half
full, the robot oscillates when the mean normalised linear velocity is below
``oscillation_v_eps``, the mean normalised angular velocity below
``oscillation_omega_eps``, and the angular velocity changed sign more than once.
"""

from __future__ import annotations

import math
from collections import deque
from itertools import pairwise

from roverlab.navigation.controllers.base import Velocity2D
from roverlab.navigation.controllers.teb.params import TebParams

__all__ = ["FailureDetector", "OscillationRecovery"]


def _sign(x: float) -> int:
    return 1 if x > 0 else -1 if x < 0 else 0


class FailureDetector:
    """TEB's ``FailureDetector``: :meth:`update` with each command, then
    :attr:`oscillating`."""

    def __init__(self, length: int) -> None:
        self._buf: deque[tuple[float, float]] = deque(maxlen=max(int(length), 0))
        self.oscillating = False

    def clear(self) -> None:
        self._buf.clear()
        self.oscillating = False

    def update(
        self,
        cmd: Velocity2D,
        v_max: float,
        v_backwards_max: float,
        omega_max: float,
        v_eps: float,
        omega_eps: float,
    ) -> bool:
        """Add a command and detect (returns :attr:`oscillating`)."""
        if self._buf.maxlen == 0:
            return False
        v = cmd.vx
        if v > 0 and v_max > 0:
            v /= v_max
        elif v < 0 and v_backwards_max > 0:
            v /= v_backwards_max
        om = cmd.wz / omega_max if omega_max > 0 else cmd.wz
        self._buf.append((v, om))
        self.oscillating = False
        n = len(self._buf)
        if n < (self._buf.maxlen or 0) // 2:
            return False
        v_mean = sum(b[0] for b in self._buf) / n
        om_mean = sum(b[1] for b in self._buf) / n
        omegas = [b[1] for b in self._buf]
        crossings = sum(_sign(a) != _sign(b) for a, b in pairwise(omegas))
        self.oscillating = abs(v_mean) < v_eps and abs(om_mean) < omega_eps and crossings > 1
        return self.oscillating


class OscillationRecovery:
    """configureBackupModes' oscillation recovery: :meth:`update` each cycle (before
    planning) with the last command; while the robot oscillates, and for
    ``oscillation_recovery_min_duration`` s after, the optimisation prefers the turning
    direction the robot had when the oscillation was first detected."""

    def __init__(self, params: TebParams) -> None:
        self.params = params
        length = round(params.oscillation_filter_duration * params.controller_frequency)
        self.detector = FailureDetector(length)
        self.time_last_oscillation = -math.inf
        self.preferred_rotdir = 0

    def update(self, now: float, last_cmd: Velocity2D, robot_vel: Velocity2D) -> int:
        """The preferred turning direction for this cycle: +1 left, -1 right, 0 none.
        ``now`` in seconds (the planner counts control cycles)."""
        p = self.params
        current = p.max_vel_x if last_cmd.vx >= 0 else p.max_vel_x_backwards
        max_vel_theta = p.max_vel_theta
        if p.min_turning_radius != 0 and current > 0:
            max_vel_theta = max(current / abs(p.min_turning_radius), p.max_vel_theta)
        oscillating = self.detector.update(
            last_cmd, p.max_vel_x, p.max_vel_x_backwards, max_vel_theta,
            p.oscillation_v_eps, p.oscillation_omega_eps,
        )  # fmt: skip
        recently = now - self.time_last_oscillation < p.oscillation_recovery_min_duration
        if oscillating:
            if not recently:  # save the current turning direction
                self.preferred_rotdir = 1 if robot_vel.wz > 0 else -1
            self.time_last_oscillation = now
        elif not recently:
            self.preferred_rotdir = 0
        return self.preferred_rotdir
