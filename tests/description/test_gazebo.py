"""<gazebo> extensions: SDF and gazebo_ros defaults, topic and frame resolution."""

from __future__ import annotations

import math

import pytest

from roverlab.description import (
    CameraPluginSpec,
    DiffDriveSpec,
    ImuPluginSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    URDFError,
    gazebo_material_rgba,
    load_robot,
    resolve_frame,
    resolve_topic,
)
from tests.description.conftest import robot

WHEELS = (
    '<link name="base"/><link name="lw"/><link name="rw"/>'
    '<joint name="left_joint" type="continuous"><parent link="base"/><child link="lw"/></joint>'
    '<joint name="right_joint" type="continuous"><parent link="base"/><child link="rw"/></joint>'
)


def with_gazebo(gazebo: str) -> str:
    return robot(WHEELS + gazebo)


def test_diff_drive_defaults_are_gazebo_ros_defaults() -> None:
    m = load_robot(
        with_gazebo('<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so"/></gazebo>')
    )
    spec = m.gazebo.diff_drive
    assert spec == DiffDriveSpec()
    assert spec is not None
    assert (spec.wheel_separation_m, spec.wheel_diameter_m) == (0.34, 0.15)
    assert (spec.wheel_acceleration, spec.wheel_torque_nm, spec.update_rate_hz) == (0, 5, 100)
    assert spec.legacy_mode is True and spec.odometry_source == "world"
    assert (spec.left_joint, spec.right_joint) == ("left_joint", "right_joint")
    assert (spec.command_topic, spec.odometry_topic) == ("/cmd_vel", "/odom")
    assert (spec.odometry_frame, spec.robot_base_frame) == ("odom", "base_footprint")
    assert spec.publish_tf and spec.publish_odom_tf and not spec.publish_wheel_tf
    assert not spec.publish_wheel_joint_state
    assert spec.wheel_radius_m == pytest.approx(0.075)


def test_diff_drive_namespace_and_booleans() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
            "<robotNamespace>/robot1</robotNamespace><commandTopic>cmd</commandTopic>"
            "<odometryTopic>/abs_odom</odometryTopic><publishTf>0</publishTf>"
            "<publishWheelJointState>1</publishWheelJointState>"
            "<odometrySource>encoder</odometrySource></plugin></gazebo>"
        )
    )
    spec = m.gazebo.diff_drive
    assert spec is not None
    assert spec.command_topic == "/robot1/cmd"
    assert spec.odometry_topic == "/abs_odom"
    assert spec.odometry_frame == "robot1/odom"
    assert spec.joint_states_topic == "/robot1/joint_states"
    assert spec.publish_tf is False and spec.publish_wheel_joint_state is True
    assert spec.odometry_source == "encoder"


@pytest.mark.parametrize(
    ("xml", "message"),
    [
        ("<odometrySource>gps</odometrySource>", "'gps' is not 'world' or 'encoder'"),
        ("<publishTf>yes</publishTf>", "<publishTf>: 'yes' is not a boolean"),
        ("<wheelSeparation>-0.2</wheelSeparation>", "<wheelSeparation>: -0.2 must not be"),
        ("<wheelDiameter>abc</wheelDiameter>", "<wheelDiameter>: 'abc' is not a number"),
    ],
)
def test_diff_drive_bad_values(xml: str, message: str) -> None:
    with pytest.raises(URDFError, match=message):
        load_robot(
            with_gazebo(
                f'<gazebo><plugin name="dd" filename="libgazebo_ros_diff_drive.so">{xml}'
                "</plugin></gazebo>"
            )
        )


