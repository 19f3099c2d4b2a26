"""A holonomic base (libgazebo_ros_planar_move.so) in the simulator: sideways motion at
the commanded body twist, odometry as the plugin publishes it, its transform, the command
timeout, wall contacts, absurd commands, and the IMU of a strafing, turning body."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.description import load_robot
from roverlab.msgs import Twist, time_to_ns
from roverlab.sim.app import Simulation
from roverlab.sim.collision import circle_polygon, inner_radius
from roverlab.sim.dynamics import (
    DRIVE_HOLONOMIC,
    S_CONTACT,
    S_CVX,
    S_CVY,
    S_CW,
    S_TH,
    S_VY,
    S_X,
    S_Y,
    STATE_SIZE,
    PhysicsPack,
    advance,
    advance_packed,
)
from roverlab.sim.node import SpawnPose
from roverlab.world.yaml_world import world_from_dict
from tests.helpers.nodes import collect

_EMPTY = world_from_dict({"name": "empty"}, source=Path("empty.yaml"))
# a wall along y = 1 (its face towards the robot at y = 0.95)
_WALL = world_from_dict(
    {"name": "wall", "walls": [{"points": [[-3, 1], [3, 1]], "height": 1.0}]},
    source=Path("wall.yaml"),
)


def _omni(plugin: str = "", extra: str = "") -> Any:
    """A 0.4 m square omni-wheel base with a planar move plugin (and ``extra`` gazebo)."""
    return load_robot(
        '<robot name="omni"><link name="base_footprint"/><link name="base_link">'
        '<collision><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>'
        '<joint name="base_joint" type="fixed"><parent link="base_footprint"/>'
        '<child link="base_link"/><origin xyz="0 0 0.1"/></joint>'
        f'<gazebo><plugin name="omni" filename="libgazebo_ros_planar_move.so">{plugin}'
        f"</plugin>{extra}</gazebo></robot>"
    )


def _drive(ctx: Context, **twist: float) -> Any:
    pub = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1)
    pub.publish(Twist(**twist))
    return pub


def test_linear_y_moves_the_body_sideways_by_the_commanded_distance() -> None:
    ctx = Context()
    yaw = 0.5
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni(), spawn=SpawnPose(1.0, -1.0, yaw))
    _drive(ctx, linear_y=0.25)
    ctx.spin_for(2.0)
    s = sim.simulator
    # 0.5 m to the body's left, heading unchanged
    assert s.x == pytest.approx(1.0 - 0.5 * math.sin(yaw), abs=1e-9)
    assert s.y == pytest.approx(-1.0 + 0.5 * math.cos(yaw), abs=1e-9)
    assert s.yaw == pytest.approx(yaw, abs=1e-12)
    assert (s.v, s.vy, s.w) == pytest.approx((0.0, 0.25, 0.0))


def test_a_body_twist_is_followed_exactly_while_turning() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni())
    vx, vy, w, t = 0.3, 0.2, 0.5, 2.0
    _drive(ctx, linear_x=vx, linear_y=vy, angular_z=w)
    ctx.spin_for(t)
    th = w * t  # the integral of R(w s) (vx, vy) over [0, t]
    x = (vx * math.sin(th) + vy * (math.cos(th) - 1.0)) / w
    y = (vy * math.sin(th) - vx * (math.cos(th) - 1.0)) / w
    s = sim.simulator
    assert (s.x, s.y, s.yaw) == pytest.approx((x, y, th), abs=1e-9)


def test_odometry_is_the_true_pose_with_base_frame_velocities() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni(), spawn=SpawnPose(0.5, 0.5, 1.0))
    got = collect(
        ctx, {"/odom": "nav_msgs/msg/Odometry", "/ground_truth/state": "nav_msgs/msg/Odometry"}
    )
    _drive(ctx, linear_x=0.1, linear_y=-0.3, angular_z=0.4)
    ctx.spin_for(2.0)
    odom = got["/odom"]
    assert len(odom) == 40  # odometryRate defaults to 20 Hz
    assert (odom[-1].header.frame_id, odom[-1].child_frame_id) == ("odom", "base_footprint")
    truth = {time_to_ns(m.header.stamp): m.pose.pose for m in got["/ground_truth/state"]}
    stamps = [time_to_ns(m.header.stamp) for m in odom]
    pairs = [(m.pose.pose, truth[t]) for m, t in zip(odom, stamps, strict=True) if t in truth]
    assert len(pairs) == 20  # every 0.1 s both publish
    for o, g in pairs:
        assert (o.position.x, o.position.y) == (g.position.x, g.position.y)
        assert (o.orientation.z, o.orientation.w) == (g.orientation.z, g.orientation.w)
    s = sim.simulator
    last = odom[-1].pose.pose
    assert (last.position.x, last.position.y) == (s.x, s.y)
    # the plugin's velocity: the pose's change over the last 0.05 s, in the base frame
    twist = odom[-1].twist.twist
    assert (twist.linear.x, twist.linear.y) == pytest.approx((0.1, -0.3), abs=0.01)
    assert twist.angular.z == pytest.approx(0.4, abs=1e-9)
    assert odom[-1].pose.covariance[0] == 1e-5 and not odom[-1].twist.covariance.any()


def test_ground_truth_twist_is_the_world_velocity_as_p3d() -> None:
    """Strafing while turning: the ground truth's twist is the world-frame velocity (as
    gazebo_ros_p3d's), the central difference of its poses."""
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=_omni(), spawn=SpawnPose(0.5, 0.5, 1.0))
    got = collect(ctx, {"/ground_truth/state": "nav_msgs/msg/Odometry"})
    _drive(ctx, linear_x=0.1, linear_y=-0.3, angular_z=0.8)
    ctx.spin_for(3.0)
    msgs = got["/ground_truth/state"][2:]
    for before, m, after in zip(msgs, msgs[1:], msgs[2:], strict=False):
        dt = (time_to_ns(after.header.stamp) - time_to_ns(before.header.stamp)) / 1e9
        p, q = before.pose.pose.position, after.pose.pose.position
        t = m.twist.twist
        assert (t.linear.x, t.linear.y) == pytest.approx(
            ((q.x - p.x) / dt, (q.y - p.y) / dt), abs=1e-4
        )
        assert t.angular.z == pytest.approx(0.8, abs=1e-9)


