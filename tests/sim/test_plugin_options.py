"""Gazebo plugin settings that reach the simulated messages: the camera plugins'
``distortionK1``..``distortionT2`` and ``hackBaseline`` (CameraInfo), the IMU plugins'
``rpyOffset`` (the Imu's orientation, and for ``libgazebo_ros_imu.so`` its rates)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.description import load_robot
from roverlab.geometry import quat_from_rpy, quat_from_yaw, quat_multiply, quat_rotate
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.sim.sensors import GRAVITY
from tests.description.conftest import robot

LINKS = (
    '<link name="base_link"><collision><geometry><box size="0.3 0.2 0.1"/></geometry>'
    '</collision></link><link name="cam"/><link name="imu"/>'
    '<joint name="cam_joint" type="fixed"><parent link="base_link"/><child link="cam"/>'
    '<origin xyz="0.1 0 0.2"/></joint>'
    '<joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu"/></joint>'
)

CAMERAS = """
<gazebo reference="cam">
  <sensor type="camera" name="mono">
    <update_rate>10</update_rate>
    <camera><horizontal_fov>1.2</horizontal_fov>
      <image><width>64</width><height>48</height></image></camera>
    <plugin name="mono_plugin" filename="libgazebo_ros_camera.so">
      <cameraName>mono</cameraName><frameName>cam</frameName>
      <hackBaseline>0.07</hackBaseline>
      <distortionK1>-0.25</distortionK1><distortionK2>0.12</distortionK2>
      <distortionK3>-0.01</distortionK3><distortionT1>0.001</distortionT1>
      <distortionT2>-0.002</distortionT2>
    </plugin>
  </sensor>
  <sensor type="depth" name="kinect">
    <update_rate>10</update_rate>
    <camera><horizontal_fov>1.0</horizontal_fov>
      <image><width>40</width><height>30</height></image></camera>
    <plugin name="kinect_plugin" filename="libgazebo_ros_openni_kinect.so">
      <cameraName>kinect</cameraName><frameName>cam</frameName>
      <hackBaseline>0.075</hackBaseline><baseline>0.2</baseline>
      <distortionK1>0.3</distortionK1><distortion_k2>0.5</distortion_k2>
    </plugin>
  </sensor>
</gazebo>
"""


def _collect(ctx: Context, topics: dict[str, str]) -> dict[str, list[Any]]:
    got: dict[str, list[Any]] = {t: [] for t in topics}
    node = ctx.create_node("collector")
    for topic, typ in topics.items():
        node.create_subscription(typ, topic, got[topic].append, 100)
    return got


def test_camera_info_carries_the_plugins_distortion_and_hack_baseline() -> None:
    # GazeboRosCameraUtils::Init: D = [k1, k2, t1, t2, k3] (plumb_bob),
    # P[3] = -focal_length * hackBaseline; the kinect plugin's camera infos are the same
    # code's, and it reads neither <baseline> nor distortion_k2 (snake case)
    ctx = Context()
    Simulation(context=ctx, world="empty", robot=load_robot(robot(LINKS + CAMERAS)))
    info = "sensor_msgs/msg/CameraInfo"
    got = _collect(
        ctx,
        {
            "/mono/camera_info": info,
            "/kinect/ir/camera_info": info,
            "/kinect/depth/camera_info": info,
        },
    )
    ctx.spin_for(0.25)
    mono = got["/mono/camera_info"][-1]
    assert mono.distortion_model == "plumb_bob"
    np.testing.assert_array_equal(mono.d, [-0.25, 0.12, 0.001, -0.002, -0.01])
    f = 32 / math.tan(0.6)
    assert mono.k[0] == pytest.approx(f)
    assert mono.p[3] == pytest.approx(-f * 0.07)
    assert list(mono.p[[0, 1, 2, 5, 6, 10]]) == list(mono.k[[0, 1, 2, 4, 5, 8]])
    assert list(mono.p[[4, 7, 8, 9, 11]]) == [0.0] * 5
    fk = 20 / math.tan(0.5)
    for topic in ("/kinect/ir/camera_info", "/kinect/depth/camera_info"):
        kinect = got[topic][-1]
        np.testing.assert_array_equal(kinect.d, [0.3, 0.0, 0.0, 0.0, 0.0])
        assert kinect.p[3] == pytest.approx(-fk * 0.075)


def _imus(offset: str) -> str:
    return f"""
<gazebo>
  <plugin name="imu_a" filename="libgazebo_ros_imu.so">
    <bodyName>imu</bodyName><frameName>imu</frameName><topicName>imu_a</topicName>
    <updateRate>50</updateRate>{offset}
  </plugin>
</gazebo>
<gazebo reference="imu">
  <sensor type="imu" name="imu_sensor">
    <update_rate>50</update_rate>
    <plugin name="imu_b" filename="libgazebo_ros_imu_sensor.so">
      <robotNamespace>/</robotNamespace><topicName>imu_b</topicName>
      <frameName>imu</frameName><updateRateHZ>50</updateRateHZ>{offset}
    </plugin>
  </sensor>
</gazebo>
"""


def _last_imus(offset: str, yaw: float) -> tuple[Any, Any]:
    ctx = Context()
    Simulation(
        context=ctx,
        world="empty",
        robot=load_robot(robot(LINKS + _imus(offset))),
        spawn=SpawnPose(0.0, 0.0, yaw),
        cameras=False,
    )
    imu = "sensor_msgs/msg/Imu"
    got = _collect(ctx, {"/imu_a": imu, "/imu_b": imu})
    ctx.spin_for(0.2)
    return got["/imu_a"][-1], got["/imu_b"][-1]


def _vec(v: Any) -> list[float]:
    return [v.x, v.y, v.z]


def test_imu_rpy_offset_turns_the_orientation_and_the_model_plugin_s_rates() -> None:
    # gazebo_ros_imu: rot = offset.Rot() * link pose; orientation = rot, and the rates
    # and accelerations are turned by rot; gazebo_ros_imu_sensor: orientation =
    # offset.rot * sensor orientation, rates as measured
    rpy, yaw = (0.3, -0.2, 0.5), 0.7
    model_plugin, sensor_plugin = _last_imus(
        f"<rpyOffset>{' '.join(map(str, rpy))}</rpyOffset>", yaw
    )
    q = quat_multiply(quat_from_rpy(*rpy), quat_from_yaw(yaw))
    for msg in (model_plugin, sensor_plugin):
        o = msg.orientation
        np.testing.assert_allclose([o.x, o.y, o.z, o.w], q, atol=1e-12)
    # at rest: gravity up in the body frame, turned by the offset for the model plugin
    up = np.array([0.0, 0.0, GRAVITY])
    np.testing.assert_allclose(
        _vec(model_plugin.linear_acceleration), quat_rotate(quat_from_rpy(*rpy), up), atol=1e-9
    )
    np.testing.assert_allclose(_vec(sensor_plugin.linear_acceleration), up, atol=1e-9)
    # a zero offset is the plugins' default: the body's yaw, unturned rates
    plain_a, plain_b = _last_imus("<rpyOffset>0 0 0</rpyOffset>", yaw)
    for msg in (plain_a, plain_b):
        o = msg.orientation
        np.testing.assert_allclose([o.x, o.y, o.z, o.w], quat_from_yaw(yaw), atol=1e-12)
        np.testing.assert_allclose(_vec(msg.linear_acceleration), up, atol=1e-9)
