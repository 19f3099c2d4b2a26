"""Constructors: defaults, nested dicts, flattened names, isinstance, dtypes, errors."""

from __future__ import annotations

import numpy as np
import pytest

from roverlab import msgs
from roverlab.errors import RoverlabError
from roverlab.msgs import FieldError, MessageError, MessageValueError

_REQUIRED_BY_PACKAGE = {
    "builtin_interfaces": "Time Duration",
    "std_msgs": "Header String Bool Float64 Float32 Int32 Empty ColorRGBA",
    "geometry_msgs": (
        "Point Point32 Quaternion Vector3 Pose Pose2D PoseStamped PoseWithCovariance"
        " PoseWithCovarianceStamped PoseArray Twist TwistStamped TwistWithCovariance Transform"
        " TransformStamped Polygon PolygonStamped PointStamped Accel"
    ),
    "sensor_msgs": (
        "LaserScan Imu Image CompressedImage CameraInfo PointCloud2 PointField JointState"
        " RegionOfInterest"
    ),
    "nav_msgs": "Odometry OccupancyGrid MapMetaData Path",
    "tf2_msgs": "TFMessage",
    "rosgraph_msgs": "Clock",
    "visualization_msgs": "Marker MarkerArray",
    "action_msgs": "GoalStatus GoalStatusArray GoalInfo",
}
REQUIRED = [
    f"{pkg}/msg/{name}" for pkg, names in _REQUIRED_BY_PACKAGE.items() for name in names.split()
]


@pytest.mark.parametrize("typename", REQUIRED)
def test_required_factory_exposed(typename: str) -> None:
    assert typename in msgs.EXPOSED_TYPES
    short = typename.rsplit("/", 1)[-1]
    factory = getattr(msgs, short)
    assert short in msgs.__all__
    assert factory.typename == typename
    assert factory.cls is msgs.get_type(typename)
    msg = factory()
    assert isinstance(msg, factory.cls)
    assert msgs.type_name(msg) == typename


def test_exposed_types_unique_and_known() -> None:
    assert len(set(msgs.EXPOSED_TYPES)) == len(msgs.EXPOSED_TYPES)
    for typename in msgs.EXPOSED_TYPES:
        assert msgs.get_factory(typename) is getattr(msgs, typename.rsplit("/", 1)[-1])


def test_defaults() -> None:
    twist = msgs.Twist()
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == (0.0, 0.0, 0.0)
    assert isinstance(twist.angular.z, float)
    header = msgs.Header()
    assert header.frame_id == ""
    assert (header.stamp.sec, header.stamp.nanosec) == (0, 0)
    assert msgs.Bool().data is False
    assert msgs.Int32().data == 0 and isinstance(msgs.Int32().data, int)
    marker = msgs.Marker()
    assert marker.points == [] and marker.colors == []
    assert marker.lifetime.sec == 0


def test_quaternion_defaults_to_identity_as_in_ros2() -> None:
    q = msgs.Quaternion()
    assert (q.x, q.y, q.z, q.w) == (0.0, 0.0, 0.0, 1.0)
    assert msgs.PoseStamped().pose.orientation.w == 1.0
    assert msgs.from_dict("geometry_msgs/Pose", {}).orientation.w == 1.0


def test_default_arrays_have_ros_dtypes_and_lengths() -> None:
    cov = msgs.PoseWithCovariance().covariance
    assert isinstance(cov, np.ndarray) and cov.dtype == np.float64 and cov.shape == (36,)
    assert not cov.any()
    scan = msgs.LaserScan()
    assert scan.ranges.dtype == np.float32 and scan.ranges.shape == (0,)
    assert msgs.Image().data.dtype == np.uint8
    assert msgs.OccupancyGrid().data.dtype == np.int8
    info = msgs.CameraInfo()
    assert info.k.shape == (9,) and info.p.shape == (12,) and info.d.shape == (0,)
    assert msgs.JointState().name == []


def test_defaults_are_fresh_objects() -> None:
    a, b = msgs.PoseWithCovariance(), msgs.PoseWithCovariance()
    a.covariance[0] = 5.0
    a.pose.position.x = 1.0
    assert b.covariance[0] == 0.0 and b.pose.position.x == 0.0


def test_keyword_fields_and_nested_forms() -> None:
    vec = msgs.Vector3(x=0.2, y=1, z=-3)
    assert (vec.x, vec.y, vec.z) == (0.2, 1.0, -3.0)
    assert isinstance(vec.y, float)
    twist = msgs.Twist(linear={"x": 0.2}, angular=msgs.Vector3(z=0.5))
    assert (twist.linear.x, twist.linear.y, twist.angular.z) == (0.2, 0.0, 0.5)
    path = msgs.Path(poses=[{"pose": {"position": {"x": 1.0}}}, msgs.PoseStamped()])
    assert path.poses[0].pose.position.x == 1.0
    assert isinstance(path.poses[1], msgs.PoseStamped)


def test_flattened_names() -> None:
    twist = msgs.Twist(linear_x=0.2, angular_z=0.5)
    assert (twist.linear.x, twist.angular.z) == (0.2, 0.5)
    ps = msgs.PoseStamped(header_frame_id="map", pose_position_x=1.0, header_stamp_sec=7)
    assert ps.header.frame_id == "map"
    assert ps.pose.position.x == 1.0
    assert ps.header.stamp.sec == 7
    odom = msgs.Odometry(child_frame_id="base_link", pose_pose_position_y=2.0)
    assert odom.child_frame_id == "base_link"  # exact field name wins over flattening
    assert odom.pose.pose.position.y == 2.0
    info = msgs.CameraInfo(roi_x_offset=3, roi_do_rectify=True)
    assert info.roi.x_offset == 3 and info.roi.do_rectify is True


