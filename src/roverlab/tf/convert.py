"""Converters between tf messages and plain values, and tf_echo's text.

Messages are ``geometry_msgs/msg/TransformStamped`` and ``tf2_msgs/msg/TFMessage`` with the
ROS 2 fields. Reading accepts any object with those fields; writing builds roverlab.msgs
messages (the rosbags classes of the project's type store).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, Final

from roverlab.core.time import Time
from roverlab.geometry import Transform3, rpy_from_quat
from roverlab.msgs import classes as mc

__all__ = [
    "TF_MESSAGE_TYPE",
    "TRANSFORM_STAMPED_TYPE",
    "format_transform_echo",
    "tf_message",
    "transform_from_msg",
    "transform_to_msg",
]

TRANSFORM_STAMPED_TYPE: Final = "geometry_msgs/msg/TransformStamped"
TF_MESSAGE_TYPE: Final = "tf2_msgs/msg/TFMessage"
_NS: Final = 1_000_000_000


def transform_from_msg(msg: Any) -> tuple[str, str, Time, Transform3]:
    """``(parent, child, stamp, parent_T_child)`` of a TransformStamped message."""
    t = msg.transform.translation
    q = msg.transform.rotation
    return (
        str(msg.header.frame_id),
        str(msg.child_frame_id),
        Time.from_msg(msg.header.stamp),
        Transform3(
            (float(t.x), float(t.y), float(t.z)),
            (float(q.x), float(q.y), float(q.z), float(q.w)),
        ),
    )


def transform_to_msg(parent: str, child: str, stamp: Time, transform: Transform3) -> Any:
    """A ``geometry_msgs/msg/TransformStamped`` carrying ``parent_T_child`` at ``stamp``."""
    sec, nanosec = divmod(stamp.nanoseconds, _NS)
    tx, ty, tz = transform.translation
    qx, qy, qz, qw = transform.rotation
    # positional, in ROS field order: robot_state_publisher and broadcasters call this
    # for every transform, and keyword construction costs twice as much
    return mc.TransformStamped(
        mc.Header(mc.Time(sec, nanosec), parent),
        child,
        mc.Transform(
            mc.Vector3(float(tx), float(ty), float(tz)),
            mc.Quaternion(float(qx), float(qy), float(qz), float(qw)),
        ),
    )


def tf_message(transforms: Iterable[Any]) -> Any:
    """A ``tf2_msgs/msg/TFMessage`` holding the given TransformStamped messages."""
    return mc.TFMessage(transforms=list(transforms))


def format_transform_echo(value: Any, stamp: Time | None = None, *, precision: int = 3) -> str:
    """The text ``tf_echo`` prints for one transform.

    Args:
        value: a TransformStamped message, a ``(Transform3, Time)`` pair as returned by
            ``lookup_transform``, or a :class:`Transform3` (then ``stamp`` is required).
        stamp: the time to print when ``value`` is a bare Transform3.
        precision: decimals of every number.

    Returns:
        Five lines, e.g.::

            At time 12.345
            - Translation: [1.000, 2.000, 0.000]
            - Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]
                        in RPY (radian) [0.000, -0.000, 1.571]
                        in RPY (degree) [0.000, -0.000, 90.000]

    Raises:
        TypeError: ``value`` is none of the above, or a Transform3 without ``stamp``.
    """
    if isinstance(value, Transform3):
        if stamp is None:
            raise TypeError("format_transform_echo needs a stamp for a bare Transform3")
        transform = value
    elif isinstance(value, tuple) and len(value) == 2 and isinstance(value[0], Transform3):
        transform, stamp = value
    elif hasattr(value, "transform") and hasattr(value, "header"):
        _, _, stamp, transform = transform_from_msg(value)
    else:
        raise TypeError(f"cannot format {type(value).__name__} as a transform")
    assert stamp is not None

    def vec(values: Iterable[float]) -> str:
        return "[" + ", ".join(f"{v:.{precision}f}" for v in values) + "]"

    rpy = rpy_from_quat(transform.rotation)
    return (
        f"At time {stamp.nanoseconds / _NS:.{precision}f}\n"
        f"- Translation: {vec(transform.translation)}\n"
        f"- Rotation: in Quaternion {vec(transform.rotation)}\n"
        f"            in RPY (radian) {vec(rpy)}\n"
        f"            in RPY (degree) {vec(math.degrees(a) for a in rpy)}"
    )