@pytest.mark.parametrize(
    ("namespace", "camera_name", "image_topic", "expected"),
    [
        ("", "/", "image_raw", "/image_raw"),
        ("", "/camera", "image_raw", "/camera/image_raw"),
        ("", "camera", "rgb/image_raw", "/camera/rgb/image_raw"),
        ("", "", "image_raw", "/image_raw"),
        ("robot1", "camera", "image_raw", "/robot1/camera/image_raw"),
        ("robot1", "/camera", "/abs/image", "/abs/image"),
    ],
)
def test_camera_topics_resolve_as_the_plugin(
    namespace: str, camera_name: str, image_topic: str, expected: str
) -> None:
    ns = f"<robotNamespace>{namespace}</robotNamespace>" if namespace else ""
    m = load_robot(
        with_gazebo(
            '<gazebo reference="base"><sensor type="camera" name="cam">'
            '<plugin name="c" filename="libgazebo_ros_camera.so">'
            f"{ns}<cameraName>{camera_name}</cameraName>"
            f"<imageTopicName>{image_topic}</imageTopicName><frameName>/base</frameName>"
            "</plugin></sensor></gazebo>"
        )
    )
    (spec,) = m.gazebo.specs(CameraPluginSpec)
    assert spec.image_topic == expected
    assert spec.frame_id == "base"


def test_resolve_helpers() -> None:
    assert resolve_topic("", "scan") == "/scan"
    assert resolve_topic("/", "scan") == "/scan"
    assert resolve_topic("ns", "/scan") == "/scan"
    assert resolve_topic("//", "image_raw") == "/image_raw"
    assert resolve_frame("/", "odom") == "odom"
    assert resolve_frame("/robot1/", "odom") == "robot1/odom"
    assert resolve_frame("robot1", "/odom") == "odom"


def test_sdf_defaults_for_sparse_sensors() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo reference="base"><sensor type="ray" name="lidar"/>'
            '<sensor type="camera" name="cam"/><sensor type="imu" name="imu"/>'
            '<sensor type="contact" name="bumper"/></gazebo>'
        )
    )
    lidar = m.gazebo.sensor("lidar")
    assert lidar.ray is not None and lidar.ray.samples == 640 and lidar.ray.range_max == 0.0
    assert lidar.update_rate_hz == 0.0 and not lidar.always_on and not lidar.visualize
    cam = m.gazebo.sensor("cam").camera
    assert cam is not None and (cam.width, cam.height, cam.horizontal_fov) == (320, 240, 1.047)
    imu = m.gazebo.sensor("imu").imu
    assert imu is not None and imu.rate.stddev == 0.0
    bumper = m.gazebo.sensor("bumper")
    assert not bumper.supported and bumper.ray is None
    assert m.gazebo.unsupported_sensors == (bumper,)


def test_ray_vertical_scan_pose_and_range_count() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo reference="base"><sensor type="gpu_ray" name="velo">'
            "<pose>0.1 0 0.2 0 0 1.5707963</pose><ray><scan>"
            "<horizontal><samples>720</samples><resolution>0.5</resolution>"
            "<min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal>"
            "<vertical><samples>16</samples><min_angle>-0.26</min_angle>"
            "<max_angle>0.26</max_angle></vertical></scan>"
            "<range><min>0.3</min><max>100</max></range></ray>"
            '<plugin name="p" filename="libgazebo_ros_gpu_laser.so"><topicName>points</topicName>'
            "</plugin></sensor></gazebo>"
        )
    )
    s = m.gazebo.sensor("velo")
    assert s.ray is not None and s.ray.vertical is not None
    assert s.ray.vertical.samples == 16
    assert s.ray.range_count == 360
    assert s.ray.angle_increment == pytest.approx(2 * 3.14159 / 359)
    assert s.pose.translation == pytest.approx((0.1, 0.0, 0.2))
    assert s.pose.yaw == pytest.approx(math.pi / 2, abs=1e-6)
    (laser,) = m.gazebo.specs(LaserPluginSpec)
    assert laser.topic == "/points" and laser.frame_id == "world"


def test_kinect_defaults() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo reference="base"><sensor type="depth" name="d">'
            '<plugin name="k" filename="libgazebo_ros_openni_kinect.so">'
            "<cameraName>cam</cameraName></plugin></sensor></gazebo>"
        )
    )
    (k,) = m.gazebo.specs(KinectPluginSpec)
    assert k.image_topic == "/cam/ir/image_raw"
    assert k.point_cloud_topic == "/cam/points"
    assert k.depth_image_topic == "/cam/depth/image_raw"
    assert (k.point_cloud_cutoff_m, k.point_cloud_cutoff_max_m) == (0.4, 5.0)


