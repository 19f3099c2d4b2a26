"""The typed forms of a URDF's ``<gazebo>`` extensions: sensor, plugin and link specs (frozen
dataclasses in SI units), Gazebo's material colours, and the plugins' topic and frame name
rules. :mod:`roverlab.description.gazebo` fills them from the XML.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Final, Literal, TypeVar

from roverlab.geometry import Transform3

SENSOR_TYPES: Final = frozenset({"ray", "gpu_ray", "camera", "depth", "imu"})
"""Sensor types roverlab reads into typed specs (others are kept, listed as unsupported)."""

RGBA = tuple[float, float, float, float]

GAZEBO_MATERIALS: Final[Mapping[str, RGBA]] = MappingProxyType(
    {  # diffuse colours of gazebo's media/materials/scripts/gazebo.material
        "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
        "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
        "Gazebo/FlatBlack": (0.1, 0.1, 0.1, 1.0),
        "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
        "Gazebo/Gray": (0.7, 0.7, 0.7, 1.0),
        "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
        "Gazebo/DarkGray": (0.175, 0.175, 0.175, 1.0),
        "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
        "Gazebo/RedBright": (0.87, 0.26, 0.07, 1.0),
        "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
        "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
        "Gazebo/SkyBlue": (0.13, 0.44, 0.70, 1.0),
        "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
        "Gazebo/ZincYellow": (0.9725, 0.9529, 0.2078, 1.0),
        "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
        "Gazebo/Turquoise": (0.0, 1.0, 1.0, 1.0),
        "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
        "Gazebo/Gold": (0.8, 0.64869, 0.120759, 1.0),
        "Gazebo/Indigo": (0.33, 0.0, 0.5, 1.0),
        "Gazebo/Wood": (0.6, 0.4, 0.2, 1.0),
        "Gazebo/WoodFloor": (0.5, 0.5, 0.5, 1.0),
        "Gazebo/Bricks": (0.6, 0.3, 0.2, 1.0),
        "Gazebo/PaintedWall": (1.0, 1.0, 1.0, 1.0),
        "Gazebo/Road": (0.8, 0.8, 0.8, 1.0),
        "Gazebo/GreyTransparent": (0.5, 0.5, 0.5, 0.5),
        "Gazebo/RedTransparent": (1.0, 0.0, 0.0, 0.5),
        "Gazebo/GreenTransparent": (0.0, 1.0, 0.0, 0.5),
        "Gazebo/BlueTransparent": (0.0, 0.0, 1.0, 0.5),
    }
)
"""RGBA of the common ``Gazebo/...`` material scripts (textured ones approximated)."""


def gazebo_material_rgba(name: str) -> RGBA | None:
    """RGBA of a Gazebo material script name, or None when roverlab does not know it."""
    return GAZEBO_MATERIALS.get(name.strip())


# --------------------------------------------------------------------------- names
def _clean_name(name: str) -> str:
    cleaned = "/" + re.sub(r"/+", "/", name).strip("/")
    return cleaned


def resolve_topic(namespace: str, name: str) -> str:
    """A ROS 1 graph name as a ``ros::NodeHandle(namespace)`` resolves it.

    An absolute ``name`` ignores the namespace; repeated slashes collapse (so a camera
    namespace ``"//"`` is the root).
    """
    if name.startswith("/"):
        return _clean_name(name)
    return _clean_name(f"/{namespace}/{name}")


def resolve_frame(namespace: str, frame: str) -> str:
    """A frame id as the plugins resolve it: ``tf::resolve(tf_prefix, frame)``.

    The tf prefix is the robot namespace without slashes; a leading ``/`` is dropped.
    """
    if frame.startswith("/"):
        return frame.lstrip("/")
    prefix = namespace.strip("/")
    return f"{prefix}/{frame}" if prefix else frame


# --------------------------------------------------------------------------- specs
NOISE_TYPES = ("none", "gaussian", "gaussian_quantized")


@dataclass(frozen=True, slots=True)
class NoiseSpec:
    """SDF ``<noise>``: type (``none``/``gaussian``), mean, stddev, and bias for IMUs."""

    type: str = "none"
    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0


@dataclass(frozen=True, slots=True)
class ScanAxis:
    """One axis of a ray sensor's ``<scan>`` (SDF defaults: 640 samples over 0 rad)."""

    samples: int = 640
    resolution: float = 1.0
    min_angle: float = 0.0
    max_angle: float = 0.0

    @property
    def range_count(self) -> int:
        """Rays returned, as Gazebo's ``RangeCount()``: samples x resolution."""
        return max(1, int(self.samples * self.resolution))

    @property
    def angle_increment(self) -> float:
        """Angle between returned rays (``LaserScan.angle_increment``)."""
        n = self.range_count
        return (self.max_angle - self.min_angle) / (n - 1) if n > 1 else 0.0


