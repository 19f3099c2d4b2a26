"""Whole stamped messages built in one call, for publishers that run hundreds of times
per simulated second (the simulator's IMU, odometry, joint states and scans, TF).

Calling a rosbags message class runs its dataclass ``__init__`` through ``type.__call__``,
a C-to-Python call per object; an IMU message has six objects. These builders make the
same objects with ``object.__new__`` and plain attribute stores (one small helper per
header, point, vector or quaternion): fewer instructions for a message, and the very same result
(same classes, same instance dicts in the same order, ``__msgtype__`` included; the tests
compare each builder with the class constructors).

Arguments are the message's leaves in field order, flattened; arrays (covariances, joint
values, ranges) are stored as given, not copied.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

from . import classes as mc

__all__ = [
    "DeferredLaserScan",
    "imu",
    "joint_state",
    "laser_scan",
    "laser_scan_later",
    "odometry",
    "pose_stamped",
    "tf_message",
    "transform_stamped",
    "twist",
]

# typed loosely: the objects get their fields (and ``__msgtype__``) assigned one by one
_new: Callable[[type[Any]], Any] = object.__new__
_Time, _TIME = mc.Time, mc.Time.__msgtype__
_Header, _HEADER = mc.Header, mc.Header.__msgtype__
_Vector3, _VECTOR3 = mc.Vector3, mc.Vector3.__msgtype__
_Point, _POINT = mc.Point, mc.Point.__msgtype__
_Quaternion, _QUATERNION = mc.Quaternion, mc.Quaternion.__msgtype__
_Pose, _POSE = mc.Pose, mc.Pose.__msgtype__
_PoseStamped, _POSE_STAMPED = mc.PoseStamped, mc.PoseStamped.__msgtype__
_PoseCov, _POSE_COV = mc.PoseWithCovariance, mc.PoseWithCovariance.__msgtype__
_Twist, _TWIST = mc.Twist, mc.Twist.__msgtype__
_TwistCov, _TWIST_COV = mc.TwistWithCovariance, mc.TwistWithCovariance.__msgtype__
_Odometry, _ODOMETRY = mc.Odometry, mc.Odometry.__msgtype__
_Imu, _IMU = mc.Imu, mc.Imu.__msgtype__
_JointState, _JOINT_STATE = mc.JointState, mc.JointState.__msgtype__
_LaserScan, _LASER_SCAN = mc.LaserScan, mc.LaserScan.__msgtype__
_Transform, _TRANSFORM = mc.Transform, mc.Transform.__msgtype__
_TransformStamped, _TRANSFORM_STAMPED = mc.TransformStamped, mc.TransformStamped.__msgtype__
_TFMessage, _TF_MESSAGE = mc.TFMessage, mc.TFMessage.__msgtype__


def _header(sec: int, nanosec: int, frame_id: str) -> Any:
    t = _new(_Time)
    t.sec = sec
    t.nanosec = nanosec
    t.__msgtype__ = _TIME
    h = _new(_Header)
    h.stamp = t
    h.frame_id = frame_id
    h.__msgtype__ = _HEADER
    return h


def _xyz(cls: type[Any], msgtype: str, x: float, y: float, z: float) -> Any:
    v = _new(cls)
    v.x = x
    v.y = y
    v.z = z
    v.__msgtype__ = msgtype
    return v


def _vector3(x: float, y: float, z: float) -> Any:
    return _xyz(_Vector3, _VECTOR3, x, y, z)


def _point(x: float, y: float, z: float) -> Any:
    return _xyz(_Point, _POINT, x, y, z)


def _pose(position: Any, orientation: Any) -> Any:
    pose = _new(_Pose)
    pose.position = position
    pose.orientation = orientation
    pose.__msgtype__ = _POSE
    return pose


def _quaternion(x: float, y: float, z: float, w: float) -> Any:
    q = _new(_Quaternion)
    q.x = x
    q.y = y
    q.z = z
    q.w = w
    q.__msgtype__ = _QUATERNION
    return q


def imu(
    sec: int,
    nanosec: int,
    frame_id: str,
    qx: float,
    qy: float,
    qz: float,
    qw: float,
    orientation_covariance: Any,
    wx: float,
    wy: float,
    wz: float,
    angular_velocity_covariance: Any,
    ax: float,
    ay: float,
    az: float,
    linear_acceleration_covariance: Any,
) -> Any:
    """``sensor_msgs/Imu``: stamp, frame, orientation, rates, accelerations."""
    h = _header(sec, nanosec, frame_id)
    q = _quaternion(qx, qy, qz, qw)
    w = _vector3(wx, wy, wz)
    a = _vector3(ax, ay, az)
    m = _new(_Imu)
    m.header = h
    m.orientation = q
    m.orientation_covariance = orientation_covariance
    m.angular_velocity = w
    m.angular_velocity_covariance = angular_velocity_covariance
    m.linear_acceleration = a
    m.linear_acceleration_covariance = linear_acceleration_covariance
    m.__msgtype__ = _IMU
    return m


def odometry(
    sec: int,
    nanosec: int,
    frame_id: str,
    child_frame_id: str,
    x: float,
    y: float,
    z: float,
    qx: float,
    qy: float,
    qz: float,
    qw: float,
    pose_covariance: Any,
    vx: float,
    vy: float,
    vz: float,
    wx: float,
    wy: float,
    wz: float,
    twist_covariance: Any,
) -> Any:
    """``nav_msgs/Odometry``: stamp, frames, position, orientation, linear and angular
    velocity, with the two covariances."""
    h = _header(sec, nanosec, frame_id)
    pose = _pose(_point(x, y, z), _quaternion(qx, qy, qz, qw))
    pc = _new(_PoseCov)
    pc.pose = pose
    pc.covariance = pose_covariance
    pc.__msgtype__ = _POSE_COV
    tc = _new(_TwistCov)
    tc.twist = twist(vx, vy, vz, wx, wy, wz)
    tc.covariance = twist_covariance
    tc.__msgtype__ = _TWIST_COV
    m = _new(_Odometry)
    m.header = h
    m.child_frame_id = child_frame_id
    m.pose = pc
    m.twist = tc
    m.__msgtype__ = _ODOMETRY
    return m


def twist(vx: float, vy: float, vz: float, wx: float, wy: float, wz: float) -> Any:
    """``geometry_msgs/Twist``: linear and angular velocity (move_base's ``cmd_vel``)."""
    lin = _vector3(vx, vy, vz)
    ang = _vector3(wx, wy, wz)
    m = _new(_Twist)
    m.linear = lin
    m.angular = ang
    m.__msgtype__ = _TWIST
    return m


def pose_stamped(
    sec: int,
    nanosec: int,
    frame_id: str,
    x: float,
    y: float,
    z: float,
    qx: float,
    qy: float,
    qz: float,
    qw: float,
) -> Any:
    """``geometry_msgs/PoseStamped``: stamp, frame, position, orientation (move_base's
    feedback)."""
    h = _header(sec, nanosec, frame_id)
    pose = _pose(_point(x, y, z), _quaternion(qx, qy, qz, qw))
    m = _new(_PoseStamped)
    m.header = h
    m.pose = pose
    m.__msgtype__ = _POSE_STAMPED
    return m


def transform_stamped(
    sec: int,
    nanosec: int,
    frame_id: str,
    child_frame_id: str,
    x: float,
    y: float,
    z: float,
    qx: float,
    qy: float,
    qz: float,
    qw: float,
) -> Any:
    """``geometry_msgs/TransformStamped``: stamp, frames, translation, rotation."""
    h = _header(sec, nanosec, frame_id)
    v = _vector3(x, y, z)
    q = _quaternion(qx, qy, qz, qw)
    tr = _new(_Transform)
    tr.translation = v
    tr.rotation = q
    tr.__msgtype__ = _TRANSFORM
    m = _new(_TransformStamped)
    m.header = h
    m.child_frame_id = child_frame_id
    m.transform = tr
    m.__msgtype__ = _TRANSFORM_STAMPED
    return m


def tf_message(transforms: list[Any]) -> Any:
    """``tf2_msgs/TFMessage`` of ``transforms`` (the list itself is stored)."""
    m = _new(_TFMessage)
    m.transforms = transforms
    m.__msgtype__ = _TF_MESSAGE
    return m


def joint_state(
    sec: int,
    nanosec: int,
    frame_id: str,
    name: list[str],
    position: Any,
    velocity: Any,
    effort: Any,
) -> Any:
    """``sensor_msgs/JointState``: stamp, frame, names and the three value arrays."""
    h = _header(sec, nanosec, frame_id)
    m = _new(_JointState)
    m.header = h
    m.name = name
    m.position = position
    m.velocity = velocity
    m.effort = effort
    m.__msgtype__ = _JOINT_STATE
    return m


def laser_scan(
    sec: int,
    nanosec: int,
    frame_id: str,
    angle_min: float,
    angle_max: float,
    angle_increment: float,
    time_increment: float,
    scan_time: float,
    range_min: float,
    range_max: float,
    ranges: Any,
    intensities: Any,
) -> Any:
    """``sensor_msgs/LaserScan``: stamp, frame and the fields in ROS order."""
    return _fill_laser_scan(
        _new(_LaserScan), sec, nanosec, frame_id, angle_min, angle_max, angle_increment,
        time_increment, scan_time, range_min, range_max, "ranges", ranges, intensities,
    )  # fmt: skip


def _fill_laser_scan(
    m: Any,
    sec: int,
    nanosec: int,
    frame_id: str,
    angle_min: float,
    angle_max: float,
    angle_increment: float,
    time_increment: float,
    scan_time: float,
    range_min: float,
    range_max: float,
    ranges_key: str,
    ranges: Any,
    intensities: Any,
) -> Any:
    """Every field of a new LaserScan ``m`` in ROS order; ``ranges`` is stored under
    ``ranges_key`` (``_make`` for a :class:`DeferredLaserScan`'s function)."""
    m.header = _header(sec, nanosec, frame_id)
    m.angle_min = angle_min
    m.angle_max = angle_max
    m.angle_increment = angle_increment
    m.time_increment = time_increment
    m.scan_time = scan_time
    m.range_min = range_min
    m.range_max = range_max
    m.__dict__[ranges_key] = ranges
    m.intensities = intensities
    m.__msgtype__ = _LASER_SCAN
    return m


class DeferredLaserScan(_LaserScan):  # type: ignore[misc,valid-type]
    """A ``sensor_msgs/LaserScan`` whose ``ranges`` are made when first read (then kept):
    the simulated lidar publishes 50 scans a second and the costmaps read the few their
    updates use. Everything else is a LaserScan's: fields, ``__msgtype__``, serialisation;
    a copy or pickle is a plain LaserScan. Equality, as for any dataclass, needs the same
    class: compare fields (``ranges`` included), not the message.
    """

    @property
    def ranges(self) -> Any:
        d = self.__dict__
        make = d.get("_make")
        if make is None:
            return d["_ranges"]
        value = make()  # two threads may both make it: the same values, one kept
        d["_ranges"] = value
        d.pop("_make", None)
        return value

    @ranges.setter
    def ranges(self, value: Any) -> None:
        d = self.__dict__
        d["_ranges"] = value
        d.pop("_make", None)

    def __reduce__(self) -> tuple[Any, tuple[Any, ...]]:
        return _LaserScan, tuple(getattr(self, f.name) for f in dataclasses.fields(_LaserScan))


def laser_scan_later(
    sec: int,
    nanosec: int,
    frame_id: str,
    angle_min: float,
    angle_max: float,
    angle_increment: float,
    time_increment: float,
    scan_time: float,
    range_min: float,
    range_max: float,
    ranges: Callable[[], Any],
    intensities: Any,
) -> Any:
    """:func:`laser_scan` with ``ranges`` a function called when the field is first read
    (a :class:`DeferredLaserScan`)."""
    return _fill_laser_scan(
        _new(DeferredLaserScan), sec, nanosec, frame_id, angle_min, angle_max,
        angle_increment, time_increment, scan_time, range_min, range_max, "_make", ranges,
        intensities,
    )  # fmt: skip
