"""Recoveries that move the robot or wait, beside ROS 1's clear and rotate: Nav2's BackUp,
Spin and Wait behaviours, and move_slow_and_clear's MoveSlowAndClear.

Pure steppers like :class:`~roverlab.navigation.move_base.recovery.RotateRecovery`:
:meth:`start` with the robot's pose and the time, then :meth:`step` each control cycle
returns the velocity to command, or None when the behaviour is over (``finished``) or
cannot go on (``blocked`` holds why). As Nav2's behaviours do, each simulates its motion
``simulate_ahead_time`` ahead and stops before a collision; the footprint checked is the
robot's real (unpadded) one against lethal and unknown cells, so a robot whose padded
footprint already touches an obstacle can still back away from it.

Their parameters live under the recovery's name (``~NAME/backup_dist``), with Nav2's
names and defaults (``backup_dist`` 0.15 m, ``backup_speed`` 0.025 m/s, ``spin_dist``
1.57 rad, ``wait_duration`` 1 s, ``time_allowance`` 10 s, ``simulate_ahead_time`` 2 s,
``max_rotational_vel`` 1.0, ``min_rotational_vel`` 0.4, ``rotational_acc_lim`` 3.2).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.navigation.controllers import Velocity2D
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.costmap.footprint_kernels import footprint_cost
from roverlab.navigation.params import build_params, check

__all__ = [
    "BackUp",
    "BehaviorParams",
    "MoveSlowAndClear",
    "MoveSlowAndClearParams",
    "Spin",
    "Wait",
    "footprint_clear",
]


def footprint_clear(cm: Costmap2D, footprint: NDArray[np.float64], x: float, y: float,
                    th: float, buf: NDArray[np.int64]) -> bool:  # fmt: skip
    """Whether ``footprint`` at ``(x, y, th)`` covers no lethal or unknown cell and stays
    on ``cm``."""
    return (
        footprint_cost(
            cm.costs, cm.resolution, cm.origin_x, cm.origin_y, x, y, th, footprint, 1.0, buf
        )
        >= 0
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class BehaviorParams:
    """Nav2's behaviour parameters (its behavior_server's and its BT nodes' names)."""

    backup_dist: float = 0.15
    backup_speed: float = 0.025
    spin_dist: float = 1.57
    wait_duration: float = 1.0
    time_allowance: float = 10.0
    simulate_ahead_time: float = 2.0
    max_rotational_vel: float = 1.0
    min_rotational_vel: float = 0.4
    rotational_acc_lim: float = 3.2

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name != "spin_dist":  # its sign is the direction
                check(math.isfinite(v) and v >= 0, f"behavior: {f.name} must be >= 0, got {v}")
        check(math.isfinite(self.spin_dist), "behavior: spin_dist must be a finite number")
        check(self.backup_speed > 0, "behavior: backup_speed must be > 0")
        check(self.max_rotational_vel > 0, "behavior: max_rotational_vel must be > 0")

    @classmethod
    def from_ros(
        cls, name: str, values: Mapping[str, Any]
    ) -> tuple[BehaviorParams, tuple[str, ...]]:
        """From ``~NAME/...`` (an unknown name is a warning).

        Raises:
            NavigationParamsError: a bad value, named.
        """
        p, res = build_params(cls, values, where=name)
        return p, res.warnings


class _Motion:
    """What the moving behaviours share: the footprint, the clock, the outcome."""

    type = ""

    def __init__(self, name: str, params: BehaviorParams, *, footprint: ArrayLike) -> None:
        self.name = name
        self.params = params
        self.footprint = np.ascontiguousarray(
            np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        )
        self._buf = np.empty((4096, 2), dtype=np.int64)
        self._start = SE2()
        self._t0 = 0.0
        self.finished = False
        self.blocked: str | None = None

    def start(self, pose: SE2, now: float) -> None:
        self._start, self._t0 = pose, now
        self.finished = False
        self.blocked = None

    def _timed_out(self, now: float) -> bool:
        if self.params.time_allowance > 0 and now - self._t0 > self.params.time_allowance:
            self.blocked = f"{self.name}: exceeded time allowance before reaching the target"
            return True
        return False

    def _clear_ahead(self, pose: SE2, cmd: Velocity2D, left: float, cm: Costmap2D) -> bool:
        """Nav2's isCollisionFree: the motion at ``cmd`` for ``simulate_ahead_time`` (or
        until ``left`` of it is done) in steps of half a cell or 0.05 rad."""
        p = self.params
        speed = max(abs(cmd.vx), 1e-9) if cmd.vx else max(abs(cmd.wz), 1e-9)
        horizon = min(p.simulate_ahead_time, left / speed)
        step = (0.5 * cm.resolution) / abs(cmd.vx) if cmd.vx else 0.05 / abs(cmd.wz)
        t = 0.0
        while True:
            th = pose.theta + cmd.wz * t
            x = pose.x + cmd.vx * t * math.cos(pose.theta)
            y = pose.y + cmd.vx * t * math.sin(pose.theta)
            if not footprint_clear(cm, self.footprint, x, y, th, self._buf):
                self.blocked = f"{self.name}: collision ahead, exiting"
                return False
            if t >= horizon:
                return True
            t = min(horizon, t + step)


