"""``fake_localization``: map -> odom from the ground truth (with delta_x/y/yaw),
amcl_pose and particlecloud, transform_tolerance, waiting for odom's TF, launch files."""

from __future__ import annotations

import logging
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, Node, QoSProfile, Time
from roverlab.geometry import SE2, Transform3
from roverlab.launch import build_launch
from roverlab.localization.fake_localization import FakeLocalization
from roverlab.msgs import (
    Odometry,
    PoseWithCovarianceStamped,
    pose_from_xytheta,
    stamp_to_msg,
    xytheta_from_pose,
)
from roverlab.msgs import classes as mc
from roverlab.tf import TransformBroadcaster, transform_to_msg

TRUTH = SE2(2.0, -1.0, 0.6)
ODOM_FROM_MAP = SE2(0.4, 0.3, -0.25)  # where odometry's frame sits in the map


class Robot(Node):
    """odom -> base at 50 Hz (odometry drifted by ODOM_FROM_MAP^-1) and the ground truth
    at 20 Hz on ``topic``."""

    def __init__(self, ctx: Context, *, base: str = "base_link", topic: str = "gt",
                 tf: bool = True) -> None:  # fmt: skip
        super().__init__("robot", context=ctx)
        self.base, self.tf_on = base, tf
        self.tf = TransformBroadcaster(self)
        self.pub = self.create_publisher(mc.Odometry, topic, 10)
        self.create_timer(0.02, self._tf)
        self.create_timer(0.05, self._truth)

    def _tf(self) -> None:
        if self.tf_on:
            odom = ~ODOM_FROM_MAP * TRUTH
            self.tf.send_transform(transform_to_msg(
                "odom", self.base, self.get_clock().now(), Transform3.from_se2(odom)
            ))  # fmt: skip

    def _truth(self) -> None:
        self.pub.publish(Odometry(
            header={"frame_id": "world", "stamp": stamp_to_msg(self.get_clock().now())},
            child_frame_id=self.base,
            pose={"pose": pose_from_xytheta(TRUTH.x, TRUTH.y, TRUTH.theta)},
        ))  # fmt: skip


def _collect(ctx: Context) -> dict[str, list[Any]]:
    topics = {"/amcl_pose": mc.PoseWithCovarianceStamped, "/particlecloud": mc.PoseArray,
              "/tf": mc.TFMessage}  # fmt: skip
    got: dict[str, list[Any]] = {t: [] for t in topics}
    node = ctx.create_node("collector")
    for topic, typ in topics.items():
        node.create_subscription(typ, topic, got[topic].append, QoSProfile(depth=1000))
    return got


def _map_odom(got: dict[str, list[Any]]) -> list[Any]:
    return [t for m in got["/tf"] for t in m.transforms if t.header.frame_id == "map"]


def test_map_to_odom_pose_and_cloud_from_the_ground_truth() -> None:
    ctx = Context()
    Robot(ctx)
    node = FakeLocalization(
        ctx, remappings={"base_pose_ground_truth": "gt"},
        parameter_overrides={"transform_tolerance": 0.25},
    )  # fmt: skip
    got = _collect(ctx)
    ctx.spin_for(1.0)
    assert node.map_to_odom is not None
    est = node.map_to_odom.to_se2()
    assert np.allclose(est.as_array(), ODOM_FROM_MAP.as_array(), atol=1e-9)
    tfs = _map_odom(got)
    assert len(tfs) >= 15 and all(t.child_frame_id == "odom" for t in tfs)
    # stamped the ground truth's stamp + transform_tolerance
    assert abs(Time.from_msg(tfs[-1].header.stamp).seconds - (ctx.now().seconds + 0.25)) < 0.06
    pose = got["/amcl_pose"][-1]
    assert pose.header.frame_id == "map"
    assert np.allclose(xytheta_from_pose(pose.pose.pose), TRUTH.as_array(), atol=1e-9)
    assert not np.any(pose.pose.covariance)
    cloud = got["/particlecloud"][-1]
    assert cloud.header.frame_id == "map" and len(cloud.poses) == 1
    assert np.allclose(xytheta_from_pose(cloud.poses[0]), TRUTH.as_array(), atol=1e-9)


