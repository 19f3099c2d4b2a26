"""gazebo_ros plugins of popular robots beyond the diff drive: skid steer (husky, rosbot),
planar move (omni-wheel and mecanum bases) and the imu sensor plugin, read with the
plugins' own defaults and simulated (the planar move's simulation: tests/sim)."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.core import Context
from roverlab.description import DescriptionError, ImuPluginSpec, URDFError, load_robot
from roverlab.description.check import format_check, robot_warnings
from roverlab.msgs import Twist
from roverlab.sim.app import Simulation
from roverlab.sim.robot import sim_config_from_model
from roverlab.world.yaml_world import world_from_dict
from tests.helpers.nodes import collect

_INERTIA = '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'


def _skid(plugin: str, *, joints: tuple[str, ...] = ("fl", "fr", "rl", "rr")) -> str:
    wheels = "".join(
        f'<link name="{j}_wheel"><collision><geometry><cylinder radius="0.1" length="0.05"/>'
        f'</geometry></collision></link><joint name="{j}" type="continuous">'
        f'<parent link="base_link"/><child link="{j}_wheel"/>'
        f'<origin xyz="{0.2 if j[1] == "l" else -0.2} {0.25 if j[0] == "l" else -0.25} 0"/>'
        '<axis xyz="0 1 0"/></joint>'
        for j in joints
    )
    return (
        '<robot name="skiddy"><link name="base_link"><collision><geometry>'
        '<box size="0.6 0.4 0.2"/></geometry></collision>'
        f'<inertial><mass value="20"/>{_INERTIA}</inertial></link>{wheels}'
        '<gazebo><plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so">'
        f"{plugin}</plugin></gazebo></robot>"
    )


_HUSKY_LIKE = (
    "<updateRate>100.0</updateRate><robotNamespace>/</robotNamespace>"
    "<leftFrontJoint>fl</leftFrontJoint><rightFrontJoint>fr</rightFrontJoint>"
    "<leftRearJoint>rl</leftRearJoint><rightRearJoint>rr</rightRearJoint>"
    "<wheelSeparation>0.5</wheelSeparation><wheelDiameter>0.2</wheelDiameter>"
    "<robotBaseFrame>base_link</robotBaseFrame><torque>20</torque>"
    "<commandTopic>cmd_vel</commandTopic><odometryTopic>odom</odometryTopic>"
    "<odometryFrame>odom</odometryFrame>"
)


def test_skid_steer_is_read_with_the_plugin_s_defaults() -> None:
    m = load_robot(_skid(_HUSKY_LIKE))
    dd = m.gazebo.diff_drive
    assert dd is not None and m.gazebo.unsupported_plugins == ()
    assert (dd.left_joint, dd.right_joint, dd.rear_joints) == ("fl", "fr", ("rl", "rr"))
    assert (dd.wheel_separation_m, dd.wheel_diameter_m, dd.wheel_torque_nm) == (0.5, 0.2, 20)
    assert (dd.command_topic, dd.odometry_topic, dd.robot_base_frame) == (
        "/cmd_vel",
        "/odom",
        "base_link",
    )
    # the plugin's odometry is the model's world pose; its tf only with broadcastTF
    assert dd.odometry_source == "world" and not dd.publish_odom_tf
    assert not dd.legacy_mode and dd.wheel_count == 4
    names = ("left_front_joint", "right_front_joint", "left_rear_joint", "right_rear_joint")
    defaults = load_robot(_skid("", joints=names)).gazebo.diff_drive
    assert defaults is not None
    assert (defaults.wheel_separation_m, defaults.wheel_diameter_m) == (0.4, 0.15)
    assert (defaults.wheel_torque_nm, defaults.update_rate_hz) == (5.0, 100.0)
    tf = load_robot(_skid(_HUSKY_LIKE + "<broadcastTF>1</broadcastTF>")).gazebo.diff_drive
    assert tf is not None and tf.publish_odom_tf
    text = format_check(m)
    assert "fl/fr + rl/rr, separation 0.5 m, diameter 0.2 m, /cmd_vel -> /odom" in text
    assert not [w for w in robot_warnings(m) if "not simulated" in w]


def test_skid_steer_needs_its_four_joints() -> None:
    # Gazebo's plugin throws "couldn't get left rear hinge joint named ..."
    with pytest.raises(URDFError, match=r"<leftRearJoint> 'rl' is not a movable joint"):
        load_robot(_skid(_HUSKY_LIKE, joints=("fl", "fr", "rr")))


def test_skid_steer_torque_of_four_wheels_limits_the_acceleration() -> None:
    config = sim_config_from_model(load_robot(_skid(_HUSKY_LIKE)))
    assert config.drive is not None
    # 4 wheels x 20 N m / (0.1 m x 20 kg)
    assert config.drive.params.wheel_acceleration == pytest.approx(40.0)
    assert config.drive.publish_odom_tf is False


_EMPTY = world_from_dict({"name": "empty"}, source=Path("empty.yaml"))


def test_a_skid_steer_robot_drives_on_cmd_vel() -> None:
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=load_robot(_skid(_HUSKY_LIKE)))
    got = collect(ctx, {"/odom": "nav_msgs/msg/Odometry", "/tf": "tf2_msgs/msg/TFMessage"})
    ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1).publish(Twist(linear_x=0.5))
    ctx.spin_for(2.0)
    assert len(got["/odom"]) == pytest.approx(200, abs=2)  # updateRate 100
    last = got["/odom"][-1]
    assert last.child_frame_id == "base_link"
    assert last.pose.pose.position.x == pytest.approx(1.0, abs=0.05)
    pairs = {(t.header.frame_id, t.child_frame_id) for m in got["/tf"] for t in m.transforms}
    assert ("odom", "base_link") not in pairs  # broadcastTF defaults to false


def _imu_robot(plugin: str, sensor: str = "<update_rate>50</update_rate>") -> str:
    return (
        '<robot name="bot"><link name="base_link"/><link name="imu_link"/>'
        '<joint name="j" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>'
        f'<gazebo reference="imu_link"><sensor type="imu" name="imu">{sensor}'
        "<imu><angular_velocity><x><noise type='gaussian'><stddev>0.002</stddev></noise></x>"
        "</angular_velocity></imu>"
        f'<plugin name="p" filename="libgazebo_ros_imu_sensor.so">{plugin}</plugin>'
        "</sensor></gazebo></robot>"
    )


def test_imu_sensor_plugin_is_read_as_noetic_s_plugin() -> None:
    m = load_robot(_imu_robot("<topicName>imu</topicName><frameName>imu_link</frameName>"))
    (spec,) = m.gazebo.specs(ImuPluginSpec)
    assert m.gazebo.unsupported_plugins == ()
    # no robotNamespace: the plugin's namespace is the model's name
    assert (spec.topic, spec.frame_id, spec.body_name) == ("/bot/imu", "imu_link", "imu_link")
    assert spec.update_rate_hz == 1.0  # updateRateHZ defaults to 1 Hz
    assert spec.noise is not None and spec.noise.rate.stddev == 0.002  # the sensor's noise
    assert "/bot/imu from link imu_link in frame imu_link, rate noise 0.002" in format_check(m)
    assert "accel noise 0, 1 Hz" in format_check(m)
    fast = load_robot(
        _imu_robot(
            "<robotNamespace>/</robotNamespace><topicName>imu</topicName>"
            "<frameName>imu_link</frameName><updateRateHZ>200</updateRateHZ>"
            "<gaussianNoise>0.01</gaussianNoise>"
        )
    )
    (spec,) = fast.gazebo.specs(ImuPluginSpec)
    # no faster than its sensor's update_rate
    assert (spec.topic, spec.update_rate_hz, spec.gaussian_noise) == ("/imu", 50.0, 0.01)


def test_imu_sensor_plugin_needs_frame_name_and_an_imu_sensor() -> None:
    with pytest.raises(URDFError, match=r"libgazebo_ros_imu_sensor.so'>: <frameName>: missing"):
        load_robot(_imu_robot("<topicName>imu</topicName>"))
    model_plugin = (
        '<robot name="bot"><link name="base_link"/><gazebo>'
        '<plugin name="p" filename="libgazebo_ros_imu_sensor.so"><frameName>base_link'
        "</frameName></plugin></gazebo></robot>"
    )
    with pytest.raises(URDFError, match=r"a sensor plugin: Gazebo loads it only inside"):
        load_robot(model_plugin)


def test_the_imu_sensor_plugin_publishes_in_the_simulator() -> None:
    robot = load_robot(
        _imu_robot(
            "<robotNamespace>/</robotNamespace><topicName>imu</topicName>"
            "<frameName>imu_link</frameName><updateRateHZ>20</updateRateHZ>"
        )
    )
    ctx = Context()
    Simulation(context=ctx, world=_EMPTY, robot=robot)
    got = collect(ctx, {"/imu": "sensor_msgs/msg/Imu"})
    ctx.spin_for(2.0)
    assert len(got["/imu"]) == pytest.approx(40, abs=1)
    assert got["/imu"][-1].header.frame_id == "imu_link"
    assert got["/imu"][-1].linear_acceleration.z == pytest.approx(9.8, abs=0.1)


def _planar(plugin: str) -> str:
    return (
        '<robot name="omni"><link name="base_footprint"/><link name="base_link"/>'
        '<joint name="j" type="fixed"><parent link="base_footprint"/><child link="base_link"/>'
        '</joint><gazebo><plugin name="omni" filename="libgazebo_ros_planar_move.so">'
        f"{plugin}</plugin></gazebo></robot>"
    )


def test_planar_move_is_read_with_noetic_s_defaults() -> None:
    m = load_robot(_planar(""))
    spec = m.gazebo.planar_move
    assert spec is not None and m.gazebo.drive is spec and m.gazebo.diff_drive is None
    assert (spec.command_topic, spec.odometry_topic) == ("/cmd_vel", "/odom")
    assert (spec.odometry_frame, spec.robot_base_frame) == ("odom", "base_footprint")
    assert (spec.odometry_rate_hz, spec.cmd_timeout_s, spec.publish_odometry_tf) == (
        20.0,
        -1.0,
        True,
    )
    # simulated now: no longer among the plugins "not simulated (ignored)"
    assert m.gazebo.unsupported_plugins == ()
    assert not [w for w in robot_warnings(m) if "planar_move" in w]
    text = format_check(m)
    assert (
        "omni [libgazebo_ros_planar_move.so] on model: holonomic (linear.x, linear.y, "
        "angular.z), /cmd_vel -> /odom at 20 Hz (odom -> base_footprint)"
    ) in text
    assert "unsupported" not in text


def test_planar_move_names_rates_and_switches() -> None:
    m = load_robot(
        _planar(
            "<robotNamespace>/omni</robotNamespace><commandTopic>cmd_vel</commandTopic>"
            "<odometryTopic>odom</odometryTopic><odometryFrame>odom</odometryFrame>"
            "<robotBaseFrame>base_link</robotBaseFrame><odometryRate>50.0</odometryRate>"
            "<cmdTimeout>0.5</cmdTimeout><publishOdometryTf>false</publishOdometryTf>"
        )
    )
    spec = m.gazebo.planar_move
    assert spec is not None
    # topics live in the namespace; frames get only the tf_prefix parameter's prefix
    assert (spec.command_topic, spec.odometry_topic) == ("/omni/cmd_vel", "/omni/odom")
    assert (spec.odometry_frame, spec.robot_base_frame) == ("odom", "base_link")
    assert (spec.odometry_rate_hz, spec.cmd_timeout_s) == (50.0, 0.5)
    assert not spec.publish_odometry_tf
    text = format_check(m)
    assert "at 50 Hz (odom -> base_link), no odom transform (publishOdometryTf false" in text
    assert "stops 0.5 s after the last command" in text
    config = sim_config_from_model(m)
    assert config.base_frame == "base_link" and config.drive is not None
    assert config.drive.robot_base_frame == "base_link"
    quiet = format_check(load_robot(_planar("<odometryRate>0</odometryRate>")))
    assert "/cmd_vel, no odometry (odometryRate 0)" in quiet


def test_planar_move_bad_values_are_one_clear_error() -> None:
    with pytest.raises(URDFError, match=r"planar_move.so'>: <odometryRate>: -1 must not be neg"):
        load_robot(_planar("<odometryRate>-1</odometryRate>"))
    with pytest.raises(URDFError, match=r"<publishOdometryTf>: 'maybe' is not a boolean"):
        load_robot(_planar("<publishOdometryTf>maybe</publishOdometryTf>"))
    with pytest.raises(DescriptionError, match=r"planar move robotBaseFrame 'chassis' is not"):
        sim_config_from_model(load_robot(_planar("<robotBaseFrame>chassis</robotBaseFrame>")))


def test_a_second_drive_plugin_is_warned() -> None:
    second = '<gazebo><plugin name="b" filename="libgazebo_ros_planar_move.so"/></gazebo>'
    m = load_robot(_planar("").replace("</robot>", second + "</robot>"))
    assert len(m.gazebo.plugins) == 2
    (w,) = [w for w in robot_warnings(m) if "drive plugins" in w]
    assert "2 drive plugins: the first (libgazebo_ros_planar_move.so) moves the robot" in w