def _odom_tf_pairs(plugin: str) -> set[tuple[str, str]]:
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=_omni(plugin))
    got = collect(ctx, {"/tf": "tf2_msgs/msg/TFMessage"})
    _drive(ctx, linear_y=0.2)
    ctx.spin_for(0.5)
    return {(t.header.frame_id, t.child_frame_id) for m in got["/tf"] for t in m.transforms}


def test_the_odom_transform_is_broadcast_unless_switched_off() -> None:
    # noetic's plugin always broadcasts it; publishOdometryTf false is roverlab's switch
    assert ("odom", "base_footprint") in _odom_tf_pairs("")
    named = "<odometryFrame>map</odometryFrame><robotBaseFrame>base_link</robotBaseFrame>"
    assert ("map", "base_link") in _odom_tf_pairs(named)
    off = _odom_tf_pairs("<publishOdometryTf>false</publishOdometryTf>")
    assert ("odom", "base_footprint") not in off


def test_no_odometry_at_rate_zero() -> None:
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=_omni("<odometryRate>0</odometryRate>"))
    got = collect(ctx, {"/odom": "nav_msgs/msg/Odometry", "/tf": "tf2_msgs/msg/TFMessage"})
    ctx.spin_for(1.0)
    assert got["/odom"] == []
    assert not [t for m in got["/tf"] for t in m.transforms if t.header.frame_id == "odom"]