@dataclass(frozen=True, slots=True)
class RaySpec:
    """A ``ray``/``gpu_ray`` sensor: horizontal scan, range limits (m) and range noise.

    ``vertical`` is set when the scan has a ``<vertical>`` axis.
    """

    samples: int = 640
    resolution: float = 1.0
    min_angle: float = 0.0
    max_angle: float = 0.0
    range_min: float = 0.0
    range_max: float = 0.0
    range_resolution: float = 0.0
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    noise_type: str = "none"
    vertical: ScanAxis | None = None

    @property
    def horizontal(self) -> ScanAxis:
        return ScanAxis(self.samples, self.resolution, self.min_angle, self.max_angle)

    @property
    def range_count(self) -> int:
        """Rays per scan returned by Gazebo (samples x resolution)."""
        return self.horizontal.range_count

    @property
    def angle_increment(self) -> float:
        return self.horizontal.angle_increment


@dataclass(frozen=True, slots=True)
class CameraSpec:
    """A ``camera``/``depth`` sensor's ``<camera>`` (SDF defaults: 320x240, 1.047 rad)."""

    horizontal_fov: float = 1.047
    width: int = 320
    height: int = 240
    format: str = "R8G8B8"
    clip_near: float = 0.1
    clip_far: float = 100.0
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    noise_type: str = "none"
    name: str = ""
    lens_distortion: tuple[float, float, float, float, float] | None = None
    """SDF ``<distortion>`` (k1, k2, k3, p1, p2), which Gazebo applies to the rendered
    image; roverlab renders undistorted (``robot_warnings`` says so when it is not zero)."""

    @property
    def focal_length_px(self) -> float:
        """Pinhole focal length in pixels (what gazebo_ros_camera puts in CameraInfo)."""
        return self.width / (2.0 * math.tan(self.horizontal_fov / 2.0))

    @property
    def vertical_fov(self) -> float:
        return 2.0 * math.atan(self.height / (2.0 * self.focal_length_px))


@dataclass(frozen=True, slots=True)
class ImuSpec:
    """IMU noise: angular ``rate`` (rad/s) and linear ``accel`` (m/s^2)."""

    rate: NoiseSpec = NoiseSpec()
    accel: NoiseSpec = NoiseSpec()