def test_unknown_plugins_are_kept_generically() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo><plugin name="ctrl" filename="libgazebo_ros_p3d.so">'
            "<robotNamespace>/mybot</robotNamespace><nested><a>1</a></nested></plugin></gazebo>"
        )
    )
    (p,) = m.gazebo.plugins
    assert not p.supported and p.spec is None and p.reference is None
    assert p.params == {"robotNamespace": "/mybot", "nested/a": "1"}
    assert m.gazebo.unsupported_plugins == (p,)


def test_reference_properties_and_material_colours() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo reference="lw"><mu1>0.5</mu1><mu2>0.25</mu2><fdir1>1 0 0</fdir1>'
            "<material>Gazebo/DarkGrey</material></gazebo>"
            '<gazebo reference="lw"><selfCollide>true</selfCollide><turnGravityOff>1'
            "</turnGravityOff></gazebo>"
            '<gazebo reference="left_joint"><provideFeedback>true</provideFeedback></gazebo>'
        )
    )
    ref = m.gazebo.references["lw"]
    assert (ref.mu1, ref.mu2, ref.fdir1, ref.self_collide) == (0.5, 0.25, (1.0, 0.0, 0.0), True)
    assert ref.rgba == (0.175, 0.175, 0.175, 1.0)
    assert ref.params == {"turnGravityOff": "1"}
    assert m.gazebo.references["left_joint"].params == {"provideFeedback": "true"}
    assert gazebo_material_rgba("Gazebo/FlatBlack") == (0.1, 0.1, 0.1, 1.0)
    assert gazebo_material_rgba("Gazebo/NoSuchThing") is None


def test_sensor_without_reference_is_an_error() -> None:
    with pytest.raises(URDFError, match=r"<gazebo>: a <sensor> needs <gazebo reference='link'>"):
        load_robot(with_gazebo('<gazebo><sensor type="ray" name="l"/></gazebo>'))


def test_imu_noise_per_axis_sdf_form() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo reference="base"><sensor type="imu" name="imu"><imu>'
            '<angular_velocity><x><noise type="gaussian"><mean>0.001</mean>'
            "<stddev>0.0002</stddev><bias_mean>0.00001</bias_mean></noise></x>"
            '</angular_velocity><linear_acceleration><x><noise type="gaussian">'
            "<stddev>0.017</stddev></noise></x></linear_acceleration></imu></sensor></gazebo>"
        )
    )
    imu = m.gazebo.sensor("imu").imu
    assert imu is not None
    assert (imu.rate.type, imu.rate.mean, imu.rate.stddev, imu.rate.bias_mean) == (
        "gaussian",
        0.001,
        0.0002,
        0.00001,
    )
    assert (imu.accel.type, imu.accel.stddev) == ("gaussian", 0.017)


def _lidar_noise(kind: str) -> str:
    return with_gazebo(
        '<gazebo reference="base"><sensor type="ray" name="l"><ray><scan><horizontal>'
        "<samples>10</samples><min_angle>-1</min_angle><max_angle>1</max_angle></horizontal>"
        "</scan><range><min>0.1</min><max>5</max></range>"
        f"<noise><type>{kind}</type><stddev>0.05</stddev></noise></ray>"
        '<plugin name="p" filename="libgazebo_ros_laser.so"><topicName>scan</topicName>'
        "<frameName>base</frameName></plugin></sensor></gazebo>"
    )


@pytest.mark.parametrize(
    ("kind", "stddev"), [("gaussian", 0.05), ("gaussian_quantized", 0.05), ("none", 0.0)]
)
def test_noise_types_gazebo_knows_and_what_the_simulator_adds(kind: str, stddev: float) -> None:
    from roverlab.sim.robot import sim_config_from_model

    m = load_robot(_lidar_noise(kind))
    assert m.gazebo.sensor("l").ray.noise_type == kind  # type: ignore[union-attr]
    (lidar,) = sim_config_from_model(m).lidars
    assert lidar.params.noise_stddev == stddev


def test_an_unknown_noise_type_is_refused_by_name() -> None:
    with pytest.raises(URDFError, match=r"<noise/type>: unknown noise type 'gausian' \(one of"):
        load_robot(_lidar_noise("gausian"))


