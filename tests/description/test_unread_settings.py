"""Settings a robot file gives that the simulation does not act on are named (notes for
what Gazebo's physics or Gazebo itself ignores too, warnings for what Gazebo would show
and roverlab does not); what it does act on is read under Gazebo's names."""

from __future__ import annotations

from roverlab.description import CameraPluginSpec, KinectPluginSpec, load_robot
from roverlab.description.check import format_check, robot_notes, robot_warnings
from tests.description.conftest import robot

_CAM_LINK = '<link name="cam"/>'


def _camera(sensor_type: str, plugin: str, params: str) -> str:
    return robot(
        f'{_CAM_LINK}<gazebo reference="cam"><sensor type="{sensor_type}" name="c">'
        f'<plugin name="p" filename="{plugin}">{params}</plugin></sensor></gazebo>'
    )


def test_camera_plugins_read_gazebo_s_names_and_note_the_others() -> None:
    # GazeboRosCameraUtils reads hackBaseline and distortionK1..T2 (both plugins); the
    # <baseline> and distortion_k1 of tutorials are read by nothing, in Gazebo too
    kinect = load_robot(
        _camera(
            "depth",
            "libgazebo_ros_openni_kinect.so",
            "<baseline>0.1</baseline><distortion_k1>0.2</distortion_k1>"
            "<distortionK2>0.3</distortionK2>",
        )
    )
    (k,) = kinect.gazebo.specs(KinectPluginSpec)
    assert (k.hack_baseline, k.distortion_k1, k.distortion_k2) == (0.0, 0.0, 0.3)
    (note,) = robot_notes(kinect)
    assert "<plugin libgazebo_ros_openni_kinect.so> on sensor 'c': baseline, distortion_k1 " in (
        note
    )
    assert "not read by the plugin (Gazebo ignores them too" in note
    assert "note: " + note in format_check(kinect).splitlines()
    camera = load_robot(
        _camera(
            "camera",
            "libgazebo_ros_camera.so",
            "<hackBaseline>0.07</hackBaseline><distortionK1>-0.1</distortionK1>",
        )
    )
    (c,) = camera.gazebo.specs(CameraPluginSpec)
    assert (c.hack_baseline, c.distortion_k1) == (0.07, -0.1)
    assert robot_notes(camera) == []


def _imu_plugin(params: str) -> str:
    return robot(
        '<link name="imu"/><gazebo><plugin name="imu" filename="libgazebo_ros_imu.so">'
        f"<bodyName>imu</bodyName>{params}</plugin></gazebo>"
    )


def test_imu_xyz_offset_is_noted_and_rpy_offset_listed() -> None:
    # gazebo_ros_imu: pos = pose.Pos() + offset_.Pos(), then never published (the Imu
    # message has no position); gazebo_ros_imu_sensor: "POSITION OFFSET, UNUSED"
    moved = load_robot(_imu_plugin("<xyzOffset>0 0 0.1</xyzOffset>"))
    (note,) = robot_notes(moved)
    assert "<plugin libgazebo_ros_imu.so>: xyzOffset has no effect" in note
    assert robot_notes(load_robot(_imu_plugin("<xyzOffset>0 0 0</xyzOffset>"))) == []
    turned = load_robot(_imu_plugin("<rpyOffset>3.14159 0 0</rpyOffset>"))
    assert robot_notes(turned) == []  # simulated (tests/sim/test_plugin_options.py)
    assert ", rpyOffset 3.14159 0 0" in format_check(turned)


def _ray(vertical: str, plugin: str = "libgazebo_ros_laser.so") -> str:
    return robot(
        '<link name="laser"/><gazebo reference="laser"><sensor type="ray" name="velo">'
        "<ray><scan><horizontal><samples>360</samples><min_angle>-3.14159</min_angle>"
        f"<max_angle>3.14159</max_angle></horizontal>{vertical}</scan>"
        "<range><min>0.3</min><max>30</max></range></ray>"
        f'<plugin name="p" filename="{plugin}"><topicName>scan</topicName></plugin>'
        "</sensor></gazebo>"
    )


def test_a_multi_row_laser_is_warned_about() -> None:
    # gazebo_ros_laser copies every range of the Gazebo scan (all rows, one after the
    # other) into one LaserScan; roverlab scans one level row
    rows = (
        "<vertical><samples>16</samples><min_angle>-0.26</min_angle>"
        "<max_angle>0.26</max_angle></vertical>"
    )
    (w,) = [w for w in robot_warnings(load_robot(_ray(rows))) if "<vertical>" in w]
    assert "sensor 'velo': <vertical> samples 16 not simulated: only one level row" in w
    assert "libgazebo_ros_laser.so publishes the 16 rows" in w
    assert "one LaserScan of 5760 ranges" in w
    # one vertical sample is Gazebo's level row (pitch 0, whatever its angles)
    one = "<vertical><samples>1</samples><min_angle>-0.2</min_angle></vertical>"
    assert not [w for w in robot_warnings(load_robot(_ray(one))) if "<vertical>" in w]


_WHEEL = (
    '<inertial><mass value="0.5"/>'
    '<inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="2e-3"/></inertial>'
)


def test_inertia_joint_dynamics_and_safety_controller_are_one_note() -> None:
    m = load_robot(
        robot(
            f'<link name="base">{_WHEEL}</link><link name="left">{_WHEEL}</link>'
            '<link name="right"/><link name="arm"/>'
            '<joint name="l" type="continuous"><parent link="base"/><child link="left"/>'
            '<dynamics damping="0.1" friction="0.05"/></joint>'
            '<joint name="r" type="continuous"><parent link="base"/><child link="right"/>'
            '<dynamics damping="0" friction="0"/></joint>'
            '<joint name="a" type="revolute"><parent link="base"/><child link="arm"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
            '<safety_controller k_velocity="10" soft_lower_limit="-0.9" soft_upper_limit="0.9"/>'
            "</joint>"
        )
    )
    (note,) = robot_notes(m)
    assert note.endswith(
        "settings of Gazebo's dynamics not simulated (the body moves kinematically; only "
        "link masses are read, for wheelTorque): <inertial> inertia and centre of mass of 2 links; "
        "<dynamics> damping and friction of 1 joint; <safety_controller> of 1 joint"
    ), note
    (detail,) = robot_notes(m, detail=True)
    assert detail.endswith(
        "<inertial> inertia and centre of mass (base, left); <dynamics> damping and friction "
        "(l); <safety_controller> (a)"
    ), detail
    assert "note: " + detail in format_check(m).splitlines()


def test_sdf_lens_distortion_is_warned_about() -> None:
    # Gazebo distorts the rendered image by the SDF <camera><distortion>; roverlab does not
    def cam(distortion: str) -> str:
        return robot(
            f'{_CAM_LINK}<gazebo reference="cam"><sensor type="camera" name="fisheye">'
            f"<camera>{distortion}</camera></sensor></gazebo>"
        )

    lens = "<distortion><k1>-0.25</k1><p2>0.001</p2><center>0.5 0.5</center></distortion>"
    m = load_robot(cam(lens))
    camera = m.gazebo.sensor("fisheye").camera
    assert camera is not None and camera.lens_distortion == (-0.25, 0.0, 0.0, 0.0, 0.001)
    (w,) = [w for w in robot_warnings(m) if "distortion" in w]
    assert "sensor 'fisheye': <camera><distortion> not simulated" in w
    flat = load_robot(cam("<distortion><k1>0</k1></distortion>"))
    assert not [w for w in robot_warnings(flat) if "distortion" in w]