@dataclass(frozen=True, slots=True)
class DiffDriveSpec:
    """``libgazebo_ros_diff_drive.so`` with gazebo_ros' defaults for missing elements, or
    ``libgazebo_ros_skid_steer_drive.so`` (four wheels, the same kinematics; see
    :attr:`rear_joints`).

    Topics are absolute, frames carry the tf prefix. ``wheel_acceleration`` is the limit
    on the change of wheel surface speed per second (m/s^2; 0: unlimited), as the plugin
    applies it. ``legacy_mode`` (default true, as the plugin) swaps left and right.
    """

    command_topic: str = "/cmd_vel"
    odometry_topic: str = "/odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    publish_odom_tf: bool = True
    publish_odom_topic: bool = True
    publish_wheel_tf: bool = False
    publish_wheel_joint_state: bool = False
    publish_tf: bool = True
    odometry_source: Literal["world", "encoder"] = "world"
    wheel_separation_m: float = 0.34
    wheel_diameter_m: float = 0.15
    wheel_acceleration: float = 0.0
    wheel_torque_nm: float = 5.0
    update_rate_hz: float = 100.0
    left_joint: str = "left_joint"
    right_joint: str = "right_joint"
    legacy_mode: bool = True
    robot_namespace: str = ""
    rear_joints: tuple[str, str] | None = None
    """``leftRearJoint``/``rightRearJoint`` of ``libgazebo_ros_skid_steer_drive.so``
    (None for the two-wheel diff drive); the front pair is ``left_joint``/``right_joint``."""

    @property
    def wheel_count(self) -> int:
        """Wheels the plugin drives (each with ``wheel_torque_nm``): 2, or 4 skid-steered."""
        return 2 if self.rear_joints is None else 4

    @property
    def wheel_radius_m(self) -> float:
        return self.wheel_diameter_m / 2.0

    @property
    def joint_states_topic(self) -> str:
        """Where wheel joint states go when ``publish_wheel_joint_state``."""
        return resolve_topic(self.robot_namespace, "joint_states")


@dataclass(frozen=True, slots=True)
class PlanarMoveSpec:
    """``libgazebo_ros_planar_move.so`` (ROS 1 noetic) with its defaults: a holonomic base
    whose body-frame velocity is set straight from ``cmd_vel``'s ``linear.x``,
    ``linear.y`` and ``angular.z`` (no acceleration limit, no wheels).

    Topics are absolute (in ``robotNamespace``); frames are not prefixed with the
    namespace (the plugin resolves them with the ``tf_prefix`` parameter only).
    ``odometry_rate_hz`` 0 publishes neither odometry nor the transform. A negative
    ``cmd_timeout_s`` (the default) keeps the last command forever; otherwise the body
    stops once no command came for that long. ``publish_odometry_tf`` is roverlab's: the
    noetic plugin always broadcasts ``odom -> robotBaseFrame`` (``publishOdometryTf``, as
    gazebo_ros_force_based_move names it, switches it off here).
    """

    command_topic: str = "/cmd_vel"
    odometry_topic: str = "/odom"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    odometry_rate_hz: float = 20.0
    cmd_timeout_s: float = -1.0
    publish_odometry_tf: bool = True
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class LaserPluginSpec:
    """``libgazebo_ros_laser.so`` / ``libgazebo_ros_gpu_laser.so`` (defaults ``/world``)."""

    topic: str = "/world"
    frame_id: str = "world"
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class CameraPluginSpec:
    """``libgazebo_ros_camera.so`` (GazeboRosCameraUtils' defaults).

    ``hack_baseline`` (m) and the ``distortion_*`` coefficients go into the published
    CameraInfo only (``p[3] = -fx * hack_baseline``, ``d = [k1, k2, t1, t2, k3]``), as
    GazeboRosCameraUtils puts them; the image is not distorted by them.
    """

    camera_name: str = ""
    image_topic: str = "/image_raw"
    camera_info_topic: str = "/camera_info"
    frame_id: str = "world"
    update_rate_hz: float = 0.0
    hack_baseline: float = 0.0
    distortion_k1: float = 0.0
    distortion_k2: float = 0.0
    distortion_k3: float = 0.0
    distortion_t1: float = 0.0
    distortion_t2: float = 0.0
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class KinectPluginSpec:
    """``libgazebo_ros_openni_kinect.so``: RGB, depth image, point cloud, camera infos.

    Its camera infos are GazeboRosCameraUtils', as the camera plugin's: ``hack_baseline``
    (``hackBaseline``) and the ``distortion_*`` coefficients. ``baseline`` is the
    ``<baseline>`` element tutorials put in the plugin: the plugin reads nothing by that
    name (``urdf check`` notes it).
    """

    camera_name: str = ""
    image_topic: str = "/ir/image_raw"
    depth_image_topic: str = "/depth/image_raw"
    point_cloud_topic: str = "/points"
    camera_info_topic: str = "/ir/camera_info"
    depth_image_camera_info_topic: str = "/depth/camera_info"
    frame_id: str = "world"
    baseline: float = 0.0
    hack_baseline: float = 0.0
    point_cloud_cutoff_m: float = 0.4
    point_cloud_cutoff_max_m: float = 5.0
    update_rate_hz: float = 0.0
    distortion_k1: float = 0.0
    distortion_k2: float = 0.0
    distortion_k3: float = 0.0
    distortion_t1: float = 0.0
    distortion_t2: float = 0.0
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class ImuPluginSpec:
    """``libgazebo_ros_imu.so`` (a model plugin reading the pose of link ``body_name``), or
    ``libgazebo_ros_imu_sensor.so`` (a plugin of an ``imu`` sensor: ``body_name`` is the
    sensor's link).

    ``noise`` is the plugin's ``<imu><noise>`` block when it has one (as bingda's mybot);
    for the sensor plugin it is the sensor's own ``<imu>`` noise. ``update_rate_hz`` 0
    means every physics step.
    """

    body_name: str
    frame_id: str
    topic: str = "/default_imu"
    service: str = "/default_imu"
    gaussian_noise: float = 0.0
    update_rate_hz: float = 0.0
    xyz_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    noise: ImuSpec | None = None
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class RosControlSpec:
    """``libgazebo_ros_control.so``: ros_control's hardware interface in Gazebo. The
    controllers it runs (diff_drive_controller, joint_state_controller) are configured on
    the parameter server under ``robot_namespace``, not in the URDF.

    ``control_period_s`` 0 means every physics step (the plugin's default).
    """

    robot_namespace: str = "/"
    control_period_s: float = 0.0
    robot_sim_type: str = "gazebo_ros_control/DefaultRobotHWSim"


