"""rospy.Time and rospy.Duration on ROS 2's ``builtin_interfaces`` messages.

``rospy.Time`` *is* a ``builtin_interfaces/Time`` message (a subclass), so
``header.stamp = rospy.Time.now()`` puts a serialisable stamp in a message. Stamps in
received messages are plain ``builtin_interfaces/Time``; :func:`add_ros1_accessors` gives
that class ROS 1's ``secs`` / ``nsecs`` / ``to_sec()`` / arithmetic too, so
``msg.header.stamp.to_sec()`` and ``rospy.Time.now() - msg.header.stamp`` work.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from roverlab.msgs import classes as mc
from roverlab.ros1.rospy.exceptions import ROSInitException

__all__ = ["Duration", "Time", "add_ros1_accessors", "set_clock"]

_NS = 1_000_000_000
_clock: list[Callable[[], int]] = []


def set_clock(now_ns: Callable[[], int] | None) -> None:
    """Where ``Time.now()`` reads the ROS time (the rospy layer's node clock)."""
    _clock.clear()
    if now_ns is not None:
        _clock.append(now_ns)


def _split(secs: float | int, nsecs: int) -> tuple[int, int]:
    """ROS 1's canonical (secs, nsecs): nsecs in [0, 1e9); float secs carry a fraction."""
    if isinstance(secs, float):
        if not math.isfinite(secs):
            raise ValueError(f"time values must be finite, got {secs}")
        if nsecs:
            raise ValueError("a float secs and nsecs cannot both be given")
        total = round(secs * _NS)
    else:
        total = int(secs) * _NS + int(nsecs)
    s, ns = divmod(total, _NS)
    return int(s), int(ns)


def _ns_of(value: Any) -> int:
    return int(value.sec) * _NS + int(value.nanosec)


class _Ros1Value:
    """ROS 1 accessors on a ``sec``/``nanosec`` pair (shared by Time and Duration)."""

    sec: int
    nanosec: int

    @property
    def secs(self) -> int:
        return int(self.sec)

    @secs.setter
    def secs(self, value: int) -> None:
        self.sec = int(value)

    @property
    def nsecs(self) -> int:
        return int(self.nanosec)

    @nsecs.setter
    def nsecs(self, value: int) -> None:
        self.nanosec = int(value)

    def to_nsec(self) -> int:
        return _ns_of(self)

    def to_sec(self) -> float:
        return _ns_of(self) / _NS

    def is_zero(self) -> bool:
        return _ns_of(self) == 0


class Duration(mc.Duration, _Ros1Value):
    """rospy.Duration: ``Duration(secs, nsecs)``, ``Duration.from_sec(1.5)``."""

    def __init__(self, secs: float | int = 0, nsecs: int = 0) -> None:
        s, ns = _split(secs, nsecs)
        super().__init__(s, ns)

    @classmethod
    def from_sec(cls, secs: float) -> Duration:
        return cls(float(secs))

    @classmethod
    def from_nsec(cls, nsecs: int) -> Duration:
        return cls(0, int(nsecs))

    def __repr__(self) -> str:
        return f"rospy.Duration[{_ns_of(self)}]"

    def __str__(self) -> str:
        return str(_ns_of(self))


class Time(mc.Time, _Ros1Value):
    """rospy.Time: ``Time(secs, nsecs)``, ``Time.now()``, ``Time.from_sec(t)``."""

    def __init__(self, secs: float | int = 0, nsecs: int = 0) -> None:
        s, ns = _split(secs, nsecs)
        if s < 0:
            raise ValueError("time values must be positive")
        super().__init__(s, ns)

    @classmethod
    def now(cls) -> Time:
        """The ROS time now (sim time when the node follows /clock)."""
        if not _clock:
            raise ROSInitException("time is not initialized. Have you called init_node()?")
        return cls.from_nsec(_clock[0]())

    @classmethod
    def from_sec(cls, secs: float) -> Time:
        return cls(float(secs))

    @classmethod
    def from_nsec(cls, nsecs: int) -> Time:
        return cls(0, int(nsecs))

    def __repr__(self) -> str:
        return f"rospy.Time[{_ns_of(self)}]"

    def __str__(self) -> str:
        return str(_ns_of(self))


# ----------------------------------------------------------------------------- arithmetic
def _is_time(v: Any) -> bool:
    return isinstance(v, mc.Time)


def _is_duration(v: Any) -> bool:
    return isinstance(v, mc.Duration)


def _time_add(self: Any, other: Any) -> Any:
    if _is_duration(other):
        return Time.from_nsec(_ns_of(self) + _ns_of(other))
    return NotImplemented


def _time_sub(self: Any, other: Any) -> Any:
    if _is_time(other):
        return Duration.from_nsec(_ns_of(self) - _ns_of(other))
    if _is_duration(other):
        return Time.from_nsec(_ns_of(self) - _ns_of(other))
    return NotImplemented


def _dur_add(self: Any, other: Any) -> Any:
    if _is_duration(other):
        return Duration.from_nsec(_ns_of(self) + _ns_of(other))
    if _is_time(other):
        return Time.from_nsec(_ns_of(self) + _ns_of(other))
    return NotImplemented


def _dur_sub(self: Any, other: Any) -> Any:
    if _is_duration(other):
        return Duration.from_nsec(_ns_of(self) - _ns_of(other))
    return NotImplemented


def _dur_mul(self: Any, k: Any) -> Any:
    if isinstance(k, int | float) and not isinstance(k, bool):
        return Duration.from_nsec(round(_ns_of(self) * k))
    return NotImplemented


def _dur_div(self: Any, k: Any) -> Any:
    if _is_duration(k):
        return _ns_of(self) / _ns_of(k)
    if isinstance(k, int | float) and not isinstance(k, bool):
        return Duration.from_nsec(round(_ns_of(self) / k))
    return NotImplemented


def _dur_neg(self: Any) -> Any:
    return Duration.from_nsec(-_ns_of(self))


def _dur_abs(self: Any) -> Any:
    return Duration.from_nsec(abs(_ns_of(self)))


def _comparisons(kind: Callable[[Any], bool]) -> dict[str, Callable[[Any, Any], Any]]:
    def cmp(op: Callable[[int, int], bool]) -> Callable[[Any, Any], Any]:
        def method(self: Any, other: Any) -> Any:
            if not kind(other):
                return NotImplemented
            return op(_ns_of(self), _ns_of(other))

        return method

    return {
        "__eq__": cmp(lambda a, b: a == b),
        "__ne__": cmp(lambda a, b: a != b),
        "__lt__": cmp(lambda a, b: a < b),
        "__le__": cmp(lambda a, b: a <= b),
        "__gt__": cmp(lambda a, b: a > b),
        "__ge__": cmp(lambda a, b: a >= b),
    }


def add_ros1_accessors() -> None:
    """Give ``builtin_interfaces`` Time/Duration (and so every stamp of every message,
    sent or received) ROS 1's accessors, arithmetic and comparisons. Idempotent."""
    for cls, kind, ops in (
        (mc.Time, _is_time, {"__add__": _time_add, "__radd__": _time_add, "__sub__": _time_sub}),
        (
            mc.Duration,
            _is_duration,
            {
                "__add__": _dur_add,
                "__radd__": _dur_add,
                "__sub__": _dur_sub,
                "__mul__": _dur_mul,
                "__rmul__": _dur_mul,
                "__truediv__": _dur_div,
                "__neg__": _dur_neg,
                "__abs__": _dur_abs,
            },
        ),
    ):
        for name in ("secs", "nsecs", "to_nsec", "to_sec", "is_zero"):
            setattr(cls, name, _Ros1Value.__dict__[name])
        for name, fn in {**ops, **_comparisons(kind)}.items():
            setattr(cls, name, fn)
        cls.__hash__ = lambda self: hash(_ns_of(self))  # type: ignore[method-assign]


add_ros1_accessors()