class BackUp(_Motion):
    """Nav2's BackUp: straight back ``backup_dist`` at ``backup_speed``."""

    type = "nav2_behaviors/BackUp"

    def step(self, pose: SE2, cm: Costmap2D, now: float) -> Velocity2D | None:
        p = self.params
        done = math.hypot(pose.x - self._start.x, pose.y - self._start.y)
        left = p.backup_dist - done
        if left <= 0:
            self.finished = True
            return None
        if self._timed_out(now):
            return None
        cmd = Velocity2D(-p.backup_speed, 0.0, 0.0)
        return cmd if self._clear_ahead(pose, cmd, left, cm) else None


class Spin(_Motion):
    """Nav2's Spin: turn ``spin_dist`` (rad, its sign the direction) in place, slowing
    with ``rotational_acc_lim`` towards the end."""

    type = "nav2_behaviors/Spin"

    def start(self, pose: SE2, now: float) -> None:
        super().start(pose, now)
        self._turned = 0.0
        self._last_yaw = pose.theta

    def step(self, pose: SE2, cm: Costmap2D, now: float) -> Velocity2D | None:
        p = self.params
        self._turned += abs(float(wrap_angle(pose.theta - self._last_yaw)))
        self._last_yaw = pose.theta
        left = abs(p.spin_dist) - self._turned
        if left <= 0:
            self.finished = True
            return None
        if self._timed_out(now):
            return None
        vel = math.sqrt(2.0 * p.rotational_acc_lim * left)
        vel = min(max(vel, p.min_rotational_vel), p.max_rotational_vel)
        cmd = Velocity2D(0.0, 0.0, math.copysign(vel, p.spin_dist or 1.0))
        return cmd if self._clear_ahead(pose, cmd, left, cm) else None


class Wait(_Motion):
    """Nav2's Wait: stand still for ``wait_duration`` (the robot stopped, the costmaps
    updating: a passer-by may leave)."""

    type = "nav2_behaviors/Wait"

    def step(self, pose: SE2, cm: Costmap2D, now: float) -> Velocity2D | None:
        if now - self._t0 >= self.params.wait_duration:
            self.finished = True
            return None
        return Velocity2D()


@dataclass(frozen=True, slots=True, kw_only=True)
class MoveSlowAndClearParams:
    """move_slow_and_clear's parameters (ROS names and defaults)."""

    clearing_distance: float = 0.5
    limited_trans_speed: float = 0.25
    limited_rot_speed: float = 0.45
    limited_distance: float = 0.3
    max_trans_param_name: str = "max_trans_vel"
    max_rot_param_name: str = "max_rot_vel"

    def __post_init__(self) -> None:
        for name in ("clearing_distance", "limited_trans_speed", "limited_rot_speed",
                     "limited_distance"):  # fmt: skip
            v = getattr(self, name)
            check(math.isfinite(v) and v >= 0, f"move_slow_and_clear: {name} must be >= 0")


class MoveSlowAndClear:
    """move_slow_and_clear: clear the obstacle layers within ``clearing_distance`` of the
    robot (both costmaps), then cap the commanded speeds at ``limited_trans_speed`` and
    ``limited_rot_speed`` until the robot is ``limited_distance`` from where it was. ROS
    sets the limits on the local planner through dynamic_reconfigure (the
    ``max_trans_param_name`` / ``max_rot_param_name`` names); roverlab caps move_base's
    command, which has the same effect on every local planner (the two names are read and
    not needed)."""

    type = "move_slow_and_clear/MoveSlowAndClear"

    def __init__(self, name: str, params: MoveSlowAndClearParams | None = None) -> None:
        self.name = name
        self.params = params or MoveSlowAndClearParams()
        self._origin: SE2 | None = None

    @classmethod
    def from_ros(
        cls, name: str, values: Mapping[str, Any]
    ) -> tuple[MoveSlowAndClear, tuple[str, ...]]:
        """From ``~NAME/...`` (an unknown name is a warning).

        Raises:
            NavigationParamsError: a bad value, named.
        """
        p, res = build_params(MoveSlowAndClearParams, values, where=name)
        return cls(name, p), res.warnings

    @property
    def limiting(self) -> bool:
        return self._origin is not None

    def engage(self, pose: SE2) -> None:
        """The limit holds from ``pose`` on."""
        self._origin = pose

    def limit(self, cmd: Velocity2D, pose: SE2) -> Velocity2D:
        """``cmd`` capped while the robot is within ``limited_distance`` of where the
        recovery ran; the cap is lifted after that."""
        o, p = self._origin, self.params
        if o is None:
            return cmd
        if math.hypot(pose.x - o.x, pose.y - o.y) >= p.limited_distance:
            self._origin = None
            return cmd
        trans = math.hypot(cmd.vx, cmd.vy)
        k = p.limited_trans_speed / trans if trans > p.limited_trans_speed else 1.0
        wz = max(-p.limited_rot_speed, min(p.limited_rot_speed, cmd.wz))
        return Velocity2D(cmd.vx * k, cmd.vy * k, wz)