PluginSpec = (
    DiffDriveSpec
    | RosControlSpec
    | PlanarMoveSpec
    | LaserPluginSpec
    | CameraPluginSpec
    | KinectPluginSpec
    | ImuPluginSpec
)
_SpecT = TypeVar(
    "_SpecT",
    DiffDriveSpec,
    RosControlSpec,
    PlanarMoveSpec,
    LaserPluginSpec,
    CameraPluginSpec,
    KinectPluginSpec,
    ImuPluginSpec,
)


@dataclass(frozen=True, slots=True)
class GazeboPlugin:
    """A ``<plugin>``: of the model (``reference`` None) or of sensor ``reference``.

    Args:
        name: the plugin's ``name`` attribute.
        filename: the shared library, e.g. ``libgazebo_ros_diff_drive.so``.
        reference: the sensor the plugin belongs to, None for a model plugin.
        link: the link of that sensor (or of the ``<gazebo reference>`` block).
        params: child element name -> text (nested elements as ``a/b``).
        spec: typed view when the filename is supported, else None.
    """

    name: str
    filename: str
    reference: str | None = None
    link: str | None = None
    params: Mapping[str, str] = field(default_factory=dict)
    spec: PluginSpec | None = None

    @property
    def supported(self) -> bool:
        return self.spec is not None


@dataclass(frozen=True, slots=True)
class GazeboSensor:
    """A ``<sensor>`` of link ``reference_link`` with SDF's defaults for missing elements.

    ``pose`` is the sensor frame in the link frame; ``params`` holds other simple child
    elements (``topic``, ...). ``always_on`` changes nothing in ROS: the gazebo_ros
    plugins switch their sensor on themselves (camera and laser while subscribed, the imu
    sensor plugin at load), so the simulator does too. Exactly one of ``ray``/``camera``/
    ``imu`` is set for the supported types (``ray``/``gpu_ray``, ``camera``/``depth``,
    ``imu``).
    """

    name: str
    type: str
    reference_link: str
    pose: Transform3 = field(default_factory=Transform3)
    update_rate_hz: float = 0.0
    always_on: bool = False
    visualize: bool = False
    ray: RaySpec | None = None
    camera: CameraSpec | None = None
    imu: ImuSpec | None = None
    plugins: tuple[GazeboPlugin, ...] = ()
    params: Mapping[str, str] = field(default_factory=dict)

    @property
    def supported(self) -> bool:
        return self.type in SENSOR_TYPES


