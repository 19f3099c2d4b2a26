"""robot_state_publisher and joint_state_publisher on the deterministic executor."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, ParameterError, Time
from roverlab.description import DescriptionError, load_robot
from roverlab.description.node import JointStatePublisher, RobotStatePublisher
from roverlab.msgs import Header, JointState, String
from roverlab.msgs.cdr import serialize
from roverlab.tf import Buffer, TransformListener
from tests.description.conftest import MYBOT_XACRO, MYCAR_XACRO, robot

ARM = robot(
    '<link name="base"/><link name="a"/><link name="b"/><link name="c"/>'
    '<joint name="lift" type="prismatic"><parent link="base"/><child link="a"/>'
    '<axis xyz="0 0 1"/><limit lower="0.5" upper="1.5" effort="1" velocity="1"/></joint>'
    '<joint name="spin" type="continuous"><parent link="a"/><child link="b"/>'
    '<axis xyz="0 0 1"/></joint>'
    '<joint name="twin" type="continuous"><parent link="a"/><child link="c"/>'
    '<axis xyz="0 0 1"/><mimic joint="spin" multiplier="2"/></joint>',
    "arm",
)


def lookup(buffer: Buffer, target: str, source: str) -> Any:
    transform, _ = buffer.lookup_transform(target, source, Time(0))
    return transform


def listener(ctx: Context) -> Buffer:
    buffer = Buffer()
    TransformListener(buffer, ctx.create_node("tf_listener"))
    return buffer


def wheel_states(ctx: Context, positions: dict[str, float], rate_hz: float = 10.0) -> None:
    node = ctx.create_node("fake_driver")
    pub = node.create_publisher(JointState, "/joint_states", 10)

    def tick() -> None:
        pub.publish(
            JointState(
                header=Header(stamp=node.get_clock().now().to_msg()),
                name=list(positions),
                position=list(positions.values()),
            )
        )

    node.create_timer(1.0 / rate_hz, tick)


def test_static_and_dynamic_transforms() -> None:
    ctx = Context()
    rsp = RobotStatePublisher(ctx, robot_description=str(MYBOT_XACRO))
    buffer = listener(ctx)
    q = {"left_wheel_joint": math.pi / 2, "right_wheel_joint": -0.3}
    wheel_states(ctx, q)
    ctx.spin_for(1.0)

    laser = lookup(buffer, "base_footprint", "base_laser_link")
    assert laser.translation == pytest.approx((0.0, 0.0, 0.06))
    camera = lookup(buffer, "base_link", "base_camera_link")
    assert camera.translation == pytest.approx((0.1, 0.0, 0.025))

    model = rsp.model
    for joint_name, position in q.items():
        joint = model.joints[joint_name]
        got = lookup(buffer, joint.parent, joint.child)
        want = joint.transform(position)
        assert np.allclose(got.translation, want.translation)
        assert np.allclose(got.rotation, want.rotation) or np.allclose(
            got.rotation, -np.asarray(want.rotation)
        )
    whole = lookup(buffer, "base_footprint", "left_wheel_link")
    want = model.link_transform("left_wheel_link", q)
    assert np.allclose(whole.translation, want.translation)
    ctx.shutdown()


def test_fixed_joints_go_to_tf_static_and_movable_to_tf() -> None:
    ctx = Context()
    seen: dict[str, set[str]] = {"/tf": set(), "/tf_static": set()}
    probe = ctx.create_node("probe")

    def recorder(topic: str) -> Callable[[Any], None]:
        return lambda msg: seen[topic].update(x.child_frame_id for x in msg.transforms)

    for topic in seen:
        probe.create_subscription("tf2_msgs/msg/TFMessage", topic, recorder(topic), 100)
    RobotStatePublisher(ctx, robot_description=str(MYBOT_XACRO))
    wheel_states(ctx, {"left_wheel_joint": 0.0, "right_wheel_joint": 0.0})
    ctx.spin_for(0.5)
    assert seen["/tf_static"] == {
        "base_link",
        "ball_wheel_link",
        "imu",
        "base_camera_link",
        "base_laser_link",
    }
    assert seen["/tf"] == {"left_wheel_link", "right_wheel_link"}
    ctx.shutdown()


def test_robot_description_is_latched_and_frame_prefix_applies() -> None:
    ctx = Context()
    model = load_robot(MYBOT_XACRO)
    RobotStatePublisher(ctx, robot_description=model, parameter_overrides={"frame_prefix": "r1/"})
    buffer = listener(ctx)
    got: list[str] = []
    ctx.spin_for(0.2)
    late = ctx.create_node("late")
    late.create_subscription(String, "/robot_description", lambda m: got.append(m.data), 1)
    ctx.spin_for(0.2)
    assert got == [model.urdf]
    assert lookup(buffer, "r1/base_footprint", "r1/base_laser_link").translation == (
        pytest.approx((0.0, 0.0, 0.06))
    )
    ctx.shutdown()


def test_ros1_tf_prefix_prefixes_frames_and_an_empty_one_is_used_quietly() -> None:
    # turtlebot3_remote.launch sets tf_prefix (empty unless multi-robot): it used to be
    # reported as a parameter roverlab's robot_state_publisher does not use
    ctx = Context()
    model = load_robot(MYBOT_XACRO)
    quiet = RobotStatePublisher(
        ctx, robot_description=model, parameter_overrides={"tf_prefix": ""}, node_name="a"
    )
    assert quiet.unused_parameter_overrides() == [] and quiet.frame_prefix == ""
    RobotStatePublisher(
        ctx, robot_description=model, parameter_overrides={"tf_prefix": "/tb3_0"}, node_name="b"
    )
    buffer = listener(ctx)
    ctx.spin_for(0.2)
    assert lookup(buffer, "tb3_0/base_footprint", "tb3_0/base_laser_link").translation == (
        pytest.approx((0.0, 0.0, 0.06))
    )
    ctx.shutdown()


def _count_tf(ctx: Context) -> list[int]:
    counts = [0]

    def on_tf(msg: Any) -> None:
        counts[0] += 1

    ctx.create_node("tf_counter").create_subscription("tf2_msgs/msg/TFMessage", "/tf", on_tf, 100)
    return counts


def test_publish_frequency_throttles_per_joint() -> None:
    ctx = Context()
    RobotStatePublisher(ctx, robot_description=ARM, parameter_overrides={"publish_frequency": 2.0})
    counts = _count_tf(ctx)
    wheel_states(ctx, {"spin": 0.1}, rate_hz=20.0)
    ctx.spin_for(2.0)
    assert 3 <= counts[0] <= 5  # ~2 Hz of the 20 Hz input


def test_ignore_timestamp_publishes_every_message() -> None:
    ctx = Context()
    RobotStatePublisher(
        ctx,
        robot_description=ARM,
        parameter_overrides={"publish_frequency": 2.0, "ignore_timestamp": True},
    )
    counts = _count_tf(ctx)
    wheel_states(ctx, {"spin": 0.1}, rate_hz=20.0)
    ctx.spin_for(1.0)
    assert counts[0] >= 19


def test_mimic_joints_follow_in_tf() -> None:
    ctx = Context()
    RobotStatePublisher(ctx, robot_description=ARM)
    buffer = listener(ctx)
    wheel_states(ctx, {"lift": 1.0, "spin": 0.25, "twin": 3.0})
    ctx.spin_for(0.5)
    assert lookup(buffer, "base", "a").translation == pytest.approx((0.0, 0.0, 1.0))
    assert lookup(buffer, "a", "c").yaw == pytest.approx(0.5)
    ctx.shutdown()


def test_description_from_parameter_and_errors() -> None:
    ctx = Context()
    rsp = RobotStatePublisher(ctx, parameter_overrides={"robot_description": ARM})
    assert rsp.model.name == "arm"
    assert rsp.get_parameter("robot_description").value == ARM
    with pytest.raises(DescriptionError, match="no robot description"):
        RobotStatePublisher(ctx, node_name="rsp2")
    with pytest.raises(ParameterError, match="publish_frequency"):
        RobotStatePublisher(
            ctx,
            node_name="rsp3",
            robot_description=ARM,
            parameter_overrides={"publish_frequency": -1.0},
        )
    ctx.shutdown()


def test_joint_state_publisher_defaults_and_sources() -> None:
    ctx = Context()
    jsp = JointStatePublisher(
        ctx, robot_description=ARM, parameter_overrides={"source_list": ["/sim/joints"]}
    )
    got: list[Any] = []
    ctx.create_node("sink").create_subscription(JointState, "/joint_states", got.append, 100)
    ctx.spin_for(1.0)
    assert 9 <= len(got) <= 11  # 10 Hz
    first = got[-1]
    assert list(first.name) == ["lift", "spin", "twin"]
    assert list(first.position) == [1.0, 0.0, 0.0]  # lift: middle of [0.5, 1.5]
    assert len(first.velocity) == 0

    source = ctx.create_node("sim").create_publisher(JointState, "/sim/joints", 10)
    source.publish(JointState(name=["spin", "unknown"], position=[0.4, 9.0], velocity=[1.0, 2.0]))
    ctx.spin_for(0.3)
    last = got[-1]
    assert list(last.position) == pytest.approx([1.0, 0.4, 0.8])
    assert list(last.velocity) == pytest.approx([0.0, 1.0, 0.0])
    assert jsp.positions() == pytest.approx({"lift": 1.0, "spin": 0.4, "twin": 0.8})
    # the builder-made message is the factory-made one (values, dtypes, bytes)
    fast = jsp.message()
    names = [j.name for j in jsp.joints]
    plain = JointState(
        header=Header(stamp=ctx.now().to_msg()),
        name=names,
        position=[jsp.positions()[n] for n in names],
        velocity=[jsp._velocities.get(n, 0.0) for n in names],
        effort=[],
    )
    assert serialize(fast) == serialize(plain)
    for field in ("position", "velocity", "effort"):
        assert getattr(fast, field).dtype == getattr(plain, field).dtype == np.float64
    ctx.shutdown()


def test_joint_state_publisher_rate_parameter() -> None:
    ctx = Context()
    JointStatePublisher(ctx, robot_description=ARM, parameter_overrides={"rate": 50})
    got: list[Any] = []
    ctx.create_node("sink").create_subscription(JointState, "/joint_states", got.append, 100)
    ctx.spin_for(1.0)
    assert 49 <= len(got) <= 51
    with pytest.raises(ParameterError, match="rate must be > 0"):
        JointStatePublisher(
            ctx, node_name="jsp2", robot_description=ARM, parameter_overrides={"rate": 0.0}
        )
    ctx.shutdown()


def test_both_nodes_give_the_whole_mycar_tree() -> None:
    ctx = Context()
    JointStatePublisher(ctx, robot_description=str(MYCAR_XACRO))
    RobotStatePublisher(
        ctx, robot_description=str(MYCAR_XACRO), parameter_overrides={"publish_frequency": 50.0}
    )
    buffer = listener(ctx)
    ctx.spin_for(1.0)
    assert lookup(buffer, "base_footprint", "laser").translation == pytest.approx((0, 0, 0.27))
    assert lookup(buffer, "base_footprint", "left_wheel").translation == pytest.approx(
        (0.0, 0.1, 0.0325)
    )
    assert lookup(buffer, "base_footprint", "front_wheel").translation == pytest.approx(
        (0.0925, 0.0, 0.0075)
    )
    ctx.shutdown()