def test_cmd_timeout_stops_the_body_and_a_new_command_restarts_it() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni("<cmdTimeout>0.5</cmdTimeout>"))
    pub = _drive(ctx, linear_x=0.4)
    ctx.spin_for(1.0)
    assert sim.simulator.x == pytest.approx(0.2, abs=1e-9)  # 0.5 s at 0.4 m/s
    assert sim.simulator.v == 0.0
    pub.publish(Twist(linear_x=0.4))
    ctx.spin_for(0.3)
    pub.publish(Twist(linear_x=0.4))  # before the deadline: it moves it on
    ctx.spin_for(1.7)
    assert sim.simulator.x == pytest.approx(0.2 + 0.4 * 0.8, abs=1e-9)


def _pending_with_a_command_stream(plugin: str) -> tuple[int, float]:
    """Commands at 100 Hz for 2 s: the executor's queued events after them, and x."""
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni(plugin))
    pub = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1)
    for _ in range(200):
        pub.publish(Twist(linear_x=0.4))
        ctx.spin_for(0.01)
    return ctx.executor.pending(), sim.simulator.x


def test_a_command_stream_keeps_one_timeout_pending() -> None:
    """Each command moves the deadline; it does not queue an expiry of its own (a 1 s
    timeout at 100 Hz would hold 100 of them)."""
    without, x0 = _pending_with_a_command_stream("")
    with_timeout, x1 = _pending_with_a_command_stream("<cmdTimeout>1.0</cmdTimeout>")
    assert with_timeout == without + 1
    assert x1 == x0 == pytest.approx(0.8, abs=1e-9)  # never timed out


def test_a_teleport_leaves_no_stale_command_odometry_or_timeout() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni("<cmdTimeout>0.5</cmdTimeout>"))
    got = collect(ctx, {"/odom": "nav_msgs/msg/Odometry"})
    pub = _drive(ctx, linear_x=0.4)
    ctx.spin_for(0.32)
    s = sim.simulator
    s.teleport(3.0, -2.0, 1.0)
    ctx.spin_for(0.3)
    assert (s.x, s.y, s.yaw) == (3.0, -2.0, pytest.approx(1.0))  # at rest
    after = [m for m in got["/odom"] if time_to_ns(m.header.stamp) > 320_000_000]
    assert after and all(
        (m.twist.twist.linear.x, m.twist.twist.linear.y, m.twist.twist.angular.z) == (0, 0, 0)
        for m in after
    )  # not the jump over the message's period
    # a command after the teleport gets a timeout of its own, 0.5 s after it
    pub.publish(Twist(linear_x=0.4))
    ctx.spin_for(1.0)
    assert (s.x, s.y) == pytest.approx((3.0 + 0.2 * math.cos(1.0), -2.0 + 0.2 * math.sin(1.0)))


def test_without_cmd_timeout_the_last_command_holds() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni())
    _drive(ctx, linear_x=0.4)
    ctx.spin_for(3.0)
    assert sim.simulator.x == pytest.approx(1.2, abs=1e-9)


def test_a_wall_stops_the_sideways_motion() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_WALL, robot=_omni())
    got = collect(ctx, {"/odom": "nav_msgs/msg/Odometry"})
    pub = _drive(ctx, linear_y=0.5)
    ctx.spin_for(4.0)
    s = sim.simulator
    # the box's edge (0.2 m from its centre) at the wall's face
    assert s.y == pytest.approx(0.95 - 0.2, abs=1e-3) and s.y < 0.75
    assert s.x == pytest.approx(0.0, abs=1e-12) and s.yaw == 0.0
    assert s.contact and s.contacts == 1
    assert s.vy == pytest.approx(0.0, abs=1e-6)
    assert got["/odom"][-1].twist.twist.linear.y == pytest.approx(0.0, abs=1e-6)
    # it can still move away from the wall and along it
    pub.publish(Twist(linear_x=0.3, linear_y=-0.1))
    ctx.spin_for(1.0)
    assert (s.x, s.y) == pytest.approx((0.3, 0.75 - 0.1), abs=2e-3)


