"""arbotix_python's ``diff_controller`` on a fake base: pure, clock passed in.

Parameters (``~controllers/NAME/...``, as arbotix reads them; defaults arbotix's):
``type`` (``diff_controller``), ``ticks_meter`` and ``base_width`` (required),
``rate`` (10 Hz), ``timeout`` (1 s), ``base_frame_id`` (``base_link``),
``odom_frame_id`` (``odom``), ``Kp`` 5, ``Kd`` 1, ``Ki`` 0, ``Ko`` 50 (sent to a real
board's PID; a fake base has ideal motors), ``accel_limit`` (0.1).

Behaviour, arbotix's:

* ``cmd_vel`` sets the wheel set-points ``int((x -/+ th * base_width / 2) * ticks_meter
  / 30)`` ticks per 1/30 s frame;
* an update runs when the clock has passed ``t_next`` (then ``t_next = now + 1/rate``):
  read the encoders, integrate odometry, zero the set-points when no command came for
  ``timeout`` s, move each wheel speed towards its set-point by at most
  ``max_accel = int(accel_limit * ticks_meter / rate)`` ticks per frame, send it.

arbotix's units make that limit ``30 * accel_limit`` m/s per update period in wheel
speed (ticks per frame against ticks per second): reproduced as is, so a robot tuned on
arbotix drives the same here.

The fake base is where roverlab differs: arbotix's own ``sim`` mode copies ``cmd_vel`` into
the odometry at once (no ramp, and it never stops after ``timeout``). Here the fake base
is ideal motors under the real controller loop: the encoders count ``v * 30`` ticks per
second of the speed last sent, so the simulated odometry ramps and times out as the real
robot does.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from roverlab.drivers.errors import DriverError
from roverlab.drivers.odometry import (
    PID_RATE_HZ,
    EncoderOdometry,
    OdometryState,
    ramp,
    wheel_setpoints,
)

__all__ = ["DIFF_CONTROLLER_KEYS", "DiffController", "DiffControllerParams", "parse_controllers"]

DIFF_CONTROLLER_KEYS: Final = (
    "type",
    "ticks_meter",
    "base_width",
    "rate",
    "timeout",
    "base_frame_id",
    "odom_frame_id",
    "Kp",
    "Kd",
    "Ki",
    "Ko",
    "accel_limit",
)
"""The keys diff_controller reads under ``controllers/NAME/``."""


@dataclass(frozen=True, kw_only=True)
class DiffControllerParams:
    """One ``diff_controller``'s parameters (names and defaults arbotix's)."""

    name: str
    ticks_meter: float
    base_width: float
    rate: float = 10.0
    timeout: float = 1.0
    base_frame_id: str = "base_link"
    odom_frame_id: str = "odom"
    Kp: int = 5
    Kd: int = 1
    Ki: int = 0
    Ko: int = 50
    accel_limit: float = 0.1

    def __post_init__(self) -> None:
        for key in ("ticks_meter", "base_width", "rate"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value > 0):
                raise DriverError(f"controller {self.name}: {key} must be > 0, got {value}")
        for key in ("timeout", "accel_limit"):
            value = getattr(self, key)
            if not (math.isfinite(value) and value >= 0):
                raise DriverError(f"controller {self.name}: {key} must be >= 0, got {value}")

    @property
    def max_accel(self) -> int:
        """Largest change of a wheel speed per update, in ticks per frame (arbotix's)."""
        return int(self.accel_limit * self.ticks_meter / self.rate)


def _number(name: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise DriverError(f"controller {name}: {key} must be a number, got {value!r}")
    return float(value)


def parse_controllers(
    params: Mapping[str, Any],
) -> tuple[list[DiffControllerParams], list[str]]:
    """The diff controllers of a flat ``controllers/NAME/KEY`` parameter mapping.

    Returns:
        The diff controllers, and one note per controller of another type (arbotix's
        ``follow_controller``, ``gripper_controller``, ... drive servos, not a base).

    Raises:
        DriverError: a diff_controller without ``ticks_meter`` or ``base_width``, or a
            value of the wrong type.
    """
    grouped: dict[str, dict[str, Any]] = {}
    for key, value in params.items():
        parts = key.split("/")
        if len(parts) == 3 and parts[0] == "controllers":
            grouped.setdefault(parts[1], {})[parts[2]] = value
    diffs: list[DiffControllerParams] = []
    notes: list[str] = []
    for name in sorted(grouped):
        cfg = grouped[name]
        kind = str(cfg.get("type", ""))
        if kind != "diff_controller":
            notes.append(f"controller {name} of type {kind or '(none)'} is not simulated")
            continue
        for req in ("ticks_meter", "base_width"):
            if req not in cfg:
                raise DriverError(f"controller {name}: parameter {req} is required")
        kwargs: dict[str, Any] = {}
        for key in ("ticks_meter", "base_width", "rate", "timeout", "accel_limit"):
            if key in cfg:
                kwargs[key] = _number(name, key, cfg[key])
        for key in ("Kp", "Kd", "Ki", "Ko"):
            if key in cfg:
                kwargs[key] = int(_number(name, key, cfg[key]))
        for key in ("base_frame_id", "odom_frame_id"):
            if key in cfg:
                kwargs[key] = str(cfg[key]).lstrip("/")
        diffs.append(DiffControllerParams(name=name, **kwargs))
    return diffs, notes


class DiffController:
    """diff_controller driving a fake base with ideal motors.

    Args:
        params: the controller's parameters.
        now_s: the clock when the controller starts (its ``last_cmd`` and ``then``).
    """

    def __init__(self, params: DiffControllerParams, *, now_s: float) -> None:
        self.params = params
        self.odometry = EncoderOdometry(
            ticks_per_meter=params.ticks_meter, wheel_track_m=params.base_width
        )
        self.v_left = 0  # speed sent to the motors, ticks per frame
        self.v_right = 0
        self.v_des_left = 0  # cmd_vel set-point
        self.v_des_right = 0
        self.enc_left = 0.0  # the fake motors' encoder counts
        self.enc_right = 0.0
        self.last_cmd_s = now_s
        self.then_s = now_s
        self.t_next_s = now_s + 1.0 / params.rate

    def command(self, linear_x: float, angular_z: float, *, now_s: float) -> None:
        """A ``cmd_vel``: new wheel set-points.

        Raises:
            DriverError: a NaN or infinite command (ignored; the set-points are kept).
        """
        left, right = wheel_setpoints(
            linear_x,
            angular_z,
            wheel_track_m=self.params.base_width,
            ticks_per_meter=self.params.ticks_meter,
        )
        self.last_cmd_s = now_s
        self.v_des_left, self.v_des_right = left, right

    def due(self, now_s: float) -> bool:
        """Whether an update runs at ``now_s`` (arbotix: ``now > t_next``)."""
        return now_s > self.t_next_s

    def update(self, now_s: float) -> OdometryState:
        """One controller update: encoders, odometry, timeout, ramp, motors."""
        elapsed = now_s - self.then_s
        self.then_s = now_s
        # the fake motors turned at the speed sent last time for `elapsed` seconds
        self.enc_left += self.v_left * PID_RATE_HZ * elapsed
        self.enc_right += self.v_right * PID_RATE_HZ * elapsed
        state = self.odometry.update(round(self.enc_left), round(self.enc_right), elapsed)
        if now_s > self.last_cmd_s + self.params.timeout:
            self.v_des_left = self.v_des_right = 0
        step = self.params.max_accel
        self.v_left = int(ramp(self.v_left, self.v_des_left, step))
        self.v_right = int(ramp(self.v_right, self.v_des_right, step))
        self.t_next_s = now_s + 1.0 / self.params.rate
        return state

    def wheel_speeds_mps(self) -> tuple[float, float]:
        """The speeds sent to the wheels, in m/s."""
        k = PID_RATE_HZ / self.params.ticks_meter
        return self.v_left * k, self.v_right * k