def test_delta_parameters_shift_the_ground_truth_as_ros() -> None:
    ctx = Context()
    Robot(ctx, base="base_footprint")
    node = FakeLocalization(ctx, remappings={"base_pose_ground_truth": "gt"},
                            parameter_overrides={"base_frame_id": "base_footprint",
                                                 "global_frame_id": "/world_map",
                                                 "delta_x": 1.0, "delta_y": -2.0,
                                                 "delta_yaw": 0.5})  # fmt: skip
    got = _collect(ctx)
    ctx.spin_for(0.5)
    shifted = SE2(-1.0, 2.0, -0.5) * TRUTH  # ROS: Transform(RPY(0,0,-dyaw), (-dx, -dy))
    pose = got["/amcl_pose"][-1]
    assert pose.header.frame_id == "world_map"
    assert np.allclose(xytheta_from_pose(pose.pose.pose), shifted.as_array(), atol=1e-9)
    assert node.map_to_odom is not None
    est = node.map_to_odom.to_se2() * (~ODOM_FROM_MAP * TRUTH)
    assert np.allclose(est.as_array(), shifted.as_array(), atol=1e-9)
    assert all(t.header.frame_id == "world_map" for t in got["/tf"][-1].transforms)


def test_waits_for_odometry_before_broadcasting() -> None:
    ctx = Context()
    robot = Robot(ctx, tf=False)
    node = FakeLocalization(ctx, remappings={"base_pose_ground_truth": "gt"})
    got = _collect(ctx)
    ctx.spin_for(0.5)
    assert node.map_to_odom is None and not got["/amcl_pose"] and not _map_odom(got)
    robot.tf_on = True
    ctx.spin_for(0.5)
    assert node.map_to_odom is not None and got["/amcl_pose"]
    assert math.isclose(node.map_to_odom.to_se2().x, ODOM_FROM_MAP.x, abs_tol=1e-9)


def test_from_a_launch_file_with_ros_parameters(tmp_path: Path) -> None:
    launch = tmp_path / "fake.launch"
    launch.write_text(
        '<launch><node pkg="fake_localization" type="fake_localization" '
        'name="fake_localization"><param name="odom_frame_id" value="odom"/>'
        '<param name="delta_x" value="0.5"/><param name="transform_tolerance" value="0.2"/>'
        '<remap from="base_pose_ground_truth" to="gt"/></node></launch>'
    )
    ctx = Context()
    Robot(ctx)
    result = build_launch(launch, context=ctx)
    (node,) = [n for n in result.nodes if isinstance(n, FakeLocalization)]
    assert node.transform_tolerance == 0.2
    ctx.spin_for(0.5)
    assert node.map_to_odom is not None
    assert math.isclose((node.map_to_odom.to_se2() * ~ODOM_FROM_MAP * TRUTH).x, TRUTH.x - 0.5,
                        abs_tol=1e-9)  # fmt: skip


def test_initialpose_moves_the_offset(caplog: pytest.LogCaptureFixture) -> None:
    ctx = Context()
    Robot(ctx)
    node = FakeLocalization(ctx, remappings={"base_pose_ground_truth": "gt"})
    got = _collect(ctx)
    ctx.spin_for(0.5)
    pub = ctx.create_node("rviz").create_publisher(mc.PoseWithCovarianceStamped, "initialpose", 1)
    given = SE2(-3.0, 4.0, 2.0)

    def estimate(frame: str) -> None:
        pub.publish(PoseWithCovarianceStamped(
            header={"frame_id": frame, "stamp": stamp_to_msg(ctx.now())},
            pose={"pose": pose_from_xytheta(given.x, given.y, given.theta)},
        ))  # fmt: skip
        ctx.spin_for(0.5)

    estimate("map")
    pose = got["/amcl_pose"][-1]
    assert np.allclose(xytheta_from_pose(pose.pose.pose), given.as_array(), atol=1e-6)
    assert node.map_to_odom is not None
    est = node.map_to_odom.to_se2() * (~ODOM_FROM_MAP * TRUTH)
    assert np.allclose(est.as_array(), given.as_array(), atol=1e-6)
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        estimate("odom")  # used all the same, with ROS's warning
    assert any('Frame ID of "initialpose" (odom) is different from the global frame map'
               in r.message for r in caplog.records)  # fmt: skip
    assert np.allclose(xytheta_from_pose(got["/amcl_pose"][-1].pose.pose), given.as_array(),
                       atol=1e-6)  # fmt: skip
