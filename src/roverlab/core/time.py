"""Time and Duration with integer nanoseconds, as rclpy.time / rclpy.duration."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from roverlab.msgs import classes as mc

__all__ = ["Duration", "Time"]

_NS = 1_000_000_000


@dataclass(frozen=True, slots=True, order=True)
class Duration:
    """A signed span of time in integer nanoseconds."""

    nanoseconds: int = 0

    @staticmethod
    def from_seconds(seconds: float) -> Duration:
        if not math.isfinite(seconds):
            raise ValueError(f"duration must be finite, got {seconds}")
        return Duration(round(seconds * _NS))

    @property
    def seconds(self) -> float:
        return self.nanoseconds / _NS

    def to_msg(self) -> Any:
        sec, nsec = divmod(self.nanoseconds, _NS)
        return mc.Duration(sec=sec, nanosec=nsec)

    def __add__(self, other: Duration) -> Duration:
        return Duration(self.nanoseconds + other.nanoseconds)

    def __sub__(self, other: Duration) -> Duration:
        return Duration(self.nanoseconds - other.nanoseconds)

    def __neg__(self) -> Duration:
        return Duration(-self.nanoseconds)


@dataclass(frozen=True, slots=True, order=True)
class Time:
    """A point in time (since the clock's epoch) in integer nanoseconds."""

    nanoseconds: int = 0

    @staticmethod
    def from_seconds(seconds: float) -> Time:
        if not math.isfinite(seconds):
            raise ValueError(f"time must be finite, got {seconds}")
        return Time(round(seconds * _NS))

    @staticmethod
    def from_msg(msg: Any) -> Time:
        """From a builtin_interfaces/Time message (or anything with sec and nanosec)."""
        return Time(int(msg.sec) * _NS + int(msg.nanosec))

    @property
    def seconds(self) -> float:
        return self.nanoseconds / _NS

    def seconds_nanoseconds(self) -> tuple[int, int]:
        sec, nsec = divmod(self.nanoseconds, _NS)
        return sec, nsec

    def to_msg(self) -> Any:
        sec, nsec = divmod(self.nanoseconds, _NS)
        return mc.Time(sec=sec, nanosec=nsec)

    def __add__(self, other: Duration) -> Time:
        return Time(self.nanoseconds + other.nanoseconds)

    def __sub__(self, other: Time | Duration) -> Any:
        if isinstance(other, Time):
            return Duration(self.nanoseconds - other.nanoseconds)
        return Time(self.nanoseconds - other.nanoseconds)
