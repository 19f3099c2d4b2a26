"""What the simulator needs to know about a robot: its body, drive and sensors.

Built from a URDF/xacro model's ``<gazebo>`` extensions by :func:`roverlab.sim.robot.
sim_config_from_model`; kept separate so the simulator core never parses XML.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import Transform3
from roverlab.sim.diff_drive import DiffDriveParams
from roverlab.sim.sensors import CameraParams, ImuNoise, LidarParams

__all__ = [
    "CameraSensor",
    "DepthSensor",
    "DiffDriveConfig",
    "ImuSensor",
    "LidarSensor",
    "RobotSimConfig",
]


@dataclass(frozen=True)
class DiffDriveConfig:
    """libgazebo_ros_diff_drive.so: topics, frames and kinematics."""

    params: DiffDriveParams
    command_topic: str = "cmd_vel"
    odometry_topic: str = "odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    publish_odom_tf: bool = True
    publish_wheel_joint_state: bool = False
    odometry_source: str = "world"  # "world" or "encoder"
    update_rate_hz: float = 100.0
    left_joint: str = "left_wheel_joint"
    right_joint: str = "right_wheel_joint"


@dataclass(frozen=True)
class LidarSensor:
    name: str
    params: LidarParams
    mount: Transform3  # base frame -> sensor frame
    update_rate_hz: float
    topic: str
    frame_id: str


@dataclass(frozen=True)
class ImuSensor:
    name: str
    rate: ImuNoise
    accel: ImuNoise
    gaussian_noise: float
    update_rate_hz: float  # 0 = every physics step
    topic: str
    frame_id: str


@dataclass(frozen=True)
class CameraSensor:
    name: str
    params: CameraParams
    mount: Transform3
    update_rate_hz: float
    image_topic: str
    info_topic: str
    frame_id: str


@dataclass(frozen=True)
class DepthSensor:
    """libgazebo_ros_openni_kinect.so: RGB, depth image, point cloud."""

    name: str
    params: CameraParams
    mount: Transform3
    update_rate_hz: float
    image_topic: str
    info_topic: str
    depth_topic: str
    depth_info_topic: str
    points_topic: str
    frame_id: str
    point_cloud_cutoff: float = 0.0
    point_cloud_cutoff_max: float = float("inf")


@dataclass(frozen=True)
class RobotSimConfig:
    """A robot as the simulator sees it.

    ``footprint`` is the body's outline on the floor (body frame, (K, 2), convex) and
    ``height_band`` the z range it occupies; ``base_frame`` is the frame the drive moves.
    """

    name: str
    footprint: NDArray[np.float64]
    height_band: tuple[float, float]
    drive: DiffDriveConfig | None
    lidars: tuple[LidarSensor, ...] = ()
    imus: tuple[ImuSensor, ...] = ()
    cameras: tuple[CameraSensor, ...] = ()
    depth_cameras: tuple[DepthSensor, ...] = ()
    base_frame: str = "base_footprint"
    unsupported: tuple[str, ...] = field(default=())