@dataclass(frozen=True, slots=True)
class GazeboReference:
    """Simulation properties of one link (or joint) from ``<gazebo reference="...">``.

    ``material`` is a Gazebo script name (``Gazebo/DarkGrey``); ``mu1``/``mu2`` are the
    ODE friction coefficients; ``params`` holds every other simple child element.
    """

    reference: str
    material: str | None = None
    mu1: float | None = None
    mu2: float | None = None
    kp: float | None = None
    kd: float | None = None
    min_depth: float | None = None
    max_vel: float | None = None
    fdir1: tuple[float, float, float] | None = None
    self_collide: bool | None = None
    gravity: bool | None = None
    params: Mapping[str, str] = field(default_factory=dict)

    @property
    def rgba(self) -> RGBA | None:
        """RGBA of ``material`` when it is a known Gazebo material."""
        return gazebo_material_rgba(self.material) if self.material else None


@dataclass(frozen=True, slots=True)
class GazeboExtensions:
    """Everything the ``<gazebo>`` tags of a robot say.

    Args:
        references: per-link (or joint) properties, by reference name.
        sensors: every sensor, in document order.
        plugins: every plugin (model plugins and sensor plugins), in document order.
        model_params: simple children of reference-less ``<gazebo>`` blocks (``static``...).
    """

    references: Mapping[str, GazeboReference] = field(default_factory=dict)
    sensors: tuple[GazeboSensor, ...] = ()
    plugins: tuple[GazeboPlugin, ...] = ()
    model_params: Mapping[str, str] = field(default_factory=dict)

    def sensor(self, name: str) -> GazeboSensor:
        """The sensor called ``name``; KeyError if there is none."""
        for s in self.sensors:
            if s.name == name:
                return s
        raise KeyError(f"no gazebo sensor named '{name}'")

    def sensors_of_type(self, *types: str) -> tuple[GazeboSensor, ...]:
        return tuple(s for s in self.sensors if s.type in types)

    def plugins_of(self, filename: str) -> tuple[GazeboPlugin, ...]:
        return tuple(p for p in self.plugins if p.filename == filename)

    def specs(self, kind: type[_SpecT]) -> tuple[_SpecT, ...]:
        """Typed views of every plugin of one kind, e.g. ``specs(CameraPluginSpec)``."""
        return tuple(p.spec for p in self.plugins if isinstance(p.spec, kind))

    @property
    def diff_drive(self) -> DiffDriveSpec | None:
        """The (first) differential-drive plugin, if any."""
        found = self.specs(DiffDriveSpec)
        return found[0] if found else None

    @property
    def planar_move(self) -> PlanarMoveSpec | None:
        """The (first) planar-move (holonomic) plugin, if any."""
        found = self.specs(PlanarMoveSpec)
        return found[0] if found else None

    @property
    def drive(self) -> DiffDriveSpec | PlanarMoveSpec | None:
        """The plugin that moves the robot on ``cmd_vel``: the first diff-drive,
        skid-steer or planar-move plugin in document order."""
        for p in self.plugins:
            if isinstance(p.spec, DiffDriveSpec | PlanarMoveSpec):
                return p.spec
        return None

    @property
    def ros_control(self) -> RosControlSpec | None:
        """The ``libgazebo_ros_control.so`` plugin, if any."""
        found = self.specs(RosControlSpec)
        return found[0] if found else None

    @property
    def unsupported_plugins(self) -> tuple[GazeboPlugin, ...]:
        return tuple(p for p in self.plugins if not p.supported)

    @property
    def unsupported_sensors(self) -> tuple[GazeboSensor, ...]:
        return tuple(s for s in self.sensors if not s.supported)