def test_nan_and_huge_commands_are_contained() -> None:
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=_omni())
    pub = _drive(ctx, linear_y=float("nan"), linear_x=0.1)
    ctx.spin_for(1.0)
    s = sim.simulator
    assert (s.x, s.y, s.yaw) == (0.0, 0.0, 0.0)  # ignored, as the diff drive does
    pub.publish(Twist(linear_x=0.1, angular_z=float("inf")))
    ctx.spin_for(1.0)
    assert (s.x, s.y, s.yaw) == (0.0, 0.0, 0.0)
    pub.publish(Twist(linear_x=1e12, linear_y=1e12, angular_z=-1e12))
    ctx.spin_for(0.1)
    # clamped to 5 m/s, in the commanded direction, and to 10 rad/s
    assert math.hypot(s.v, s.vy) == pytest.approx(5.0)
    assert s.v == pytest.approx(s.vy) and s.w == pytest.approx(-10.0)
    assert all(math.isfinite(v) for v in (s.x, s.y, s.yaw))


def test_the_imu_of_a_strafing_turning_body_feels_the_rotating_frame() -> None:
    imu = (
        '<plugin name="imu" filename="libgazebo_ros_imu.so"><bodyName>base_link</bodyName>'
        "<topicName>imu</topicName><frameName>base_link</frameName>"
        "<updateRate>100</updateRate></plugin>"
    )
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=_omni(extra=imu))
    got = collect(ctx, {"/imu": "sensor_msgs/msg/Imu"})
    _drive(ctx, linear_x=0.3, linear_y=0.2, angular_z=0.5)
    ctx.spin_for(1.0)
    last = got["/imu"][-1]
    # a = dv/dt + w x v at a constant body twist: (-w vy, w vx)
    acc = last.linear_acceleration
    assert (acc.x, acc.y) == pytest.approx((-0.1, 0.15), abs=1e-9)
    assert last.angular_velocity.z == pytest.approx(0.5)


def test_the_kernel_glides_and_stops_at_a_wall_without_noise() -> None:
    footprint = circle_polygon(0.15)
    state = np.zeros(STATE_SIZE)
    state[S_CVX], state[S_CVY], state[S_CW] = 0.0, 1.0, 0.0
    params = np.array([0.2, 0.05, 0.0, 0.02, inner_radius(footprint), DRIVE_HOLONOMIC])
    walls = np.array([[-1.0, 0.5, 1.0, 0.5]])
    near = np.zeros(1, dtype=np.int64)
    noise = np.full((4, 2), np.nan)  # a holonomic step draws no slip
    pos = advance(state, params, 0.01, footprint, walls, np.zeros((0, 3)), near, noise, 0, 100)
    assert pos == 0
    # the 24-gon around the 0.15 m circle reaches 0.15 / cos(pi / 24) up
    stop = 0.5 - 0.15 / math.cos(math.pi / 24)
    assert state[S_Y] == pytest.approx(stop, abs=1e-4) and state[S_Y] <= stop
    assert (state[S_X], state[S_TH], state[S_VY]) == (0.0, 0.0, pytest.approx(0.0, abs=1e-9))


def test_the_packed_kernel_matches_advance_for_a_holonomic_body() -> None:
    footprint = circle_polygon(0.15)
    walls = np.array([[0.6, -1.0, 0.6, 1.0]])
    noise = np.zeros((8, 2))
    params = np.array([0.2, 0.05, 0.0, 0.02, inner_radius(footprint), DRIVE_HOLONOMIC])
    st = np.zeros(STATE_SIZE)
    st[S_CVX], st[S_CVY], st[S_CW] = 0.4, 0.3, -0.7
    pack = PhysicsPack(st, params, 0.01, footprint, walls, np.zeros((0, 3)), noise)
    near = np.zeros(1, dtype=np.int64)
    for steps in (1, 7, 60, 200):
        advance_packed(pack.array, near, 0, steps)
        advance(st, params, 0.01, footprint, walls, np.zeros((0, 3)), near, noise, 0, steps)
        assert pack.state.tobytes() == st.tobytes()
    assert st[S_CONTACT] == 1.0 and st[S_X] < 0.6
