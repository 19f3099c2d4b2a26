"""Parameters of a differential-drive robot (gazebo_ros_diff_drive semantics).

The motion itself is integrated by the compiled loop in :mod:`roverlab.sim.dynamics`.

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

__all__ = ["DiffDriveParams"]


@dataclass(frozen=True, slots=True)
class DiffDriveParams:
    """Kinematic parameters, as the plugin's ``wheelSeparation`` etc.

    Args:
        wheel_separation_m: distance between the wheels' contact points.
        wheel_diameter_m: wheel diameter.
        wheel_acceleration: max change of wheel surface speed, m/s^2 (0 = unlimited): the
            plugin's ``wheelAcceleration``, or less when ``wheelTorque`` cannot push the
            robot's mass faster (see ``sim.robot``).
        max_wheel_speed_mps: clamp of each wheel's surface speed (a guard against absurd
            commands; the plugin has no speed limit).
        slip_stddev: relative 1-sigma slip of each wheel per physics step (0 = no slip;
            the simulator node's ``wheel_slip`` parameter sets it).
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
