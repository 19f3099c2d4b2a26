"""Type names: ROS 2, ROS 1 and Python forms; unknown types with suggestions."""

from __future__ import annotations

import pytest

from roverlab import msgs
from roverlab.errors import RoverlabError
from roverlab.msgs import UnknownTypeError, get_type, normalize_type_name, type_name


@pytest.mark.parametrize(
    "name",
    [
        "geometry_msgs/msg/Twist",
        "geometry_msgs/Twist",
        "geometry_msgs.msg.Twist",
        " geometry_msgs/Twist ",
    ],
)
def test_normalize_accepts_ros2_ros1_and_python_forms(name: str) -> None:
    assert normalize_type_name(name) == "geometry_msgs/msg/Twist"
    assert get_type(name) is msgs.Twist.cls


def test_get_type_of_class_factory_and_message() -> None:
    cls = msgs.LaserScan.cls
    assert get_type(cls) is cls
    assert get_type(msgs.LaserScan) is cls
    assert get_type(msgs.LaserScan()) is cls


def test_type_name_of_message_class_factory_and_name() -> None:
    assert type_name(msgs.Odometry()) == "nav_msgs/msg/Odometry"
    assert type_name(msgs.Odometry.cls) == "nav_msgs/msg/Odometry"
    assert type_name(msgs.Odometry) == "nav_msgs/msg/Odometry"
    assert type_name("nav_msgs/Odometry") == "nav_msgs/msg/Odometry"


def test_unknown_type_suggests_the_close_name() -> None:
    with pytest.raises(UnknownTypeError) as info:
        get_type("geometry_msgs/Twst")
    assert str(info.value) == (
        "unknown message type 'geometry_msgs/Twst' (did you mean geometry_msgs/msg/Twist?)"
    )
    assert isinstance(info.value, RoverlabError)


def test_unknown_type_suggestions_for_case_and_missing_package() -> None:
    with pytest.raises(UnknownTypeError, match=r"did you mean sensor_msgs/msg/LaserScan\?"):
        get_type("sensor_msgs/laserscan")
    with pytest.raises(UnknownTypeError, match=r"did you mean nav_msgs/msg/Odometry\?"):
        get_type("Odometry")


def test_unknown_type_without_suggestion_is_one_line() -> None:
    with pytest.raises(UnknownTypeError) as info:
        get_type("zzz_pkg/msg/Qqqqqq")
    assert "\n" not in str(info.value)
    assert "did you mean" not in str(info.value)
    assert "'zzz_pkg/msg/Qqqqqq'" in str(info.value)


@pytest.mark.parametrize("bad", ["", "a/b/c/d", "geometry_msgs/foo/Twist", "geometry msgs/Twist"])
def test_malformed_names_rejected(bad: str) -> None:
    with pytest.raises(UnknownTypeError, match="not a message type name"):
        normalize_type_name(bad)


def test_non_type_object_rejected() -> None:
    with pytest.raises(UnknownTypeError, match="not a message type"):
        get_type(42)


def test_service_message_names_are_names() -> None:
    assert normalize_type_name("std_srvs/srv/Empty_Request") == "std_srvs/srv/Empty_Request"
    with pytest.raises(UnknownTypeError, match="unknown message type 'geometry_msgs/srv/Twist'"):
        get_type("geometry_msgs/srv/Twist")
