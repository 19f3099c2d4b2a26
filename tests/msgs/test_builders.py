"""The one-call message builders make exactly what the message classes make."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from roverlab.msgs import builders as build
from roverlab.msgs import classes as mc
from roverlab.msgs import serialize


def _same(built: Any, reference: Any) -> None:
    """Equal, of the same classes, with the same instance dicts (keys in the same order)
    all the way down, and the same bytes."""
    assert type(built) is type(reference)
    assert list(vars(built)) == list(vars(reference))
    for f in dataclasses.fields(reference):
        value, got = getattr(reference, f.name), getattr(built, f.name)
        if dataclasses.is_dataclass(value):
            _same(got, value)
        elif isinstance(value, np.ndarray):
            assert got is value  # stored as given, not copied
        else:
            assert type(got) is type(value) and got == value
    assert serialize(built) == serialize(reference)


def test_imu() -> None:
    cov = np.arange(9.0)
    ref = mc.Imu(
        mc.Header(mc.Time(3, 4), "imu"),
        mc.Quaternion(0.1, 0.2, 0.3, 0.9),
        cov,
        mc.Vector3(1.0, 2.0, 3.0),
        cov,
        mc.Vector3(4.0, 5.0, 6.0),
        cov,
    )
    got = build.imu(3, 4, "imu", 0.1, 0.2, 0.3, 0.9, cov, 1.0, 2.0, 3.0, cov, 4.0, 5.0, 6.0, cov)
    _same(got, ref)


def test_odometry() -> None:
    pc, tc = np.arange(36.0), np.arange(36.0) * 2
    ref = mc.Odometry(
        mc.Header(mc.Time(5, 6), "odom"),
        "base",
        mc.PoseWithCovariance(
            mc.Pose(mc.Point(1.0, 2.0, 3.0), mc.Quaternion(0.1, 0.2, 0.3, 0.9)), pc
        ),
        mc.TwistWithCovariance(mc.Twist(mc.Vector3(4.0, 5.0, 6.0), mc.Vector3(7.0, 8.0, 9.0)), tc),
    )
    got = build.odometry(
        5, 6, "odom", "base", 1.0, 2.0, 3.0, 0.1, 0.2, 0.3, 0.9, pc,
        4.0, 5.0, 6.0, 7.0, 8.0, 9.0, tc,
    )  # fmt: skip
    _same(got, ref)


def test_transforms() -> None:
    ref = mc.TransformStamped(
        mc.Header(mc.Time(7, 8), "odom"),
        "base",
        mc.Transform(mc.Vector3(1.0, 2.0, 3.0), mc.Quaternion(0.1, 0.2, 0.3, 0.9)),
    )
    got = build.transform_stamped(7, 8, "odom", "base", 1.0, 2.0, 3.0, 0.1, 0.2, 0.3, 0.9)
    _same(got, ref)
    _same(build.tf_message([got]), mc.TFMessage([ref]))


def test_twist_and_pose_stamped() -> None:
    _same(build.twist(1.0, 2.0, 3.0, 4.0, 5.0, 6.0),
          mc.Twist(mc.Vector3(1.0, 2.0, 3.0), mc.Vector3(4.0, 5.0, 6.0)))  # fmt: skip
    ref = mc.PoseStamped(
        mc.Header(mc.Time(9, 10), "map"),
        mc.Pose(mc.Point(1.0, 2.0, 0.0), mc.Quaternion(0.0, 0.0, 0.3, 0.9)),
    )
    _same(build.pose_stamped(9, 10, "map", 1.0, 2.0, 0.0, 0.0, 0.0, 0.3, 0.9), ref)


def test_joint_state_and_laser_scan() -> None:
    pos, vel, eff = np.arange(2.0), np.arange(2.0) + 2, np.zeros(2)
    ref = mc.JointState(mc.Header(mc.Time(1, 2), ""), ["l", "r"], pos, vel, eff)
    _same(build.joint_state(1, 2, "", ["l", "r"], pos, vel, eff), ref)
    ranges = np.arange(10, dtype=np.float32)
    empty = np.zeros(0, dtype=np.float32)
    ref_scan = mc.LaserScan(
        mc.Header(mc.Time(1, 2), "laser"), -1.0, 1.0, 0.2, 0.0, 0.1, 0.05, 12.0, ranges, empty
    )
    got = build.laser_scan(1, 2, "laser", -1.0, 1.0, 0.2, 0.0, 0.1, 0.05, 12.0, ranges, empty)
    _same(got, ref_scan)


def test_a_deferred_laser_scan_is_the_laser_scan_once_read() -> None:
    """``laser_scan_later``: ``ranges`` made on first read (once), then a LaserScan in
    every way but its class: fields, bytes (CDR and ROS 1), a copy or pickle is plain."""
    import copy
    import pickle

    from roverlab.msgs.ros1 import serialize_ros1

    ranges = np.arange(10, dtype=np.float32)
    empty = np.zeros(0, dtype=np.float32)
    calls: list[int] = []

    def make() -> Any:
        calls.append(1)
        return ranges

    args = (1, 2, "laser", -1.0, 1.0, 0.2, 0.0, 0.1, 0.05, 12.0)
    got = build.laser_scan_later(*args, make, empty)
    ref = build.laser_scan(*args, ranges, empty)
    assert not calls and isinstance(got, mc.LaserScan) and got.__msgtype__ == ref.__msgtype__
    assert got.ranges is ranges and got.ranges is ranges and len(calls) == 1
    for f in dataclasses.fields(ref):
        assert getattr(got, f.name) is getattr(ref, f.name) or (
            getattr(got, f.name) == getattr(ref, f.name)
        )
    assert serialize(got) == serialize(ref)
    assert serialize_ros1(got) == serialize_ros1(ref)
    for twin in (copy.copy(got), pickle.loads(pickle.dumps(got))):
        assert type(twin) is mc.LaserScan and serialize(twin) == serialize(ref)
    unread = build.laser_scan_later(*args, make, empty)
    assert serialize(pickle.loads(pickle.dumps(unread))) == serialize(ref)
    unread.ranges = np.zeros(3, dtype=np.float32)  # a reader may replace the field
    assert list(unread.ranges) == [0.0, 0.0, 0.0] and len(calls) == 2
