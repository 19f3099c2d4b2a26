"""Planar rigid-body physics of a differential-drive robot (gazebo_ros_diff_drive semantics).

The plugin turns a commanded body twist ``(v, w)`` into left/right wheel surface speeds
``v -+ w * separation / 2``. Each update it moves each wheel's speed towards its target by
at most ``wheel_acceleration * dt`` (m/s^2 of wheel surface; 0 = instantly), exactly as
``GazeboRosDiffDrive::UpdateChild`` does. The body then moves with the wheels' speeds; with
``slip_stddev > 0`` the ground moves the body by slightly different amounts than the wheels
turned (multiplicative Gaussian noise per wheel and step), which is what makes encoder
odometry drift.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from roverlab.geometry import wrap_angle

__all__ = ["DiffDriveParams", "DiffDriveState", "arc_step", "step_wheels"]


@dataclass(frozen=True, slots=True)
class DiffDriveParams:
    """Kinematic parameters, as the plugin's ``wheelSeparation`` etc.

    Args:
        wheel_separation_m: distance between the wheels' contact points.
        wheel_diameter_m: wheel diameter.
        wheel_acceleration: max change of wheel surface speed, m/s^2 (0 = unlimited).
        max_wheel_speed_mps: clamp of each wheel's surface speed (from ``wheelTorque`` we
            cannot derive one; this guards against absurd commands).
        slip_stddev: relative 1-sigma slip of each wheel per step (0 = no slip).
    """

    wheel_separation_m: float
    wheel_diameter_m: float
    wheel_acceleration: float = 0.0
    max_wheel_speed_mps: float = 5.0
    slip_stddev: float = 0.0

    def __post_init__(self) -> None:
        for name in ("wheel_separation_m", "wheel_diameter_m"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be > 0, got {v}")
        for name in ("wheel_acceleration", "max_wheel_speed_mps", "slip_stddev"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be >= 0, got {v}")


@dataclass(slots=True)
class DiffDriveState:
    """Wheel speeds (m/s of surface), wheel angles (rad) and their commanded targets."""

    left_speed: float = 0.0
    right_speed: float = 0.0
    left_target: float = 0.0
    right_target: float = 0.0
    left_angle: float = 0.0
    right_angle: float = 0.0

    def command(self, params: DiffDriveParams, v: float, w: float) -> None:
        """Set wheel targets from a body twist (non-finite values stop the robot)."""
        if not (math.isfinite(v) and math.isfinite(w)):
            v = w = 0.0
        half = 0.5 * params.wheel_separation_m * w
        lim = params.max_wheel_speed_mps
        self.left_target = max(-lim, min(lim, v - half))
        self.right_target = max(-lim, min(lim, v + half))

    def stop(self) -> None:
        self.left_speed = self.right_speed = 0.0


def _approach(current: float, target: float, max_delta: float) -> float:
    if max_delta <= 0.0:
        return target
    if target > current:
        return min(target, current + max_delta)
    return max(target, current - max_delta)


def step_wheels(state: DiffDriveState, params: DiffDriveParams, dt: float) -> None:
    """Advance wheel speeds towards their targets (acceleration limit) and wheel angles."""
    acc = params.wheel_acceleration
    max_delta = acc * dt if acc > 0 else 0.0
    state.left_speed = _approach(state.left_speed, state.left_target, max_delta)
    state.right_speed = _approach(state.right_speed, state.right_target, max_delta)
    r = 0.5 * params.wheel_diameter_m
    state.left_angle = float(wrap_angle(state.left_angle + state.left_speed * dt / r))
    state.right_angle = float(wrap_angle(state.right_angle + state.right_speed * dt / r))


def arc_step(
    x: float, y: float, theta: float, v: float, w: float, dt: float
) -> tuple[float, float, float]:
    """Exact pose after moving with constant (v, w) for dt (an arc; a line if w == 0)."""
    if abs(w) < 1e-9:
        c, s = math.cos(theta), math.sin(theta)
        return x + v * dt * c, y + v * dt * s, theta
    th2 = theta + w * dt
    r = v / w
    return (
        x + r * (math.sin(th2) - math.sin(theta)),
        y - r * (math.cos(th2) - math.cos(theta)),
        float(wrap_angle(th2)),
    )


def body_twist(
    params: DiffDriveParams,
    left: float,
    right: float,
    rng: np.random.Generator | None = None,
) -> tuple[float, float]:
    """Body (v, w) from wheel surface speeds, with per-wheel slip if ``rng`` is given."""
    if rng is not None and params.slip_stddev > 0.0:
        nl, nr = rng.normal(0.0, params.slip_stddev, 2)
        left *= 1.0 + nl
        right *= 1.0 + nr
    return 0.5 * (left + right), (right - left) / params.wheel_separation_m
