"""Seed 002's launch file shape (base, rplidar, static transform, gmapping, move_base,
usb_cam, face_detector, rviz) as one launch file on emulated devices."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import build_launch, load_launch
from roverlab.msgs import Twist, get_factory
from roverlab.msgs import classes as mc
from roverlab.world import BUNDLED_WORLDS_DIR
from tests.helpers.devices import ArduinoBaseEmulator, RplidarEmulator

pytestmark = pytest.mark.timeout(180)
FACE_PNG = BUNDLED_WORLDS_DIR / "models/poster_face/materials/textures/face.png"


def square_room_mm(angle_deg: np.ndarray) -> np.ndarray:
    """A 5 m x 4 m room around the lidar (device angles clockwise)."""
    a = np.radians(np.asarray(angle_deg))
    c, s = np.abs(np.cos(a)), np.abs(np.sin(a))
    with np.errstate(divide="ignore"):
        return 1000.0 * np.minimum(
            np.where(c > 0, 2.5 / c, np.inf), np.where(s > 0, 2.0 / s, np.inf)
        )


def seed_launch(tmp_path: Path, lidar_port: str, base_port: str, picture: Path) -> Path:
    bringup = find_package("roborts_bringup")
    params = (find_package("roborts_base") / "config/roborts_base_parameter.yaml").read_text()
    base_yaml = tmp_path / "roborts_base_parameter.yaml"
    base_yaml.write_text(params.replace("/dev/ttyUSB0", base_port))
    text = (bringup / "launch/Ymap_move_face1.launch").read_text()
    text = text.replace("/dev/ttyUSB4", lidar_port)
    text = text.replace("$(find roborts_base)/config/roborts_base_parameter.yaml", str(base_yaml))
    text = text.replace(
        '<include file="$(find roborts_bringup)/launch/usb_cam.launch"/>',
        '<include file="$(find roborts_bringup)/launch/usb_cam.launch">'
        f'<arg name="video_device" value="{picture}"/></include>',
    )
    path = tmp_path / "Ymap_move_face1.launch"
    path.write_text(text)
    return path


def test_seed_002_launch_on_emulated_devices(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", "0")
    picture = tmp_path / "operator.png"
    scene = np.full((480, 640, 3), 100, np.uint8)
    scene[140:340, 220:420] = cv2.imread(str(FACE_PNG))
    cv2.imwrite(str(picture), scene)
    lidar = RplidarEmulator(square_room_mm, seed=4).start()
    board = ArduinoBaseEmulator(seed=5).start()
    ctx = Context(clock="wall")
    try:
        spec = load_launch(seed_launch(tmp_path, lidar.port, board.port, picture))
        launch = build_launch(spec, context=ctx)
        names = {n.get_name() for n in launch.nodes}
        assert {
            "roborts_base_node",
            "rplidarNode",
            "base_link_base_laser_link_broadcaster",
            "slam_gmapping",
            "move_base",
            "usb_cam",
            "face_detector",
            "rviz",
        } <= names
        probe = ctx.create_node("probe")
        got: dict[str, list[object]] = {k: [] for k in ("scan", "odom", "map", "faces")}
        probe.create_subscription(mc.LaserScan, "/scan", got["scan"].append, 100)
        probe.create_subscription(mc.Odometry, "/odom", got["odom"].append, 100)
        probe.create_subscription(mc.OccupancyGrid, "/map", got["map"].append, 10)
        probe.create_subscription(
            get_factory("people_msgs/msg/PositionMeasurementArray"),
            "/face_detector/people_tracker_measurements_array",
            got["faces"].append,
            10,
        )
        cmd = probe.create_publisher(mc.Twist, "/cmd_vel", 10)
        probe.create_timer(0.1, lambda: cmd.publish(Twist(angular_z=0.3)))
        ctx.spin_for(7.0)
        scans = got["scan"]
        assert len(scans) >= 40  # ~10 Hz
        s = scans[-1]
        assert s.header.frame_id == "base_laser_link"  # type: ignore[attr-defined]
        ranges = np.asarray(s.ranges)  # type: ignore[attr-defined]
        mid = len(ranges) // 2  # scan angle 0: the device's 180 degrees
        ahead = ranges[mid - 3 : mid + 4]
        assert np.median(ahead[np.isfinite(ahead)]) == pytest.approx(2.5, abs=0.05)
        assert got["odom"] and got["odom"][-1].twist.twist.angular.z == pytest.approx(  # type: ignore[attr-defined]
            0.3, abs=0.05
        )
        assert board.speed[1] > 0 > board.speed[0]  # turning in place
        assert got["map"], "gmapping published no map"
        grid = got["map"][-1]
        assert grid.header.frame_id == "map"  # type: ignore[attr-defined]
        occupied = (np.asarray(grid.data) == 100).sum()  # type: ignore[attr-defined]
        assert occupied > 50  # the room's walls
        people = got["faces"][-1].people  # type: ignore[attr-defined]
        assert len(people) == 1 and people[0].name == "frontalface"
        assert math.isfinite(people[0].pos.x)
    finally:
        ctx.shutdown()
        lidar.close()
        board.close()
