"""gazebo_ros_control + ros_control's diff_drive_controller: the controller's YAML read
with its names and defaults, its speed limiter, the command timeout, odometry from the
wheels, and the bundled Jackal-sized robot driven through it."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from roverlab.core import Context
from roverlab.description import RosControlSpec, load_robot
from roverlab.description.check import format_check
from roverlab.launch import build_launch
from roverlab.msgs import Twist
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.sim.robot import sim_config_from_model
from roverlab.sim.ros_control import (
    DiffDriveControllerConfig,
    RosControlError,
    SpeedLimits,
    diff_drive_controller_config,
)
from roverlab.world.yaml_world import world_from_dict
from tests.helpers.nodes import collect

_EMPTY = world_from_dict({"name": "empty"}, source=Path("empty.yaml"))


def _two_wheeler() -> str:
    wheel = (
        '<link name="{s}_wheel"><collision><origin rpy="1.5708 0 0"/><geometry>'
        '<cylinder radius="0.05" length="0.02"/></geometry></collision></link>'
        '<joint name="{s}_wheel_joint" type="continuous"><parent link="base_link"/>'
        '<child link="{s}_wheel"/><origin xyz="0 {y} 0"/><axis xyz="0 1 0"/></joint>'
    )
    return (
        '<robot name="duo"><link name="base_link"><collision><geometry>'
        '<box size="0.3 0.25 0.1"/></geometry></collision></link>'
        + wheel.format(s="left", y=0.15)
        + wheel.format(s="right", y=-0.15)
        + '<gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">'
        "<robotNamespace>/duo</robotNamespace></plugin></gazebo></robot>"
    )


def _controller(**extra: Any) -> dict[str, Any]:
    return {
        "duo": {
            "mobile_base_controller": {
                "type": "diff_drive_controller/DiffDriveController",
                "left_wheel": "left_wheel_joint",
                "right_wheel": "right_wheel_joint",
                **extra,
            }
        }
    }


def test_speed_limiter_is_ros_controls() -> None:
    lim = SpeedLimits(
        has_velocity_limits=True, min_velocity=-1.0, max_velocity=2.0,
        has_acceleration_limits=True, min_acceleration=-4.0, max_acceleration=10.0,
    )  # fmt: skip
    assert lim.limit(5.0, 0.0, 0.0, 0.01) == pytest.approx(0.1)  # acceleration first
    assert lim.limit(5.0, 1.95, 1.9, 0.01) == pytest.approx(2.0)  # then the velocity cap
    assert lim.limit(-5.0, 0.0, 0.0, 0.01) == pytest.approx(-0.04)  # min_acceleration
    jerk = SpeedLimits(has_jerk_limits=True, min_jerk=-1.0, max_jerk=1.0)
    # the change of the change is bounded: v0 + (v0 - v1) + clamp(...)
    assert jerk.limit(1.0, 0.0, 0.0, 0.1) == pytest.approx(0.02)
    assert SpeedLimits().limit(3.0, 0.0, 0.0, 0.01) == 3.0  # no limits, no change


def test_config_from_yaml_and_urdf() -> None:
    model = load_robot(_two_wheeler())
    assert model.gazebo.ros_control == RosControlSpec(robot_namespace="/duo")
    cfg = sim_config_from_model(
        model, controllers=_controller(wheel_separation_multiplier=1.2, linear={"x": {
            "has_velocity_limits": True, "max_velocity": 0.8}}, publish_rate=20, odd=1),
    )  # fmt: skip
    d = cfg.drive
    assert isinstance(d, DiffDriveControllerConfig)
    # from the URDF: the wheel joints 0.30 m apart, the wheel's cylinder radius
    assert d.wheel_separation_m == pytest.approx(0.36)  # the controller's: times 1.2
    assert d.params.wheel_separation_m == pytest.approx(0.30)  # two wheels: geometric
    assert d.left_wheel_radius_m == pytest.approx(0.05)
    assert d.linear.max_velocity == 0.8 and d.linear.min_velocity == -0.8
    assert d.command_topic == "/duo/mobile_base_controller/cmd_vel"
    assert d.odometry_topic == "/duo/mobile_base_controller/odom"
    assert (d.publish_rate_hz, d.cmd_vel_timeout_s, d.robot_base_frame) == (20.0, 0.5, "base_link")
    assert d.warnings == (
        "<parameters>: mobile_base_controller: unknown parameter 'odd' (ignored)",
    )
    assert cfg.base_frame == "base_link"
    # without controller parameters nothing drives it
    assert sim_config_from_model(model).drive is None
    assert "ros_control in namespace /duo" in format_check(model)


@pytest.mark.parametrize(
    ("tree", "message"),
    [
        ({"left_wheel": "left_wheel_joint"}, "duo_ctl: missing right_wheel"),
        ({"left_wheel": "nope", "right_wheel": "right_wheel_joint"},
         "duo_ctl: wheel joint 'nope' is not a joint of the robot"),
        ({"left_wheel": "left_wheel_joint", "right_wheel": "right_wheel_joint",
          "publish_rate": "fast"}, "duo_ctl/publish_rate: expected a number, got 'fast'"),
        ({"left_wheel": "left_wheel_joint", "right_wheel": "right_wheel_joint",
          "linear": {"x": {"max_speed": 1}}}, "duo_ctl/linear/x: unknown parameter 'max_speed'"),
    ],
)  # fmt: skip
def test_bad_controller_parameters_are_one_line(tree: dict[str, Any], message: str) -> None:
    with pytest.raises(RosControlError, match=r"^control\.yaml: ") as err:
        diff_drive_controller_config(
            load_robot(_two_wheeler()), "duo_ctl", tree, source="control.yaml"
        )
    assert str(err.value).endswith(message) and "\n" not in str(err.value)


def _drive(ctx: Context, sim: Simulation, topic: str, v: float, w: float, seconds: float) -> None:
    node = ctx.create_node(f"driver_{len(ctx.nodes)}")
    pub = node.create_publisher(Twist, topic, 10)
    timer = node.create_timer(0.05, lambda: pub.publish(Twist(linear_x=v, angular_z=w)))
    ctx.spin_for(seconds)
    timer.cancel()


def test_jackal_drives_through_its_diff_drive_controller() -> None:
    ctx = Context()
    sim = Simulation(
        context=ctx, world=_EMPTY, robot="jackal", spawn=SpawnPose(0.0, 0.0, 0.0),
        cameras=False, parameters={"wheel_slip": 0.0},
    )  # fmt: skip
    s = sim.simulator
    got = collect(ctx, {"/jackal_velocity_controller/odom": "nav_msgs/msg/Odometry",
                        "/front/scan": "sensor_msgs/msg/LaserScan"})  # fmt: skip
    topic = "/jackal_velocity_controller/cmd_vel"
    # 3 m/s asked: the controller's limit is 2 m/s, reached at 20 m/s^2 (0.1 s)
    _drive(ctx, sim, topic, 3.0, 0.0, 0.1)  # the first command at 0.05 s
    assert 0.8 <= s.v <= 1.2  # ramping: 20 m/s^2 for 0.05 s
    _drive(ctx, sim, topic, 3.0, 0.0, 1.0)
    assert s.v == pytest.approx(2.0)
    # commands stop: after cmd_vel_timeout (0.25 s) the controller brakes to zero
    ctx.spin_for(0.2)
    assert s.v == pytest.approx(2.0)
    ctx.spin_for(0.3)
    assert s.v == 0.0
    x_stop = s.x
    # a turn at 1 rad/s: the calibrated skid-steer track turns the body as commanded
    yaw0 = s.yaw
    _drive(ctx, sim, topic, 0.0, 1.0, 1.0)
    assert math.remainder(s.yaw - yaw0, math.tau) == pytest.approx(1.0, abs=0.1)
    odom = got["/jackal_velocity_controller/odom"][-1]
    assert odom.header.frame_id == "odom" and odom.child_frame_id == "base_link"
    assert odom.pose.pose.position.x == pytest.approx(x_stop, abs=0.01)
    assert odom.pose.covariance[0] == 0.001 and odom.twist.covariance[35] == 0.03
    assert len(got["/jackal_velocity_controller/odom"]) / (50 * ctx.now().nanoseconds / 1e9) > 0.8
    scan = got["/front/scan"][-1]
    assert len(scan.ranges) == 720 and scan.header.frame_id == "front_laser"
    assert scan.angle_min == pytest.approx(-2.35619)


def test_controller_yaml_file_drives_a_two_wheeler(tmp_path: Path) -> None:
    control = tmp_path / "control.yaml"
    control.write_text(
        "duo:\n  base_controller:\n    type: diff_drive_controller/DiffDriveController\n"
        "    left_wheel: left_wheel_joint\n    right_wheel: right_wheel_joint\n"
        "    wheel_separation_multiplier: 2.0\n    enable_odom_tf: false\n"
    )
    ctx = Context()
    sim = Simulation(context=ctx, world=_EMPTY, robot=load_robot(_two_wheeler()), cameras=False,
                     parameters={"wheel_slip": 0.0}, controllers=control)  # fmt: skip
    got = collect(ctx, {"/tf": "tf2_msgs/msg/TFMessage",
                        "/duo/base_controller/odom": "nav_msgs/msg/Odometry"})  # fmt: skip
    _drive(ctx, sim, "/duo/base_controller/cmd_vel", 0.0, 0.5, 1.0)
    # the controller spreads the wheels for a 0.6 m track; the body's is 0.3 m: twice
    # the commanded turn (a mis-calibrated multiplier shows as it would in Gazebo), while
    # the controller's odometry, with its own track, reports the commanded one
    assert sim.simulator.w == pytest.approx(1.0)
    assert got["/duo/base_controller/odom"][-1].twist.twist.angular.z == pytest.approx(0.5)
    assert not any(t.child_frame_id == "base_link" for m in got["/tf"] for t in m.transforms)


def test_a_launch_file_with_controller_manager_spawner_drives_jackal(tmp_path: Path) -> None:
    launch = tmp_path / "jackal.launch"
    launch.write_text(
        "<launch>\n"
        '  <include file="$(find gazebo_ros)/launch/empty_world.launch">\n'
        '    <arg name="world_name" value="empty"/>\n  </include>\n'
        '  <param name="robot_description" command="$(find xacro)/xacro '
        '$(find jackal_description)/urdf/jackal.urdf.xacro"/>\n'
        '  <node name="spawner" pkg="gazebo_ros" type="spawn_model" '
        'args="-urdf -model jackal -param robot_description"/>\n'
        '  <include file="$(find jackal_control)/launch/control.launch"/>\n'
        "</launch>\n"
    )
    ctx = Context()
    built = build_launch(launch, {}, context=ctx)
    sim = built.simulator
    assert sim is not None and isinstance(sim.robot.drive, DiffDriveControllerConfig)
    node = ctx.create_node("driver")
    pub = node.create_publisher(Twist, "/jackal_velocity_controller/cmd_vel", 10)
    node.create_timer(0.05, lambda: pub.publish(Twist(linear_x=0.5)))
    ctx.spin_for(1.0)
    assert sim.v == pytest.approx(0.5, abs=0.05) and sim.x > 0.3  # 2 % wheel slip