def test_imu_noise_of_type_none_adds_nothing() -> None:
    from roverlab.sim.robot import sim_config_from_model

    def imu(kind: str) -> str:  # mybot's form: the noise block inside the plugin
        return with_gazebo(
            '<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"><bodyName>base</bodyName>'
            f"<imu><noise><type>{kind}</type><rate><stddev>0.01</stddev></rate></noise></imu>"
            "</plugin></gazebo>"
        )

    for kind, stddev in (("gaussian", 0.01), ("none", 0.0)):
        (sensor,) = sim_config_from_model(load_robot(imu(kind))).imus
        assert sensor.rate.stddev == stddev, kind


def test_imu_plugin_frame_defaults_to_body_and_needs_a_body() -> None:
    m = load_robot(
        with_gazebo(
            '<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"><bodyName>base</bodyName>'
            "</plugin></gazebo>"
        )
    )
    (p,) = m.gazebo.plugins
    assert p.spec is not None and p.spec == ImuPluginSpec(body_name="base", frame_id="base")
    assert p.spec.topic == "/default_imu" and p.spec.noise is None
    with pytest.raises(URDFError, match=r"<bodyName>: missing"):
        load_robot(
            with_gazebo('<gazebo><plugin name="i" filename="libgazebo_ros_imu.so"/></gazebo>')
        )
    with pytest.raises(URDFError, match=r"<bodyName> 'ghost' is not a link"):
        load_robot(
            with_gazebo(
                '<gazebo><plugin name="i" filename="libgazebo_ros_imu.so">'
                "<bodyName>ghost</bodyName></plugin></gazebo>"
            )
        )


def _drive(extra: str, mass: float | None) -> str:
    inertial = (
        f'<inertial><mass value="{mass}"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
        'izz="1"/></inertial>'
        if mass is not None
        else ""
    )
    return (
        f'<robot name="r"><link name="base">{inertial}</link><link name="lw"/><link name="rw"/>'
        '<joint name="left_joint" type="continuous"><parent link="base"/><child link="lw"/>'
        '</joint><joint name="right_joint" type="continuous"><parent link="base"/>'
        '<child link="rw"/></joint><gazebo><plugin name="d" '
        'filename="libgazebo_ros_diff_drive.so"><robotBaseFrame>base</robotBaseFrame>'
        f"<wheelDiameter>0.2</wheelDiameter>{extra}</plugin></gazebo></robot>"
    )


@pytest.mark.parametrize(
    ("extra", "mass", "limit"),
    [
        ("<wheelTorque>1</wheelTorque>", 10.0, 2.0),  # 2 T / (r m) = 2 / (0.1 * 10)
        ("<wheelTorque>1</wheelTorque><wheelAcceleration>1</wheelAcceleration>", 10.0, 1.0),
        ("<wheelTorque>1</wheelTorque><wheelAcceleration>5</wheelAcceleration>", 10.0, 2.0),
        ("", 10.0, 10.0),  # Gazebo's default wheelTorque, 5 N m: 2 * 5 / (0.1 * 10)
        ("<wheelTorque>1</wheelTorque>", None, 0.0),  # no mass: no torque limit (unlimited)
    ],
)
def test_wheel_torque_limits_the_acceleration(extra: str, mass: float | None, limit: float) -> None:
    from roverlab.sim.robot import sim_config_from_model

    config = sim_config_from_model(load_robot(_drive(extra, mass)))
    assert config.drive is not None
    assert config.drive.params.wheel_acceleration == pytest.approx(limit)


def test_diff_drive_settings_the_simulator_does_not_act_on_are_warned() -> None:
    from roverlab.description.check import robot_warnings

    flags = (
        "<publishWheelTF>true</publishWheelTF><publishWheelJointState>true</publishWheelJointState>"
    )
    warnings = robot_warnings(load_robot(_drive(flags, 1.0)))
    assert any("publishWheelTF is not simulated" in w for w in warnings), warnings
    assert any("legacyMode true swaps the wheels' speeds" in w for w in warnings), warnings
    quiet = robot_warnings(load_robot(_drive("<legacyMode>false</legacyMode>", 1.0)))
    assert not [w for w in quiet if "diff_drive" in w], quiet