def test_flattened_names_merge_with_nested_value() -> None:
    twist = msgs.Twist(linear={"x": 1.0}, linear_y=2.0)
    assert (twist.linear.x, twist.linear.y) == (1.0, 2.0)
    twist = msgs.Twist(linear=msgs.Vector3(x=1.0, z=3.0), linear_y=2.0)
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == (1.0, 2.0, 3.0)


def test_isinstance_and_factory_attributes() -> None:
    twist = msgs.Twist()
    assert isinstance(twist, msgs.Twist)
    assert not isinstance(twist, msgs.Vector3)
    assert not isinstance(msgs.Vector3(), msgs.Twist)
    assert msgs.Twist.typename == "geometry_msgs/msg/Twist"
    assert msgs.Twist.cls.__name__ == "geometry_msgs__msg__Twist"
    assert msgs.Twist.fields == ("linear", "angular")
    assert "geometry_msgs/msg/Twist" in repr(msgs.Twist)


def test_constants_on_factories() -> None:
    assert msgs.Marker.ARROW == 0
    assert msgs.Marker.DELETEALL == 3
    assert msgs.GoalStatus.STATUS_SUCCEEDED == 4
    assert msgs.PointField.FLOAT32 == 7
    assert "ARROW" in dir(msgs.Marker)
    with pytest.raises(AttributeError, match="NOPE"):
        _ = msgs.Marker.NOPE


def test_sequences_become_numpy_arrays_of_field_dtype() -> None:
    scan = msgs.LaserScan(ranges=[1, 2], intensities=(0.5,))
    assert scan.ranges.dtype == np.float32 and scan.ranges.tolist() == [1.0, 2.0]
    assert scan.intensities.dtype == np.float32
    f64 = np.array([1.0, 2.0])
    assert msgs.LaserScan(ranges=f64).ranges.dtype == np.float32
    exact = np.array([1.0, 2.0], dtype=np.float32)
    assert msgs.LaserScan(ranges=exact).ranges is exact  # no copy for the exact dtype
    img = msgs.Image(data=b"\x01\x02\xff")
    assert img.data.dtype == np.uint8 and img.data.tolist() == [1, 2, 255]
    grid = msgs.OccupancyGrid(data=[-1, 0, 100])
    assert grid.data.dtype == np.int8
    joint = msgs.JointState(name=["a", "b"], position=[0.1, 0.2])
    assert joint.name == ["a", "b"] and joint.position.dtype == np.float64


def test_unknown_field_error_names_field_and_type() -> None:
    with pytest.raises(FieldError, match="'Twist' has no field 'linaer'") as info:
        msgs.Twist(linaer=0.2)
    assert "did you mean 'linear'" in str(info.value)
    assert "\n" not in str(info.value)
    with pytest.raises(FieldError, match="'Twist' has no field 'linear_w'"):
        msgs.Twist(linear_w=1.0)
    with pytest.raises(FieldError, match=r"'Twist' has no field 'linear\.w'"):
        msgs.Twist(linear={"w": 1.0})
    assert issubclass(FieldError, MessageError) and issubclass(MessageError, RoverlabError)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"linear_x": "fast"}, r"'Twist' field 'linear\.x': expected a number"),
        ({"linear_x": True}, r"'linear\.x': expected a number"),
        ({"linear": 3.0}, r"'linear': expected a geometry_msgs/msg/Vector3 message"),
        ({"linear": msgs.Point()}, r"'linear': expected a geometry_msgs/msg/Vector3"),
        ({"angular": {"z": {"a": 1}}}, r"'angular\.z': expected a number"),
    ],
)
def test_wrong_value_kind(kwargs: dict[str, object], match: str) -> None:
    with pytest.raises(MessageValueError, match=match):
        msgs.Twist(**kwargs)


def test_value_checks_for_ints_arrays_and_strings() -> None:
    with pytest.raises(MessageValueError, match="out of range for int8"):
        msgs.GoalStatus(status=300)
    with pytest.raises(MessageValueError, match="expected an integer"):
        msgs.Int32(data=1.5)
    with pytest.raises(MessageValueError, match="exactly 36 values"):
        msgs.PoseWithCovariance(covariance=[0.0] * 35)
    with pytest.raises(MessageValueError, match=r"'ranges\[1\]'"):
        msgs.LaserScan(ranges=[1.0, "x"])
    with pytest.raises(MessageValueError, match="1-D array"):
        msgs.LaserScan(ranges=np.zeros((2, 2)))
    with pytest.raises(MessageValueError, match="values out of range for uint8"):
        msgs.Image(data=np.array([256]))
    with pytest.raises(MessageValueError, match="expected a string"):
        msgs.Header(frame_id=5)
    with pytest.raises(MessageValueError, match="expected a bool"):
        msgs.Bool(data=1)
    with pytest.raises(MessageValueError, match="sequence of strings"):
        msgs.JointState(name="joint")


def test_make_and_get_factory_cover_the_whole_store() -> None:
    status = msgs.make("diagnostic_msgs/DiagnosticStatus", name="motor", level=2)
    assert status.name == "motor" and status.level == 2
    factory = msgs.get_factory("sensor_msgs.msg.Temperature")
    assert factory(temperature=21.5).temperature == 21.5
    assert msgs.get_factory(factory.cls) is factory
    with pytest.raises(msgs.UnknownTypeError):
        msgs.make("nav_msgs/NoSuchThing")


def test_factory_from_dict() -> None:
    twist = msgs.Twist.from_dict({"angular": {"z": 1.0}})
    assert twist.angular.z == 1.0
