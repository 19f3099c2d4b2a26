"""``ros_arduino_python``'s base controller, pure: the clock and the encoder counts are
passed in, the motor speeds handed back.

Parameters (names and defaults of ros_arduino_python): ``base_controller_rate`` 10 Hz,
``base_controller_timeout`` 1 s, ``wheel_diameter``, ``wheel_track``,
``encoder_resolution`` (required), ``gear_reduction`` 1.0, ``accel_limit`` 1.0,
``motors_reversed`` false, ``odom_linear_scale_correction`` / ``..._angular_...`` 1.0,
``Kp`` 20, ``Kd`` 12, ``Ki`` 0, ``Ko`` 50 (sent to the firmware).

``ticks_per_meter = encoder_resolution * gear_reduction / (wheel_diameter * pi)``;
``max_accel = accel_limit * ticks_per_meter / rate`` ticks per frame per update.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from roverlab.drivers.errors import DriverError
from roverlab.drivers.odometry import EncoderOdometry, OdometryState, ramp, wheel_setpoints

__all__ = ["BaseController", "BaseParams"]


@dataclass(frozen=True, kw_only=True)
class BaseParams:
    """The base controller's parameters (ros_arduino_python's names)."""

    wheel_diameter: float
    wheel_track: float
    encoder_resolution: float
    gear_reduction: float = 1.0
    base_controller_rate: float = 10.0
    base_controller_timeout: float = 1.0
    accel_limit: float = 1.0
    motors_reversed: bool = False
    odom_linear_scale_correction: float = 1.0
    odom_angular_scale_correction: float = 1.0
    Kp: int = 20
    Kd: int = 12
    Ki: int = 0
    Ko: int = 50

    def __post_init__(self) -> None:
        for key in (
            "wheel_diameter",
            "wheel_track",
            "encoder_resolution",
            "gear_reduction",
            "base_controller_rate",
        ):
            value = getattr(self, key)
            if not (math.isfinite(value) and value > 0):
                raise DriverError(f"{key} must be > 0, got {value}")
        for key in ("base_controller_timeout", "accel_limit"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0):
                raise DriverError(f"{key} must be >= 0, got {value}")

    @property
    def ticks_per_meter(self) -> float:
        return self.encoder_resolution * self.gear_reduction / (self.wheel_diameter * math.pi)

    @property
    def max_accel(self) -> float:
        return self.accel_limit * self.ticks_per_meter / self.base_controller_rate


class BaseController:
    """The base controller's loop: command -> set-points; counts -> odometry, speeds.

    Args:
        params: the base's parameters.
        now_s: the clock at start (``last_cmd_vel``, ``then``).
    """

    def __init__(self, params: BaseParams, *, now_s: float) -> None:
        self.params = params
        self.odometry = EncoderOdometry(
            ticks_per_meter=params.ticks_per_meter,
            wheel_track_m=params.wheel_track,
            linear_scale=params.odom_linear_scale_correction,
            angular_scale=params.odom_angular_scale_correction,
        )
        self.v_left = 0.0
        self.v_right = 0.0
        self.v_des_left = 0
        self.v_des_right = 0
        self.last_cmd_s = now_s
        self.then_s = now_s

    def command(self, linear_x: float, angular_z: float, *, now_s: float) -> None:
        """A ``cmd_vel``.

        Raises:
            DriverError: a NaN or infinite command (the set-points are kept).
        """
        p = self.params
        self.v_des_left, self.v_des_right = wheel_setpoints(
            linear_x,
            angular_z,
            wheel_track_m=p.wheel_track,
            ticks_per_meter=p.ticks_per_meter,
            gear_reduction=p.gear_reduction,
        )
        self.last_cmd_s = now_s

    def update(self, left: int, right: int, now_s: float) -> tuple[OdometryState, int, int]:
        """One poll with fresh encoder counts: the odometry and the speeds to send
        (``m LEFT RIGHT``, ticks per frame; negated and swapped when the motors are
        reversed, as the driver does)."""
        dt = now_s - self.then_s
        self.then_s = now_s
        if self.params.motors_reversed:
            left, right = -left, -right
        state = self.odometry.update(left, right, dt)
        if now_s > self.last_cmd_s + self.params.base_controller_timeout:
            self.v_des_left = self.v_des_right = 0
        step = self.params.max_accel
        self.v_left = ramp(self.v_left, self.v_des_left, step)
        self.v_right = ramp(self.v_right, self.v_des_right, step)
        out_l, out_r = int(self.v_left), int(self.v_right)
        if self.params.motors_reversed:
            out_l, out_r = -out_l, -out_r
        return state, out_l, out_r
