"""check_urdf's text, and the sensor/plugin listing after it."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.description import format_check, format_tree, load_robot
from tests.description.conftest import MYBOT_URDF, MYBOT_XACRO, robot

MYBOT_CHECK_URDF = """\
robot name is: mybot
---------- Successfully Parsed XML ---------------
root Link: base_footprint has 1 child(ren)
    child(1):  base_link
        child(1):  ball_wheel_link
        child(2):  left_wheel_link
        child(3):  right_wheel_link"""


def test_tree_is_check_urdf_byte_for_byte() -> None:
    assert format_tree(load_robot(MYBOT_URDF)) == MYBOT_CHECK_URDF


def test_children_are_ordered_by_joint_name_as_urdfdom() -> None:
    m = load_robot(
        robot(
            '<link name="root"/><link name="zeta"/><link name="alpha"/><link name="deep"/>'
            '<joint name="b_joint" type="fixed"><parent link="root"/><child link="alpha"/></joint>'
            '<joint name="a_joint" type="fixed"><parent link="root"/><child link="zeta"/></joint>'
            '<joint name="c" type="fixed"><parent link="zeta"/><child link="deep"/></joint>',
            "order",
        )
    )
    assert format_tree(m).splitlines()[2:] == [
        "root Link: root has 2 child(ren)",
        "    child(1):  zeta",
        "        child(1):  deep",
        "    child(2):  alpha",
    ]


def test_check_lists_sensors_and_plugins() -> None:
    text = format_check(load_robot(MYBOT_XACRO))
    assert text.startswith("robot name is: mybot\n")
    assert "---------- Gazebo sensors: 3 ---------------" in text
    assert "  rplidar_sensor (ray) on base_laser_link: 720 samples" in text
    assert "range 0.12-12 m, 7 Hz" in text
    assert "  csi Camera (camera) on base_camera_link: 640x480 R8G8B8" in text
    assert "---------- Gazebo plugins: 4 ---------------" in text
    assert "separation 0.18 m, diameter 0.05 m" in text
    assert "[libgazebo_ros_camera.so] on sensor 'csi Camera': /image_raw" in text
    # the IMU plugin's own <imu><noise> block is what the simulation uses
    assert "[libgazebo_ros_imu.so] on model: /imu from link imu in frame imu, " in text
    assert "rate noise 0.0002, accel noise 0.017" in text
    assert "unsupported" not in text


def test_check_marks_unsupported_plugins_and_unknown_references() -> None:
    m = load_robot(
        robot(
            '<link name="a"/><gazebo><plugin name="ctl" filename="libgazebo_ros_p3d.so"/>'
            '</gazebo><gazebo reference="ghost"><material>Gazebo/Red</material></gazebo>'
            '<gazebo reference="a"><sensor type="sonar" name="s"/></gazebo>'
        )
    )
    text = format_check(m)
    assert "  ctl [libgazebo_ros_p3d.so] on model: not supported by roverlab" in text
    assert "  s (sonar) on a: not supported by roverlab" in text
    assert "unsupported (ignored): plugin libgazebo_ros_p3d.so, sensor type sonar" in text
    assert "warning: <gazebo reference> names no link or joint: 'ghost'" in text


CONTACT_ROBOT = robot(
    '<link name="base"><collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>'
    '</link><link name="wheel"/>'
    '<joint name="j" type="continuous"><parent link="base"/><child link="wheel"/></joint>'
    '<gazebo reference="wheel"><material>Gazebo/Black</material><mu1>0.2</mu1><mu2>0.2</mu2>'
    "<kp>1e6</kp><turnGravityOff>true</turnGravityOff></gazebo>"
    '<gazebo reference="base"><selfCollide>true</selfCollide></gazebo>'
    "<gazebo><static>false</static></gazebo>",
    "contact",
)


def test_gazebo_settings_the_simulator_does_not_act_on_are_named() -> None:
    from roverlab.description.check import robot_notes

    model = load_robot(CONTACT_ROBOT)
    short = robot_notes(model)
    assert len(short) == 2, short
    assert short[0].endswith(
        "settings not simulated (the drive is kinematic, a contact stops the body): "
        "mu1, mu2, kp, turnGravityOff, selfCollide on 2 links"
    ), short
    assert "model settings not simulated: static" in short[1]
    detail = robot_notes(model, detail=True)[0]
    assert "mu1 (wheel); mu2 (wheel); kp (wheel); turnGravityOff (wheel); selfCollide (base)" in (
        detail
    )
    assert "material" not in detail  # read: the dashboard's colour
    report = format_check(model)
    assert "note: " + detail in report.splitlines()
    bare = robot(
        '<link name="base"/><gazebo reference="base"><material>Gazebo/Red</material></gazebo>'
    )
    assert robot_notes(load_robot(bare)) == []


def test_sim_prints_the_notes_and_strict_does_not_refuse_them(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    from tests.helpers.nodes import run_main

    urdf = tmp_path / "contact.urdf"
    urdf.write_text(CONTACT_ROBOT)
    code = run_main(
        [
            "sim",
            "--robot",
            str(urdf),
            "--world",
            "empty",
            "--rate",
            "max",
            "--duration",
            "0.1",
            "--strict",
        ]
    )
    err = capfd.readouterr().err
    assert code == 0, err
    assert f"note: {urdf}: <gazebo reference> settings not simulated" in err, err
