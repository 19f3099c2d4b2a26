"""Typed ``<gazebo>`` extensions of a URDF: sensors, plugins and per-link properties.

A URDF carries Gazebo's simulation settings in ``<gazebo>`` tags::

    <gazebo reference="base_laser_link">          <!-- a link (or joint) -->
      <material>Gazebo/FlatBlack</material>
      <sensor type="ray" name="rplidar_sensor"> ... <plugin filename="libgazebo_ros_laser.so">
    </gazebo>
    <gazebo>                                      <!-- the model -->
      <plugin filename="libgazebo_ros_diff_drive.so"> ... </plugin>
    </gazebo>

This module reads them into frozen dataclasses with SI units, applying the defaults of SDF
and of the ``gazebo_ros`` plugins (ROS 1, ``gazebo_plugins``) for elements left out, and
resolving topic and frame names the way the plugins do: a camera's image topic is
``<robotNamespace>/<cameraName>/<imageTopicName>`` (``/camera/image_raw``; with
``cameraName`` ``/`` it is ``/image_raw``), a relative ``topicName`` lives in the robot
namespace (``scan`` -> ``/scan``), and frames get the namespace as tf prefix.

Every plugin is kept with its raw ``params`` (element name -> text; nested elements as
``a/b/c``); plugins whose filename is in :data:`PLUGIN_SPECS` also get a typed ``spec``.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Final, Literal, TypeVar

from roverlab.description.errors import URDFError
from roverlab.geometry import Transform3, quat_from_rpy

__all__ = [
    "GAZEBO_MATERIALS",
    "PLUGIN_SPECS",
    "SENSOR_TYPES",
    "CameraPluginSpec",
    "CameraSpec",
    "DiffDriveSpec",
    "GazeboExtensions",
    "GazeboPlugin",
    "GazeboReference",
    "GazeboSensor",
    "ImuPluginSpec",
    "ImuSpec",
    "KinectPluginSpec",
    "LaserPluginSpec",
    "NoiseSpec",
    "PluginSpec",
    "RaySpec",
    "ScanAxis",
    "gazebo_material_rgba",
    "parse_gazebo",
    "resolve_frame",
    "resolve_topic",
]

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
    """``libgazebo_ros_diff_drive.so`` with gazebo_ros' defaults for missing elements.

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

    @property
    def wheel_radius_m(self) -> float:
        return self.wheel_diameter_m / 2.0

    @property
    def joint_states_topic(self) -> str:
        """Where wheel joint states go when ``publish_wheel_joint_state``."""
        return resolve_topic(self.robot_namespace, "joint_states")


@dataclass(frozen=True, slots=True)
class LaserPluginSpec:
    """``libgazebo_ros_laser.so`` / ``libgazebo_ros_gpu_laser.so`` (defaults ``/world``)."""

    topic: str = "/world"
    frame_id: str = "world"
    robot_namespace: str = ""


