"""What the simulator needs to know about a robot: its body, drive and sensors.

Built from a URDF/xacro model's ``<gazebo>`` extensions by :func:`roverlab.sim.robot.
sim_config_from_model`; kept separate so the simulator core never parses XML.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import Transform3
from roverlab.sim.diff_drive import DiffDriveParams
from roverlab.sim.sensors import CameraParams, ImuNoise, LidarParams

if TYPE_CHECKING:
    from roverlab.sim.ros_control import DiffDriveControllerConfig

__all__ = [
    "CameraSensor",
    "DepthSensor",
    "DiffDriveConfig",
    "ImuSensor",
    "LidarSensor",
    "PlanarMoveConfig",
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
class PlanarMoveConfig:
    """libgazebo_ros_planar_move.so: a holonomic base moved at the commanded body twist.

    Args:
        odometry_rate_hz: odometry (and transform) messages per second; 0: none.
        cmd_timeout_s: the body stops once no command came for this long; < 0: never.
        publish_odom_tf: broadcast ``odometry_frame -> robot_base_frame``.
        max_speed_mps: clamp of the commanded linear speed (a guard against absurd
            commands; the plugin has no limit), keeping its direction.
        max_turn_rate_rad_s: clamp of the commanded turn rate (the same guard).

    Raises:
        ValueError: a negative or non-finite rate or limit, a non-finite timeout.
    """

    command_topic: str = "cmd_vel"
    odometry_topic: str = "odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_rate_hz: float = 20.0
    cmd_timeout_s: float = -1.0
    publish_odom_tf: bool = True
    max_speed_mps: float = 5.0
    max_turn_rate_rad_s: float = 10.0

    def __post_init__(self) -> None:
        for name in ("odometry_rate_hz", "max_speed_mps", "max_turn_rate_rad_s"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be >= 0, got {v}")
        if not math.isfinite(self.cmd_timeout_s):
            raise ValueError(f"cmd_timeout_s must be finite, got {self.cmd_timeout_s}")


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
    rpy_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """The plugin's ``rpyOffset`` (rad): the orientation published is the offset's
    rotation times the body's (both IMU plugins)."""
    offset_turns_rates: bool = False
    """``libgazebo_ros_imu.so`` turns the angular velocity and linear acceleration by the
    ``rpyOffset`` rotation too; ``libgazebo_ros_imu_sensor.so`` does not."""


@dataclass(frozen=True)
class CameraSensor:
    name: str
    params: CameraParams
    mount: Transform3
    update_rate_hz: float
    image_topic: str
    info_topic: str
    frame_id: str
    distortion: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)
    """CameraInfo ``d`` (plumb_bob: k1, k2, t1, t2, k3) from the plugin's ``distortionK1``..
    ``distortionT2``: reported only, the image is not distorted (as in Gazebo)."""
    hack_baseline_m: float = 0.0
    """The plugin's ``hackBaseline``: CameraInfo ``p[3]`` (Tx) is ``-fx * hack_baseline_m``."""


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
    distortion: tuple[float, float, float, float, float] = (0.0, 0.0, 0.0, 0.0, 0.0)
    """CameraInfo ``d`` (plumb_bob: k1, k2, t1, t2, k3) from the plugin's ``distortionK1``..
    ``distortionT2``: reported only, the image is not distorted (as in Gazebo)."""
    hack_baseline_m: float = 0.0
    """The plugin's ``hackBaseline``: CameraInfo ``p[3]`` (Tx) is ``-fx * hack_baseline_m``."""


@dataclass(frozen=True)
class RobotSimConfig:
    """A robot as the simulator sees it.

    ``footprint`` is the body's outline on the floor (body frame, (K, 2), convex) and
    ``height_band`` the z range it occupies; ``base_frame`` is the frame the drive moves.
    ``drive`` is a differential (or skid-steer) drive, a holonomic planar move, ros_control's
    diff_drive_controller, or None.
    """

    name: str
    footprint: NDArray[np.float64]
    height_band: tuple[float, float]
    drive: DiffDriveConfig | PlanarMoveConfig | DiffDriveControllerConfig | None
    lidars: tuple[LidarSensor, ...] = ()
    imus: tuple[ImuSensor, ...] = ()
    cameras: tuple[CameraSensor, ...] = ()
    depth_cameras: tuple[DepthSensor, ...] = ()
    base_frame: str = "base_footprint"
    unsupported: tuple[str, ...] = field(default=())
