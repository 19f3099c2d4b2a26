"""CDR round trips of every exposed type, checked against rosbags' own serialiser."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from roverlab import msgs
from roverlab.msgs import EXPOSED_TYPES, SerializationError, deserialize, serialize

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)


@pytest.mark.parametrize("typename", EXPOSED_TYPES)
def test_round_trip_filled(
    typename: str, filler: Callable[[str], Any], same: Callable[[Any, Any], None]
) -> None:
    msg = filler(typename)
    data = serialize(msg)
    assert isinstance(data, bytes)
    assert data == bytes(TYPESTORE.serialize_cdr(msg, typename, little_endian=True))
    if typename != "std_msgs/msg/Empty":  # the only type without a field to fill
        assert data != serialize(msgs.make(typename))
    back = deserialize(data, typename)
    same(back, msg)
    assert msgs.messages_equal(back, msg)


@pytest.mark.parametrize("typename", EXPOSED_TYPES)
def test_round_trip_default(typename: str, same: Callable[[Any, Any], None]) -> None:
    msg = msgs.make(typename)
    same(deserialize(serialize(msg), typename), msg)


def test_default_twist_is_52_bytes() -> None:
    data = serialize(msgs.Twist())
    assert len(data) == 52  # 4-byte CDR header + 6 float64
    assert data[:4] == b"\x00\x01\x00\x00"
    assert data[4:] == bytes(48)
    assert msgs.cdr_size(msgs.Twist()) == 52


def test_twist_values_little_endian() -> None:
    data = serialize(msgs.Twist(linear_x=0.2, angular_z=-0.5))
    assert np.frombuffer(data[4:], dtype="<f8").tolist() == [0.2, 0, 0, 0, 0, -0.5]


def test_deserialize_big_endian() -> None:
    msg = msgs.Twist(linear_x=1.5)
    data = bytes(TYPESTORE.serialize_cdr(msg, "geometry_msgs/msg/Twist", little_endian=False))
    assert data[:2] == b"\x00\x00"
    assert deserialize(data, "geometry_msgs/msg/Twist").linear.x == 1.5


def test_deserialize_accepts_any_type_reference() -> None:
    data = serialize(msgs.Vector3(x=1.0, y=2.0, z=3.0))
    for ref in (
        "geometry_msgs/Vector3",
        "geometry_msgs.msg.Vector3",
        msgs.Vector3,
        msgs.Vector3.cls,
    ):
        back = deserialize(data, ref)
        assert (back.x, back.y, back.z) == (1.0, 2.0, 3.0)
    assert deserialize(bytearray(data), "geometry_msgs/msg/Vector3").z == 3.0
    assert deserialize(memoryview(data), "geometry_msgs/msg/Vector3").y == 2.0


def test_deserialized_arrays_survive_buffer_reuse() -> None:
    scan = msgs.LaserScan(ranges=[1.0, 2.0, 3.0])
    buf = bytearray(serialize(scan))
    back = deserialize(buf, "sensor_msgs/msg/LaserScan")
    buf[:] = bytes(len(buf))
    assert back.ranges.tolist() == [1.0, 2.0, 3.0]
    assert back.ranges.dtype == np.float32


@pytest.mark.parametrize(
    "data",
    [b"", b"\x00\x01", b"\x07\x01\x00\x00" + bytes(48), b"\x00\x01\x00\x00" + bytes(10)],
)
def test_deserialize_rejects_bad_bytes(data: bytes) -> None:
    with pytest.raises(SerializationError, match="geometry_msgs/msg/Twist"):
        deserialize(data, "geometry_msgs/msg/Twist")


def test_deserialize_rejects_trailing_bytes() -> None:
    data = serialize(msgs.Twist()) + bytes(16)
    with pytest.raises(SerializationError, match="left over"):
        deserialize(data, "geometry_msgs/msg/Twist")


def test_serialize_rejects_badly_typed_message() -> None:
    msg = msgs.LaserScan()
    msg.ranges = "not numbers"
    with pytest.raises(SerializationError, match="sensor_msgs/msg/LaserScan"):
        serialize(msg)


def test_serialize_rejects_non_message() -> None:
    with pytest.raises(msgs.UnknownTypeError):
        serialize(3.0)


def test_scan_720_round_trip() -> None:
    ranges = np.linspace(0.5, 10.0, 720, dtype=np.float32)
    scan = msgs.make_scan(ranges, angle_min=-3.1, angle_max=3.1, range_min=0.1, range_max=12.0)
    data = serialize(scan)
    # CDR header, stamp, frame_id (length + 'laser\0' + 2 pad), 7 float32, ranges, intensities
    assert len(data) == 4 + 8 + (4 + 6 + 2) + 7 * 4 + (4 + 720 * 4) + 4
    back = deserialize(data, "sensor_msgs/msg/LaserScan")
    np.testing.assert_array_equal(back.ranges, ranges)
    assert back.header.frame_id == "laser"