@dataclass(frozen=True, slots=True)
class CameraPluginSpec:
    """``libgazebo_ros_camera.so`` (GazeboRosCameraUtils' defaults)."""

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
    """``libgazebo_ros_openni_kinect.so``: RGB, depth image, point cloud, camera infos."""

    camera_name: str = ""
    image_topic: str = "/ir/image_raw"
    depth_image_topic: str = "/depth/image_raw"
    point_cloud_topic: str = "/points"
    camera_info_topic: str = "/ir/camera_info"
    depth_image_camera_info_topic: str = "/depth/camera_info"
    frame_id: str = "world"
    baseline: float = 0.0
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
    """``libgazebo_ros_imu.so`` (a model plugin reading the pose of link ``body_name``).

    ``noise`` is the plugin's ``<imu><noise>`` block when it has one (as bingda's mybot).
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


PluginSpec = DiffDriveSpec | LaserPluginSpec | CameraPluginSpec | KinectPluginSpec | ImuPluginSpec
_SpecT = TypeVar(
    "_SpecT", DiffDriveSpec, LaserPluginSpec, CameraPluginSpec, KinectPluginSpec, ImuPluginSpec
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
    elements (``topic``, ...). Exactly one of ``ray``/``camera``/``imu`` is set for the
    supported types (``ray``/``gpu_ray``, ``camera``/``depth``, ``imu``).
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
    def unsupported_plugins(self) -> tuple[GazeboPlugin, ...]:
        return tuple(p for p in self.plugins if not p.supported)

    @property
    def unsupported_sensors(self) -> tuple[GazeboSensor, ...]:
        return tuple(s for s in self.sensors if not s.supported)


# --------------------------------------------------------------------------- parsing
class _Values:
    """Typed reads of child-element text, errors naming ``where``."""

    def __init__(self, values: Mapping[str, str], where: str) -> None:
        self.values = values
        self.where = where

    def fail(self, key: str, problem: str) -> URDFError:
        return URDFError(f"{self.where}: <{key}>: {problem}")

    def text(self, key: str, default: str) -> str:
        value = self.values.get(key)
        return default if value is None else value.strip()

    def noise_type(self, key: str) -> str:
        """A ``<noise><type>``: Gazebo's ``none``, ``gaussian`` or ``gaussian_quantized``
        (Gazebo prints an error and adds no noise for any other; roverlab refuses it)."""
        value = self.text(key, "none")
        if value not in NOISE_TYPES:
            raise self.fail(key, f"unknown noise type '{value}' (one of {', '.join(NOISE_TYPES)})")
        return value

    def number(self, key: str, default: float) -> float:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        try:
            value = float(raw)
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not a number") from None
        if not math.isfinite(value):
            raise self.fail(key, f"'{raw.strip()}' is not a finite number")
        return value

    def non_negative(self, key: str, default: float) -> float:
        value = self.number(key, default)
        if value < 0:
            raise self.fail(key, f"{value:g} must not be negative")
        return value

    def integer(self, key: str, default: int, *, minimum: int = 0) -> int:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        try:
            value = int(raw.strip())
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not an integer") from None
        if value < minimum:
            raise self.fail(key, f"{value} must be >= {minimum}")
        return value

    def flag(self, key: str, default: bool) -> bool:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        word = raw.strip().lower()
        if word in ("true", "1"):
            return True
        if word in ("false", "0"):
            return False
        raise self.fail(key, f"'{raw.strip()}' is not a boolean (true/false/1/0)")

    def vector(self, key: str, default: tuple[float, float, float]) -> tuple[float, float, float]:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        parts = raw.split()
        try:
            nums = [float(p) for p in parts]
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not 3 numbers") from None
        if len(nums) != 3 or not all(math.isfinite(v) for v in nums):
            raise self.fail(key, f"'{raw.strip()}' is not 3 finite numbers")
        return (nums[0], nums[1], nums[2])


def _flatten(elem: ET.Element, prefix: str = "") -> dict[str, str]:
    """Child element texts by tag; nested elements as ``a/b`` (the first occurrence wins)."""
    out: dict[str, str] = {}
    for child in elem:
        if not isinstance(child.tag, str):
            continue
        key = prefix + child.tag
        if len(child):
            for k, v in _flatten(child, key + "/").items():
                out.setdefault(k, v)
        else:
            out.setdefault(key, (child.text or "").strip())
    return out


def _noise(values: _Values, prefix: str) -> NoiseSpec:
    return NoiseSpec(
        type=values.noise_type(prefix + "type"),
        mean=values.number(prefix + "mean", 0.0),
        stddev=values.non_negative(prefix + "stddev", 0.0),
        bias_mean=values.number(prefix + "bias_mean", 0.0),
        bias_stddev=values.non_negative(prefix + "bias_stddev", 0.0),
    )


def _imu_noise(elem: ET.Element | None, where: str) -> ImuSpec | None:
    """``<imu>`` noise, in SDF 1.4 form (``noise/rate``, ``noise/accel``) or SDF 1.5+
    per-axis form (``angular_velocity/x/noise``; the x axis stands for all three)."""
    if elem is None:
        return None
    v = _Values(_flatten(elem), where + ": <imu>")
    keys = v.values.keys()
    if any(k.startswith("noise/") for k in keys):
        noise_type = v.noise_type("noise/type")
        return ImuSpec(
            rate=replace(_noise(v, "noise/rate/"), type=noise_type),
            accel=replace(_noise(v, "noise/accel/"), type=noise_type),
        )
    av = elem.find("angular_velocity/x/noise")
    la = elem.find("linear_acceleration/x/noise")

    def axis(noise: ET.Element | None, what: str) -> NoiseSpec:
        if noise is None:
            return NoiseSpec()
        values = _Values({**_flatten(noise), "type": noise.get("type", "none")},
                         f"{where}: <imu> {what}")  # fmt: skip
        return _noise(values, "")

    return ImuSpec(rate=axis(av, "angular_velocity"), accel=axis(la, "linear_acceleration"))


def _pose(text: str | None, where: str) -> Transform3:
    if text is None or not text.strip():
        return Transform3()
    try:
        nums = [float(p) for p in text.split()]
    except ValueError:
        raise URDFError(f"{where}: <pose>: '{text.strip()}' is not 6 numbers") from None
    if len(nums) != 6 or not all(math.isfinite(n) for n in nums):
        raise URDFError(f"{where}: <pose>: '{text.strip()}' is not 6 finite numbers")
    return Transform3.from_arrays(nums[:3], quat_from_rpy(nums[3], nums[4], nums[5]))


def _ray(elem: ET.Element, where: str) -> RaySpec:
    v = _Values(_flatten(elem), where + ": <ray>")
    vertical = None
    if elem.find("scan/vertical") is not None:
        vertical = ScanAxis(
            samples=v.integer("scan/vertical/samples", 1, minimum=1),
            resolution=v.non_negative("scan/vertical/resolution", 1.0),
            min_angle=v.number("scan/vertical/min_angle", 0.0),
            max_angle=v.number("scan/vertical/max_angle", 0.0),
        )
    spec = RaySpec(
        samples=v.integer("scan/horizontal/samples", 640, minimum=1),
        resolution=v.non_negative("scan/horizontal/resolution", 1.0),
        min_angle=v.number("scan/horizontal/min_angle", 0.0),
        max_angle=v.number("scan/horizontal/max_angle", 0.0),
        range_min=v.non_negative("range/min", 0.0),
        range_max=v.non_negative("range/max", 0.0),
        range_resolution=v.non_negative("range/resolution", 0.0),
        noise_mean=v.number("noise/mean", 0.0),
        noise_stddev=v.non_negative("noise/stddev", 0.0),
        noise_type=v.noise_type("noise/type"),
        vertical=vertical,
    )
    if spec.max_angle < spec.min_angle:
        raise v.fail("scan/horizontal", f"max_angle {spec.max_angle:g} < min_angle")
    if spec.range_max < spec.range_min:
        raise v.fail("range", f"max {spec.range_max:g} < min {spec.range_min:g}")
    return spec


def _camera(elem: ET.Element, where: str) -> CameraSpec:
    v = _Values(_flatten(elem), where + ": <camera>")
    spec = CameraSpec(
        horizontal_fov=v.number("horizontal_fov", 1.047),
        width=v.integer("image/width", 320, minimum=1),
        height=v.integer("image/height", 240, minimum=1),
        format=v.text("image/format", "R8G8B8"),
        clip_near=v.non_negative("clip/near", 0.1),
        clip_far=v.non_negative("clip/far", 100.0),
        noise_mean=v.number("noise/mean", 0.0),
        noise_stddev=v.non_negative("noise/stddev", 0.0),
        noise_type=v.noise_type("noise/type"),
        name=elem.get("name", ""),
    )
    if not 0.0 < spec.horizontal_fov < math.pi:
        raise v.fail("horizontal_fov", f"{spec.horizontal_fov:g} rad is not in (0, pi)")
    return spec


# ----------------------------------------------------------------- plugin specs
def _diff_drive(v: _Values, plugin: GazeboPlugin) -> DiffDriveSpec:
    ns = v.text("robotNamespace", "")
    source = v.text("odometrySource", "world")
    if source not in ("world", "encoder"):
        raise v.fail("odometrySource", f"'{source}' is not 'world' or 'encoder'")
    spec = DiffDriveSpec(
        command_topic=resolve_topic(ns, v.text("commandTopic", "cmd_vel")),
        odometry_topic=resolve_topic(ns, v.text("odometryTopic", "odom")),
        odometry_frame=resolve_frame(ns, v.text("odometryFrame", "odom")),
        robot_base_frame=resolve_frame(ns, v.text("robotBaseFrame", "base_footprint")),
        publish_odom_tf=v.flag("publishOdomTF", True),
        publish_odom_topic=v.flag("publishOdomTopic", True),
        publish_wheel_tf=v.flag("publishWheelTF", False),
        publish_wheel_joint_state=v.flag("publishWheelJointState", False),
        publish_tf=v.flag("publishTf", True),
        odometry_source="world" if source == "world" else "encoder",
        wheel_separation_m=v.non_negative("wheelSeparation", 0.34),
        wheel_diameter_m=v.non_negative("wheelDiameter", 0.15),
        wheel_acceleration=v.non_negative("wheelAcceleration", 0.0),
        wheel_torque_nm=v.non_negative("wheelTorque", 5.0),
        update_rate_hz=v.non_negative("updateRate", 100.0),
        left_joint=v.text("leftJoint", "left_joint"),
        right_joint=v.text("rightJoint", "right_joint"),
        legacy_mode=v.flag("legacyMode", True),
        robot_namespace=ns,
    )
    if spec.wheel_separation_m <= 0 or spec.wheel_diameter_m <= 0:
        raise v.fail("wheelSeparation", "wheelSeparation and wheelDiameter must be > 0")
    return spec


def _laser(v: _Values, plugin: GazeboPlugin) -> LaserPluginSpec:
    ns = v.text("robotNamespace", "")
    return LaserPluginSpec(
        topic=resolve_topic(ns, v.text("topicName", "/world")),
        frame_id=resolve_frame(ns, v.text("frameName", "/world")),
        robot_namespace=ns,
    )


def _distortion(v: _Values, name: str) -> float:
    """``distortionK1`` (what the camera utils read) or ``distortion_k1`` (seen in tutorials)."""
    camel = "distortion" + name.upper()
    snake = "distortion_" + name.lower()
    return v.number(camel, v.number(snake, 0.0))


def _camera_plugin(v: _Values, plugin: GazeboPlugin) -> CameraPluginSpec:
    ns = v.text("robotNamespace", "")
    name = v.text("cameraName", "")
    camera_ns = f"{ns}/{name}"
    return CameraPluginSpec(
        camera_name=name,
        image_topic=resolve_topic(camera_ns, v.text("imageTopicName", "image_raw")),
        camera_info_topic=resolve_topic(camera_ns, v.text("cameraInfoTopicName", "camera_info")),
        frame_id=resolve_frame(ns, v.text("frameName", "/world")),
        update_rate_hz=v.non_negative("updateRate", 0.0),
        hack_baseline=v.number("hackBaseline", 0.0),
        distortion_k1=_distortion(v, "k1"),
        distortion_k2=_distortion(v, "k2"),
        distortion_k3=_distortion(v, "k3"),
        distortion_t1=_distortion(v, "t1"),
        distortion_t2=_distortion(v, "t2"),
        robot_namespace=ns,
    )


def _kinect(v: _Values, plugin: GazeboPlugin) -> KinectPluginSpec:
    ns = v.text("robotNamespace", "")
    name = v.text("cameraName", "")
    cns = f"{ns}/{name}"
    spec = KinectPluginSpec(
        camera_name=name,
        image_topic=resolve_topic(cns, v.text("imageTopicName", "ir/image_raw")),
        depth_image_topic=resolve_topic(cns, v.text("depthImageTopicName", "depth/image_raw")),
        point_cloud_topic=resolve_topic(cns, v.text("pointCloudTopicName", "points")),
        camera_info_topic=resolve_topic(cns, v.text("cameraInfoTopicName", "ir/camera_info")),
        depth_image_camera_info_topic=resolve_topic(
            cns, v.text("depthImageCameraInfoTopicName", "depth/camera_info")
        ),
        frame_id=resolve_frame(ns, v.text("frameName", "/world")),
        baseline=v.number("baseline", v.number("hackBaseline", 0.0)),
        point_cloud_cutoff_m=v.non_negative("pointCloudCutoff", 0.4),
        point_cloud_cutoff_max_m=v.non_negative("pointCloudCutoffMax", 5.0),
        update_rate_hz=v.non_negative("updateRate", 0.0),
        distortion_k1=_distortion(v, "k1"),
        distortion_k2=_distortion(v, "k2"),
        distortion_k3=_distortion(v, "k3"),
        distortion_t1=_distortion(v, "t1"),
        distortion_t2=_distortion(v, "t2"),
        robot_namespace=ns,
    )
    if spec.point_cloud_cutoff_max_m < spec.point_cloud_cutoff_m:
        raise v.fail("pointCloudCutoffMax", "is below pointCloudCutoff")
    return spec


def _imu_plugin(v: _Values, plugin: GazeboPlugin, elem: ET.Element) -> ImuPluginSpec:
    ns = v.text("robotNamespace", "")
    body = v.text("bodyName", "")
    if not body:
        raise v.fail("bodyName", "missing (the imu plugin needs the link to measure)")
    return ImuPluginSpec(
        body_name=body,
        frame_id=v.text("frameName", body).lstrip("/"),
        topic=resolve_topic(ns, v.text("topicName", "/default_imu")),
        service=resolve_topic(ns, v.text("serviceName", "/default_imu")),
        gaussian_noise=v.non_negative("gaussianNoise", 0.0),
        update_rate_hz=v.non_negative("updateRate", 0.0),
        xyz_offset=v.vector("xyzOffset", (0.0, 0.0, 0.0)),
        rpy_offset=v.vector("rpyOffset", (0.0, 0.0, 0.0)),
        noise=_imu_noise(elem.find("imu"), v.where),
        robot_namespace=ns,
    )


_SpecParser = Callable[[_Values, GazeboPlugin, ET.Element], PluginSpec]

PLUGIN_SPECS: Final[Mapping[str, _SpecParser]] = MappingProxyType(
    {
        "libgazebo_ros_diff_drive.so": lambda v, p, e: _diff_drive(v, p),
        "libgazebo_ros_laser.so": lambda v, p, e: _laser(v, p),
        "libgazebo_ros_gpu_laser.so": lambda v, p, e: _laser(v, p),
        "libgazebo_ros_camera.so": lambda v, p, e: _camera_plugin(v, p),
        "libgazebo_ros_openni_kinect.so": lambda v, p, e: _kinect(v, p),
        "libgazebo_ros_imu.so": _imu_plugin,
    }
)
"""Plugin filenames roverlab understands -> parser of their typed spec."""


def _plugin(elem: ET.Element, where: str, sensor: str | None, link: str | None) -> GazeboPlugin:
    name = elem.get("name", "")
    filename = elem.get("filename", "")
    label = f"{where}: <plugin name='{name}' filename='{filename}'>"
    if not filename:
        raise URDFError(f"{label}: missing filename")
    plugin = GazeboPlugin(
        name=name,
        filename=filename,
        reference=sensor,
        link=link,
        params=MappingProxyType(_flatten(elem)),
    )
    parser = PLUGIN_SPECS.get(filename)
    if parser is None:
        return plugin
    spec = parser(_Values(plugin.params, label), plugin, elem)
    return GazeboPlugin(plugin.name, filename, sensor, link, plugin.params, spec)


_SENSOR_KEYS: Final = frozenset(
    {"always_on", "update_rate", "visualize", "pose", "ray", "lidar", "camera", "imu", "plugin"}
)


def _sensor(elem: ET.Element, link: str, where: str) -> GazeboSensor:
    name = elem.get("name", "")
    stype = elem.get("type", "")
    label = f"{where}: <sensor name='{name}' type='{stype}'>"
    if not name or not stype:
        raise URDFError(f"{label}: a sensor needs a name and a type")
    simple = {c.tag: (c.text or "").strip() for c in elem if isinstance(c.tag, str) and not len(c)}
    v = _Values(simple, label)
    ray = camera = imu = None
    if stype in ("ray", "gpu_ray"):
        ray_elem = elem.find("ray")
        if ray_elem is None:
            ray_elem = elem.find("lidar")  # SDF >= 1.7 name
        ray = _ray(ray_elem if ray_elem is not None else ET.Element("ray"), label)
    elif stype in ("camera", "depth"):
        cam_elem = elem.find("camera")
        camera = _camera(cam_elem if cam_elem is not None else ET.Element("camera"), label)
    elif stype == "imu":
        imu = _imu_noise(elem.find("imu"), label) or ImuSpec()
    plugins = tuple(_plugin(p, label, name, link) for p in elem.findall("plugin"))
    return GazeboSensor(
        name=name,
        type=stype,
        reference_link=link,
        pose=_pose(simple.get("pose"), label),
        update_rate_hz=v.non_negative("update_rate", 0.0),
        always_on=v.flag("always_on", False),
        visualize=v.flag("visualize", False),
        ray=ray,
        camera=camera,
        imu=imu,
        plugins=plugins,
        params=MappingProxyType({k: t for k, t in simple.items() if k not in _SENSOR_KEYS}),
    )


_REFERENCE_KEYS: Final = {
    "material": "material",
    "mu1": "mu1",
    "mu2": "mu2",
    "kp": "kp",
    "kd": "kd",
    "minDepth": "min_depth",
    "maxVel": "max_vel",
    "fdir1": "fdir1",
    "selfCollide": "self_collide",
    "gravity": "gravity",
}


def _reference(name: str, values: dict[str, str], where: str) -> GazeboReference:
    v = _Values(values, where)

    def opt(key: str) -> float | None:
        return v.number(key, math.nan) if key in values else None

    return GazeboReference(
        reference=name,
        material=values.get("material") or None,
        mu1=opt("mu1"),
        mu2=opt("mu2"),
        kp=opt("kp"),
        kd=opt("kd"),
        min_depth=opt("minDepth"),
        max_vel=opt("maxVel"),
        fdir1=v.vector("fdir1", (0.0, 0.0, 0.0)) if "fdir1" in values else None,
        self_collide=v.flag("selfCollide", False) if "selfCollide" in values else None,
        gravity=v.flag("gravity", True) if "gravity" in values else None,
        params=MappingProxyType({k: t for k, t in values.items() if k not in _REFERENCE_KEYS}),
    )


def parse_gazebo(elements: Iterable[ET.Element], source: str) -> GazeboExtensions:
    """Read the top-level ``<gazebo>`` elements of a URDF, in document order.

    Raises:
        URDFError: a malformed value, naming ``source`` and the element.
    """
    ref_values: dict[str, dict[str, str]] = {}
    sensors: list[GazeboSensor] = []
    plugins: list[GazeboPlugin] = []
    model_params: dict[str, str] = {}
    for elem in elements:
        ref = elem.get("reference")
        where = f"{source}: <gazebo reference='{ref}'>" if ref else f"{source}: <gazebo>"
        for child in elem:
            if not isinstance(child.tag, str):
                continue
            if child.tag == "sensor":
                if not ref:
                    raise URDFError(f"{where}: a <sensor> needs <gazebo reference='link'>")
                sensor = _sensor(child, ref, where)
                sensors.append(sensor)
                plugins.extend(sensor.plugins)
            elif child.tag == "plugin":
                plugins.append(_plugin(child, where, None, ref))
            elif not len(child):
                target = ref_values.setdefault(ref, {}) if ref else model_params
                target[child.tag] = (child.text or "").strip()
        if ref:
            ref_values.setdefault(ref, {})
    references = {
        name: _reference(name, values, f"{source}: <gazebo reference='{name}'>")
        for name, values in ref_values.items()
    }
    return GazeboExtensions(
        references=MappingProxyType(references),
        sensors=tuple(sensors),
        plugins=tuple(plugins),
        model_params=MappingProxyType(model_params),
    )
