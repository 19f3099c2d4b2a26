"""Message converters and tf_echo text."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from roverlab.core.time import Time
from roverlab.geometry import Transform3, quat_from_yaw
from roverlab.tf import (
    TF_MESSAGE_TYPE,
    TRANSFORM_STAMPED_TYPE,
    Buffer,
    format_transform_echo,
    tf_message,
    transform_from_msg,
    transform_to_msg,
)

YAW90 = Transform3.from_arrays((1.0, 2.0, 0.0), quat_from_yaw(math.pi / 2))


def test_transform_msg_round_trip() -> None:
    stamp = Time(12_345_678_901)
    msg = transform_to_msg("odom", "base_link", stamp, YAW90)
    assert msg.__msgtype__ == TRANSFORM_STAMPED_TYPE
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (12, 345_678_901)
    assert msg.header.frame_id == "odom" and msg.child_frame_id == "base_link"
    assert msg.transform.translation.y == 2.0
    assert msg.transform.rotation.w == pytest.approx(math.sqrt(0.5))
    assert transform_from_msg(msg) == ("odom", "base_link", stamp, YAW90)


def test_transform_from_msg_accepts_look_alikes() -> None:
    v = SimpleNamespace
    msg = v(
        header=v(stamp=v(sec=3, nanosec=5), frame_id="map"),
        child_frame_id="odom",
        transform=v(translation=v(x=1, y=0, z=0), rotation=v(x=0, y=0, z=0, w=1)),
    )
    parent, child, stamp, t = transform_from_msg(msg)
    assert (parent, child, stamp.nanoseconds) == ("map", "odom", 3_000_000_005)
    assert t == Transform3((1.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def test_tf_message_holds_the_transforms() -> None:
    a = transform_to_msg("map", "odom", Time(1), Transform3())
    b = transform_to_msg("odom", "base_link", Time(1), YAW90)
    msg = tf_message((a, b))
    assert msg.__msgtype__ == TF_MESSAGE_TYPE
    assert [t.child_frame_id for t in msg.transforms] == ["odom", "base_link"]


def test_buffer_message_helpers() -> None:
    buf = Buffer()
    buf.set_transform_msg(transform_to_msg("/odom", "base_link", Time(2_000_000_000), YAW90))
    buf.set_transform_msg(
        transform_to_msg("base_link", "laser", Time(0), Transform3((0.5, 0, 0))), is_static=True
    )
    msg = buf.lookup_transform_msg("odom", "laser", Time(0))
    assert msg.header.frame_id == "odom" and msg.child_frame_id == "laser"
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) == (2, 0)
    assert msg.transform.translation.x == pytest.approx(1.0)
    assert msg.transform.translation.y == pytest.approx(2.5)
    full = buf.lookup_transform_full_msg(
        "laser", Time(2_000_000_000), "laser", Time(2_000_000_000), "odom"
    )
    assert full.transform.rotation.w == pytest.approx(1.0)


def test_format_transform_echo_matches_tf_echo() -> None:
    expected = (
        "At time 12.345\n"
        "- Translation: [1.000, 2.000, 0.000]\n"
        "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]\n"
        "            in RPY (radian) [0.000, -0.000, 1.571]\n"
        "            in RPY (degree) [0.000, -0.000, 90.000]"
    )
    stamp = Time(12_345_000_000)
    text = format_transform_echo(transform_to_msg("odom", "base_link", stamp, YAW90))
    # "-0.000" vs "0.000" for pitch depends on the sign of a rounding residue, as in tf_echo
    assert text.replace("-0.000", "0.000") == expected.replace("-0.000", "0.000")
    assert format_transform_echo((YAW90, stamp)) == text
    assert format_transform_echo(YAW90, stamp) == text
    assert format_transform_echo(YAW90, stamp, precision=1).startswith("At time 12.3\n")
    with pytest.raises(TypeError):
        format_transform_echo(YAW90)
    with pytest.raises(TypeError):
        format_transform_echo(42)
