"""Twists as ``(linear x, linear y, linear z, angular z)`` tuples, shared by the teleop tests."""

from __future__ import annotations

Fields = tuple[float, float, float, float]

ZERO: Fields = (0.0, 0.0, 0.0, 0.0)

#: What teleop_twist_keyboard publishes for the keys ``i q J j`` + a stop key + ``t``,
#: started with speed 0.4 and turn 0.8 (``q`` raises both by 10 %).
IQJJ_STOP_T: list[Fields] = [
    (0.4, 0.0, 0.0, 0.0),
    (0.4 * 1.1, 0.0, 0.0, 0.0),
    (0.0, 0.4 * 1.1, 0.0, 0.0),
    (0.0, 0.0, 0.0, 0.8 * 1.1),
    ZERO,
    (0.0, 0.0, 0.4 * 1.1, 0.0),
]
