"""Every bundled robot loads, passes check, and carries the seeds' values."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from roverlab.description import (
    CameraPluginSpec,
    Cylinder,
    DiffDriveSpec,
    ImuPluginSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    Sphere,
    find_package,
    format_check,
    load_robot,
)
from roverlab.packages import BUNDLED_PACKAGES_DIR
from tests.description.conftest import (
    MBOT_SEED_XACRO,
    MBOT_XACRO,
    MYBOT_URDF,
    MYBOT_XACRO,
    MYCAR_XACRO,
)

ROBOT_FILES = [MYBOT_URDF, MYBOT_XACRO, MBOT_XACRO, MBOT_SEED_XACRO, MYCAR_XACRO]


@pytest.mark.parametrize(
    "path", ROBOT_FILES, ids=lambda p: str(p.relative_to(BUNDLED_PACKAGES_DIR))
)
def test_every_bundled_robot_loads_and_checks(path: Path) -> None:
    model = load_robot(path)
    text = format_check(model)
    assert text.startswith(f"robot name is: {model.name}\n")
    assert f"root Link: {model.root_link} has" in text
    assert model.root_link == "base_footprint"
    for link in model.links:
        if link != model.root_link:
            assert f"):  {link}" in text


def test_every_package_has_a_manifest_naming_it() -> None:
    for name in ("mbot_description", "bingda_tutorials", "mycar"):
        manifest = ET.parse(find_package(name) / "package.xml").getroot()
        assert manifest.findtext("name") == name


@pytest.mark.parametrize(
    "launch",
    sorted(BUNDLED_PACKAGES_DIR.glob("*/launch/*.launch")),
    ids=lambda p: p.name,
)
def test_launch_files_are_xml_and_point_at_existing_files(launch: Path) -> None:
    root = ET.parse(launch).getroot()
    assert root.tag == "launch"
    for ref in ("$(find mbot_description)", "$(find bingda_tutorials)", "$(find mycar)"):
        pkg = ref[len("$(find ") : -1]
        for text in launch.read_text().split(ref)[1:]:
            rel = text.split()[0].split("'")[0].split('"')[0]
            assert (find_package(pkg) / rel.lstrip("/")).exists(), f"{launch}: {ref}{rel}"


def test_world_files_are_sdf() -> None:
    worlds = sorted(BUNDLED_PACKAGES_DIR.glob("*/world*/*.world"))
    assert [w.name for w in worlds] == ["maze.world", "hui.world", "box_house.world"]
    for w in worlds:
        root = ET.parse(w).getroot()
        assert root.tag == "sdf" and root.find("world/model") is not None


# ------------------------------------------------------------------ bingda mybot
def test_mybot_xacro_keeps_the_urdf_and_adds_sensors() -> None:
    plain = load_robot(MYBOT_URDF)
    full = load_robot(MYBOT_XACRO)
    assert set(plain.links) < set(full.links)
    assert set(full.links) - set(plain.links) == {"imu", "base_camera_link", "base_laser_link"}
    for name, joint in plain.joints.items():
        assert full.joints[name] == joint
    assert full.link_transform("base_laser_link").translation == pytest.approx((0, 0, 0.06))
    assert full.link_transform("imu").translation == pytest.approx((0.08, 0, 0.025))


def test_mybot_lidar() -> None:
    m = load_robot(MYBOT_XACRO)
    lidar = m.gazebo.sensor("rplidar_sensor")
    assert lidar.type == "ray" and lidar.reference_link == "base_laser_link"
    assert lidar.update_rate_hz == 7.0 and lidar.visualize is False
    r = lidar.ray
    assert r is not None
    assert (r.samples, r.resolution) == (720, 0.5)
    assert (r.min_angle, r.max_angle) == (0.0, 6.28319)
    assert (r.range_min, r.range_max, r.range_resolution) == (0.12, 12.0, 0.015)
    assert (r.noise_type, r.noise_mean, r.noise_stddev) == ("gaussian", 0.0, 0.01)
    (laser,) = m.gazebo.specs(LaserPluginSpec)
    assert (laser.topic, laser.frame_id) == ("/scan", "base_laser_link")


def test_mybot_camera() -> None:
    m = load_robot(MYBOT_XACRO)
    cam = m.gazebo.sensor("csi Camera")
    assert cam.type == "camera" and cam.always_on
    c = cam.camera
    assert c is not None
    assert (c.width, c.height, c.format) == (640, 480, "R8G8B8")
    assert c.horizontal_fov == 1.085595
    assert (c.clip_near, c.clip_far) == (0.03, 100.0)
    assert c.focal_length_px == pytest.approx(320 / math.tan(1.085595 / 2))
    (spec,) = m.gazebo.specs(CameraPluginSpec)
    assert spec.camera_name == "/"
    assert (spec.image_topic, spec.camera_info_topic) == ("/image_raw", "/camera_info")
    assert (spec.frame_id, spec.update_rate_hz, spec.hack_baseline) == (
        "base_camera_link",
        30.0,
        0.07,
    )


def test_mybot_diff_drive_and_imu() -> None:
    m = load_robot(MYBOT_XACRO)
    dd = m.gazebo.diff_drive
    assert dd == DiffDriveSpec(
        command_topic="/cmd_vel",
        odometry_topic="/odom",
        odometry_frame="odom",
        robot_base_frame="base_footprint",
        publish_odom_tf=True,
        publish_wheel_tf=False,
        publish_wheel_joint_state=True,
        publish_tf=True,
        odometry_source="world",
        wheel_separation_m=0.18,
        wheel_diameter_m=0.05,
        wheel_acceleration=10.0,
        wheel_torque_nm=100.0,
        update_rate_hz=30.0,
        left_joint="left_wheel_joint",
        right_joint="right_wheel_joint",
        legacy_mode=False,
    )
    (imu,) = m.gazebo.specs(ImuPluginSpec)
    assert (imu.body_name, imu.frame_id, imu.topic, imu.service) == (
        "imu",
        "imu",
        "/imu",
        "/imu_service",
    )
    assert imu.noise is not None
    assert (imu.noise.rate.stddev, imu.noise.rate.bias_mean) == (2e-4, 0.0000075)
    assert (imu.noise.accel.stddev, imu.noise.accel.bias_mean) == (1.7e-2, 0.1)
    assert imu.noise.accel.bias_stddev == 0.001 and imu.noise.rate.type == "gaussian"
    assert m.gazebo.sensor("imu").type == "imu"


def test_mybot_gazebo_materials_and_friction() -> None:
    refs = load_robot(MYBOT_XACRO).gazebo.references
    assert refs["base_link"].material == "Gazebo/DarkGrey"
    assert refs["right_wheel_link"].rgba == (0.1, 0.1, 0.1, 1.0)
    left = refs["left_wheel_link"]
    assert (left.mu1, left.mu2, left.kp, left.kd) == (0.5, 0.5, 500000.0, 10.0)
    assert (left.min_depth, left.max_vel, left.fdir1) == (0.001, 1.0, (1.0, 0.0, 0.0))
    assert refs["ball_wheel_link"].mu1 == 0.1


def test_mybot_visual_args() -> None:
    m = load_robot(MYBOT_XACRO, args={"laser_visual": "true", "camera_visual": "true"})
    assert m.gazebo.sensor("rplidar_sensor").visualize is True
    assert m.gazebo.sensor("csi Camera").visualize is True
    assert m.gazebo.sensor("imu").visualize is False


# ------------------------------------------------------------------ mbot
def test_mbot_links_geometry_and_plugins() -> None:
    m = load_robot(MBOT_XACRO)
    assert sorted(m.links) == [
        "back_caster_link",
        "base_footprint",
        "base_link",
        "front_caster_link",
        "laser_link",
        "left_wheel_link",
        "right_wheel_link",
    ]
    assert load_robot(MBOT_SEED_XACRO).links.keys() == m.links.keys()
    wheel = m.links["left_wheel_link"].collisions[0].geometry
    caster = m.links["front_caster_link"].collisions[0].geometry
    assert isinstance(wheel, Cylinder) and isinstance(caster, Sphere)
    dd = m.gazebo.diff_drive
    assert dd is not None
    # the drive plugin agrees with the geometry
    left = m.link_transform("left_wheel_link").translation
    right = m.link_transform("right_wheel_link").translation
    assert dd.wheel_separation_m == pytest.approx(left[1] - right[1])
    assert dd.wheel_diameter_m == pytest.approx(2 * wheel.radius)
    # wheels and casters touch the ground (z = 0 in base_footprint)
    assert left[2] == pytest.approx(wheel.radius)
    assert m.link_transform("back_caster_link").translation[2] == pytest.approx(caster.radius)
    assert (dd.left_joint, dd.right_joint, dd.command_topic) == (
        "left_wheel_joint",
        "right_wheel_joint",
        "/cmd_vel",
    )
    lidar = m.gazebo.sensors_of_type("ray")[0]
    assert lidar.reference_link == "laser_link"
    assert lidar.ray is not None and lidar.ray.samples == 360
    assert (lidar.ray.range_min, lidar.ray.range_max) == (0.1, 6.0)
    (laser,) = m.gazebo.specs(LaserPluginSpec)
    assert (laser.topic, laser.frame_id) == ("/scan", "laser_link")


# ------------------------------------------------------------------ mycar
def test_mycar_dimensions() -> None:
    m = load_robot(MYCAR_XACRO)
    assert m.name == "car"
    base = m.links["base_link"].visuals[0].geometry
    assert base == Cylinder(radius=0.1, length=0.08)
    assert m.link_transform("base_link").translation == pytest.approx((0, 0, 0.015 + 0.04))
    wheel = m.links["left_wheel"].visuals[0].geometry
    assert wheel == Cylinder(radius=0.0325, length=0.015)
    assert m.links["front_wheel"].visuals[0].geometry == Sphere(0.0075)
    for link in m.links.values():
        if link.name != "base_footprint":
            assert link.inertial is not None and link.inertial.mass > 0
            assert link.collisions
    assert m.joints["front_wheel2base_link"].axis == pytest.approx((1 / math.sqrt(3),) * 3)


def test_mycar_sensors_and_plugins() -> None:
    m = load_robot(MYCAR_XACRO)
    dd = m.gazebo.diff_drive
    assert dd is not None
    assert (dd.wheel_separation_m, dd.wheel_diameter_m) == pytest.approx((0.2, 0.065))
    assert (dd.left_joint, dd.right_joint) == ("left_wheel2base_link", "right_wheel2base_link")
    lidar = m.gazebo.sensor("rplidar")
    assert lidar.reference_link == "laser" and lidar.ray is not None
    assert (lidar.ray.samples, lidar.ray.min_angle, lidar.ray.max_angle) == (360, -3.0, 3.0)
    assert (lidar.ray.range_min, lidar.ray.range_max) == (0.1, 30.0)
    assert m.gazebo.specs(LaserPluginSpec)[0].topic == "/scan"
    cam = m.gazebo.sensor("camera_node").camera
    assert cam is not None
    assert (cam.width, cam.height, cam.horizontal_fov, cam.noise_stddev) == (
        1280,
        720,
        1.3962634,
        0.007,
    )
    (cam_plugin,) = m.gazebo.specs(CameraPluginSpec)
    assert cam_plugin.image_topic == "/camera/image_raw"
    depth = m.gazebo.sensor("camera")
    assert depth.type == "depth" and depth.reference_link == "support"
    assert depth.camera is not None
    assert depth.camera.horizontal_fov == pytest.approx(60.0 * 3.141 / 180.0)
    (k,) = m.gazebo.specs(KinectPluginSpec)
    assert (k.image_topic, k.depth_image_topic, k.point_cloud_topic) == (
        "/camera/rgb/image_raw",
        "/camera/depth/image_raw",
        "/camera/depth/points",
    )
    assert (k.camera_info_topic, k.depth_image_camera_info_topic) == (
        "/camera/rgb/camera_info",
        "/camera/depth/camera_info",
    )
    assert (k.frame_id, k.baseline, k.point_cloud_cutoff_m, k.update_rate_hz) == (
        "support_depth",
        0.1,
        0.4,
        10.0,
    )
    # <baseline> is read by neither Gazebo's plugin nor roverlab: P[3] comes from hackBaseline
    assert k.hack_baseline == 0.0


def test_mycar_rviz_config_lists_the_robot_links() -> None:
    config = yaml.safe_load((find_package("mycar") / "config" / "test.rviz").read_text())
    displays = config["Visualization Manager"]["Displays"]
    (robot_display,) = [d for d in displays if d["Class"] == "rviz/RobotModel"]
    listed = set(robot_display["Links"]) - {
        "All Links Enabled",
        "Expand Joint Details",
        "Expand Link Details",
        "Expand Tree",
        "Link Tree Style",
    }
    assert listed == set(load_robot(MYCAR_XACRO).links)
    assert config["Visualization Manager"]["Global Options"]["Fixed Frame"] == "odom"
