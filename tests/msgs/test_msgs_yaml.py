"""dict and YAML conversion: validation paths, flow / block / lenient forms, round trips."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
import yaml

from roverlab import msgs
from roverlab.msgs import (
    FieldError,
    MessageValueError,
    MessageYAMLError,
    from_dict,
    parse_yaml_message,
    to_dict,
    to_yaml,
)

TWIST = "geometry_msgs/msg/Twist"


def _twist_values(msg: Any) -> tuple[float, ...]:
    return (msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z)


def test_to_dict_gives_plain_python_values() -> None:
    scan = msgs.LaserScan(header_frame_id="laser", ranges=[1.5, 2.5], range_max=10.0)
    d = to_dict(scan)
    assert d["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": "laser"}
    assert d["ranges"] == [1.5, 2.5]
    assert all(type(v) is float for v in d["ranges"])
    assert d["intensities"] == []
    img = to_dict(msgs.Image(data=b"\x00\xff"))
    assert img["data"] == [0, 255] and all(type(v) is int for v in img["data"])
    assert list(to_dict(msgs.Twist())) == ["linear", "angular"]
    assert to_dict(msgs.Empty()) == {}


def test_from_dict_round_trip(
    filler: Callable[[str], Any], same: Callable[[Any, Any], None]
) -> None:
    for typename in (
        "nav_msgs/msg/Odometry",
        "visualization_msgs/msg/Marker",
        "sensor_msgs/msg/Image",
    ):
        msg = filler(typename)
        same(from_dict(typename, to_dict(msg)), msg)


def test_from_dict_unknown_field_names_dotted_path() -> None:
    with pytest.raises(FieldError, match=r"^geometry_msgs/msg/Twist has no field 'linear\.w'$"):
        from_dict(TWIST, {"linear": {"w": 1.0}})
    with pytest.raises(FieldError, match=r"has no field 'poses\[0\]\.pose\.positon'"):
        from_dict("nav_msgs/Path", {"poses": [{"pose": {"positon": {}}}]})


@pytest.mark.parametrize(
    ("data", "path"),
    [
        ({"linear": {"x": "abc"}}, "linear.x"),
        ({"linear": {"x": {"a": 1}}}, "linear.x"),
        ({"linear": [1, 2, 3]}, "linear"),
        ({"angular": {"z": None}}, "angular.z"),
    ],
)
def test_from_dict_wrong_kind_names_path(data: dict[str, Any], path: str) -> None:
    with pytest.raises(MessageValueError, match=f"'{path}'"):
        from_dict(TWIST, data)


def test_from_dict_out_of_range_and_not_a_mapping() -> None:
    with pytest.raises(MessageValueError, match=r"'stamp\.nanosec'.*out of range for uint32"):
        from_dict("std_msgs/Header", {"stamp": {"nanosec": -1}})
    with pytest.raises(MessageValueError, match="expected a mapping"):
        from_dict(TWIST, [1, 2])  # type: ignore[arg-type]


def test_parse_flow_form() -> None:
    msg = parse_yaml_message(TWIST, "{linear: {x: 0.2}, angular: {z: 0.5}}")
    assert _twist_values(msg) == (0.2, 0.0, 0.0, 0.0, 0.0, 0.5)


def test_parse_block_form() -> None:
    text = "linear:\n  x: 0.0\n  y: 1.5\n  z: 0.0\nangular:\n  x: 0.0\n  y: 0.0\n  z: -0.25\n"
    msg = parse_yaml_message("geometry_msgs/Twist", text)
    assert _twist_values(msg) == (0.0, 1.5, 0.0, 0.0, 0.0, -0.25)


def test_parse_without_spaces_after_colons() -> None:
    text = "{linear:{x:0.2,y:0,z:0},angular:{x:0,y:0,z:0.5}}"
    msg = parse_yaml_message(TWIST, text)
    assert _twist_values(msg) == (0.2, 0.0, 0.0, 0.0, 0.0, 0.5)
    assert parse_yaml_message("std_msgs/Header", "{frame_id:'a:b'}").frame_id == "a:b"


def test_parse_exponent_floats() -> None:
    msg = parse_yaml_message(TWIST, "{linear: {x: 1e-3, y: -2E+2}}")
    assert (msg.linear.x, msg.linear.y) == (0.001, -200.0)


@pytest.mark.parametrize("text", ["", "   \n", "{}", "~"])
def test_parse_empty_gives_default(text: str) -> None:
    msg = parse_yaml_message(TWIST, text)
    assert _twist_values(msg) == (0.0,) * 6
    assert parse_yaml_message("geometry_msgs/Quaternion", text).w == 1.0


@pytest.mark.parametrize(
    "text", ["{linear: {x: [1}", "linear: [1, 2", "a:\n  - 1\n b: 2", "- 1\n- 2", "just words"]
)
def test_parse_malformed_raises_one_line(text: str) -> None:
    with pytest.raises(MessageYAMLError) as info:
        parse_yaml_message(TWIST, text)
    message = str(info.value)
    assert message.startswith("invalid YAML for geometry_msgs/msg/Twist: ")
    assert "\n" not in message


def test_parse_malformed_reports_yaml_reason() -> None:
    with pytest.raises(MessageYAMLError, match=r"expected ',' or '\]'.*\(line 1, column"):
        parse_yaml_message(TWIST, "linear: [1, 2")


def test_parse_unknown_field_and_wrong_kind() -> None:
    with pytest.raises(FieldError, match=r"has no field 'linear\.w'"):
        parse_yaml_message(TWIST, "{linear: {w: 1.0}}")
    with pytest.raises(MessageValueError, match=r"'linear\.x'.*str 'fast'"):
        parse_yaml_message(TWIST, "{linear: {x: fast}}")


def test_to_yaml_looks_like_ros2_topic_echo() -> None:
    text = to_yaml(msgs.Twist(linear_x=0.2, angular_z=0.5))
    assert text == (
        "linear:\n  x: 0.2\n  y: 0.0\n  z: 0.0\nangular:\n  x: 0.0\n  y: 0.0\n  z: 0.5\n"
    )
    scan_text = to_yaml(msgs.LaserScan(ranges=[0.1, 2.0], angle_increment=0.1))
    assert "ranges:\n- 0.1\n- 2.0\n" in scan_text  # float32 0.1 shown as 0.1
    assert "angle_increment: 0.1\n" in scan_text
    assert "intensities: []\n" in scan_text
    assert "frame_id: ''\n" in scan_text


def test_to_yaml_quotes_strings_that_look_like_numbers() -> None:
    for frame in ("1e-3", "yes", "12", "a: b"):
        msg = msgs.Header(frame_id=frame)
        assert parse_yaml_message("std_msgs/Header", to_yaml(msg)).frame_id == frame


@pytest.mark.parametrize(
    "msg",
    [
        msgs.Twist(linear_x=0.2, linear_y=-1e-9, angular_z=3.25),
        msgs.PoseStamped(
            header_frame_id="map",
            header_stamp_sec=12,
            header_stamp_nanosec=5,
            pose_position_x=1.0,
            pose_orientation_z=0.5,
        ),
        msgs.make_scan(
            np.array([0.1, 1.3, np.inf, np.nan, 29.97], dtype=np.float32),
            angle_min=-1.2,
            angle_max=1.2,
            range_min=0.05,
            range_max=30.0,
            intensities=[1, 2, 3, 4, 5],
        ),
    ],
    ids=["Twist", "PoseStamped", "LaserScan"],
)
def test_yaml_round_trip(msg: Any, same: Callable[[Any, Any], None]) -> None:
    text = to_yaml(msg)
    assert isinstance(yaml.safe_load(text), dict)
    back = parse_yaml_message(msgs.type_name(msg), text)
    assert msgs.messages_equal(back, msg)
    if msgs.type_name(msg) != "sensor_msgs/msg/LaserScan":  # NaN != NaN in the plain compare
        same(back, msg)


def test_messages_equal_detects_differences() -> None:
    a = msgs.LaserScan(ranges=[1.0, float("nan")])
    assert msgs.messages_equal(a, msgs.LaserScan(ranges=[1.0, float("nan")]))
    assert not msgs.messages_equal(a, msgs.LaserScan(ranges=[1.0, 2.0]))
    assert not msgs.messages_equal(a, msgs.LaserScan(ranges=[1.0]))
    assert not msgs.messages_equal(msgs.Twist(), msgs.Accel())
    assert not msgs.messages_equal(msgs.Twist(), msgs.Twist(angular_y=1e-12))
