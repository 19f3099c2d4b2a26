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
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable, Mapping
from dataclasses import replace
from types import MappingProxyType
from typing import Final, TypedDict

from roverlab.description.errors import URDFError
from roverlab.description.gazebo_planar import parse_planar_move, parse_ros_control
from roverlab.description.gazebo_specs import (
    CameraPluginSpec,
    CameraSpec,
    DiffDriveSpec,
    GazeboExtensions,
    GazeboPlugin,
    GazeboReference,
    GazeboSensor,
    ImuPluginSpec,
    ImuSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    NoiseSpec,
    PluginSpec,
    RaySpec,
    ScanAxis,
    resolve_frame,
    resolve_topic,
)
from roverlab.description.gazebo_values import ElementValues, flatten_element
from roverlab.geometry import Transform3, quat_from_rpy

__all__ = ["DISTORTION_KEYS", "PLUGIN_SPECS", "REFERENCE_KEYS", "parse_gazebo"]


# --------------------------------------------------------------------------- parsing
def _noise(values: ElementValues, prefix: str) -> NoiseSpec:
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
    v = ElementValues(flatten_element(elem), where + ": <imu>")
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
        values = ElementValues({**flatten_element(noise), "type": noise.get("type", "none")},
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
    v = ElementValues(flatten_element(elem), where + ": <ray>")
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


def _lens_distortion(v: ElementValues) -> tuple[float, float, float, float, float]:
    """SDF ``<camera><distortion>``: k1, k2, k3, p1, p2 (default 0)."""
    k1, k2, k3, p1, p2 = (v.number(f"distortion/{k}", 0.0) for k in ("k1", "k2", "k3", "p1", "p2"))
    return (k1, k2, k3, p1, p2)


def _camera(elem: ET.Element, where: str) -> CameraSpec:
    v = ElementValues(flatten_element(elem), where + ": <camera>")
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
        lens_distortion=_lens_distortion(v) if elem.find("distortion") is not None else None,
    )
    if not 0.0 < spec.horizontal_fov < math.pi:
        raise v.fail("horizontal_fov", f"{spec.horizontal_fov:g} rad is not in (0, pi)")
    return spec


# ----------------------------------------------------------------- plugin specs
class _DriveNames(TypedDict):
    """The topics and frames both drive plugins read, with the same defaults."""

    command_topic: str
    odometry_topic: str
    odometry_frame: str
    robot_base_frame: str


def _drive_names(v: ElementValues, ns: str) -> _DriveNames:
    """Topics resolved in ``ns``, frames prefixed with it."""
    return _DriveNames(
        command_topic=resolve_topic(ns, v.text("commandTopic", "cmd_vel")),
        odometry_topic=resolve_topic(ns, v.text("odometryTopic", "odom")),
        odometry_frame=resolve_frame(ns, v.text("odometryFrame", "odom")),
        robot_base_frame=resolve_frame(ns, v.text("robotBaseFrame", "base_footprint")),
    )


def _checked_wheels(v: ElementValues, spec: DiffDriveSpec) -> DiffDriveSpec:
    """``spec``, once its wheel separation and diameter are known to be positive."""
    if spec.wheel_separation_m <= 0 or spec.wheel_diameter_m <= 0:
        raise v.fail("wheelSeparation", "wheelSeparation and wheelDiameter must be > 0")
    return spec


def _diff_drive(v: ElementValues, plugin: GazeboPlugin) -> DiffDriveSpec:
    ns = v.text("robotNamespace", "")
    source = v.text("odometrySource", "world")
    if source not in ("world", "encoder"):
        raise v.fail("odometrySource", f"'{source}' is not 'world' or 'encoder'")
    spec = DiffDriveSpec(
        **_drive_names(v, ns),
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
    return _checked_wheels(v, spec)


def _skid_steer(v: ElementValues, plugin: GazeboPlugin) -> DiffDriveSpec:
    """``libgazebo_ros_skid_steer_drive.so``: four wheels, the diff drive's kinematics;
    odometry is always the model's world pose, the odom transform only with
    ``broadcastTF`` (default false), ``torque`` (not ``wheelTorque``) on each wheel."""
    ns = v.text("robotNamespace", "")
    spec = DiffDriveSpec(
        **_drive_names(v, ns),
        publish_odom_tf=v.flag("broadcastTF", False),
        odometry_source="world",
        wheel_separation_m=v.non_negative("wheelSeparation", 0.4),
        wheel_diameter_m=v.non_negative("wheelDiameter", 0.15),
        wheel_torque_nm=v.non_negative("torque", 5.0),
        update_rate_hz=v.non_negative("updateRate", 100.0),
        left_joint=v.text("leftFrontJoint", "left_front_joint"),
        right_joint=v.text("rightFrontJoint", "right_front_joint"),
        rear_joints=(
            v.text("leftRearJoint", "left_rear_joint"),
            v.text("rightRearJoint", "right_rear_joint"),
        ),
        legacy_mode=False,
        robot_namespace=ns,
    )
    return _checked_wheels(v, spec)


def _laser(v: ElementValues, plugin: GazeboPlugin) -> LaserPluginSpec:
    ns = v.text("robotNamespace", "")
    return LaserPluginSpec(
        topic=resolve_topic(ns, v.text("topicName", "/world")),
        frame_id=resolve_frame(ns, v.text("frameName", "/world")),
        robot_namespace=ns,
    )


# GazeboRosCameraUtils' distortion coefficients: distortionK1 .. distortionT2
DISTORTION_KEYS: Final = ("k1", "k2", "k3", "t1", "t2")


def _distortions(v: ElementValues) -> dict[str, float]:
    """The five ``distortion_*`` fields of a camera plugin spec, from ``distortionK1``..
    ``distortionT2`` (GazeboRosCameraUtils reads only these names: a ``distortion_k1``
    seen in tutorials is ignored, and ``urdf check`` notes it)."""
    return {f"distortion_{k}": v.number("distortion" + k.upper(), 0.0) for k in DISTORTION_KEYS}


def _camera_plugin(v: ElementValues, plugin: GazeboPlugin) -> CameraPluginSpec:
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
        **_distortions(v),
        robot_namespace=ns,
    )


def _kinect(v: ElementValues, plugin: GazeboPlugin) -> KinectPluginSpec:
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
        baseline=v.number("baseline", 0.0),
        hack_baseline=v.number("hackBaseline", 0.0),
        point_cloud_cutoff_m=v.non_negative("pointCloudCutoff", 0.4),
        point_cloud_cutoff_max_m=v.non_negative("pointCloudCutoffMax", 5.0),
        update_rate_hz=v.non_negative("updateRate", 0.0),
        **_distortions(v),
        robot_namespace=ns,
    )
    if spec.point_cloud_cutoff_max_m < spec.point_cloud_cutoff_m:
        raise v.fail("pointCloudCutoffMax", "is below pointCloudCutoff")
    return spec


def _imu_plugin(v: ElementValues, plugin: GazeboPlugin, elem: ET.Element) -> ImuPluginSpec:
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


def _imu_sensor_plugin(v: ElementValues, plugin: GazeboPlugin, elem: ET.Element) -> ImuPluginSpec:
    """``libgazebo_ros_imu_sensor.so`` (noetic): the sensor's own measurements (with its
    ``<imu>`` noise, filled in by ``_sensor``) plus ``gaussianNoise``, at ``updateRateHZ``
    (default 1 Hz), on ``<robotNamespace>/<topicName>`` (default namespace: the model's
    name, default topic ``imu_data``); ``frameName`` is required."""
    if plugin.reference is None or plugin.link is None:
        raise URDFError(
            f"{v.where}: a sensor plugin: Gazebo loads it only inside "
            "<gazebo reference='link'><sensor type='imu'>"
        )
    ns = v.text("robotNamespace", "") if "robotNamespace" in v.values else "/" + v.model_name
    frame = v.text("frameName", "")
    if not frame:
        raise v.fail("frameName", "missing (Gazebo does not load the plugin without it)")
    return ImuPluginSpec(
        body_name=plugin.link,
        frame_id=frame.lstrip("/"),
        topic=resolve_topic(ns, v.text("topicName", "imu_data")),
        service="",
        gaussian_noise=v.non_negative("gaussianNoise", 0.0),
        update_rate_hz=v.non_negative("updateRateHZ", 1.0),
        xyz_offset=v.vector("xyzOffset", (0.0, 0.0, 0.0)),
        rpy_offset=v.vector("rpyOffset", (0.0, 0.0, 0.0)),
        robot_namespace=ns,
    )


_SpecParser = Callable[[ElementValues, GazeboPlugin, ET.Element], PluginSpec]

PLUGIN_SPECS: Final[Mapping[str, _SpecParser]] = MappingProxyType(
    {
        "libgazebo_ros_diff_drive.so": lambda v, p, e: _diff_drive(v, p),
        "libgazebo_ros_skid_steer_drive.so": lambda v, p, e: _skid_steer(v, p),
        "libgazebo_ros_planar_move.so": lambda v, p, e: parse_planar_move(v),
        "libgazebo_ros_control.so": lambda v, p, e: parse_ros_control(v),
        "libgazebo_ros_laser.so": lambda v, p, e: _laser(v, p),
        "libgazebo_ros_gpu_laser.so": lambda v, p, e: _laser(v, p),
        "libgazebo_ros_camera.so": lambda v, p, e: _camera_plugin(v, p),
        "libgazebo_ros_openni_kinect.so": lambda v, p, e: _kinect(v, p),
        "libgazebo_ros_imu.so": _imu_plugin,
        "libgazebo_ros_imu_sensor.so": _imu_sensor_plugin,
    }
)
"""Plugin filenames roverlab understands -> parser of their typed spec."""


def _plugin(
    elem: ET.Element, where: str, sensor: str | None, link: str | None, model_name: str
) -> GazeboPlugin:
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
        params=MappingProxyType(flatten_element(elem)),
    )
    parser = PLUGIN_SPECS.get(filename)
    if parser is None:
        return plugin
    spec = parser(ElementValues(plugin.params, label, model_name), plugin, elem)
    return GazeboPlugin(plugin.name, filename, sensor, link, plugin.params, spec)


_SENSOR_KEYS: Final = frozenset(
    {"always_on", "update_rate", "visualize", "pose", "ray", "lidar", "camera", "imu", "plugin"}
)


def _sensor_imu_plugin(plugin: GazeboPlugin, imu: ImuSpec | None, rate: float) -> GazeboPlugin:
    """An imu sensor plugin measures what its sensor measures: the sensor's noise, and
    no faster than the sensor updates (``rate`` 0: every physics step)."""
    spec = plugin.spec
    if plugin.filename != "libgazebo_ros_imu_sensor.so" or not isinstance(spec, ImuPluginSpec):
        return plugin
    hz = spec.update_rate_hz
    if rate > 0:
        hz = min(hz, rate) if hz > 0 else rate
    return replace(plugin, spec=replace(spec, noise=imu, update_rate_hz=hz))


def _sensor(elem: ET.Element, link: str, where: str, model_name: str) -> GazeboSensor:
    name = elem.get("name", "")
    stype = elem.get("type", "")
    label = f"{where}: <sensor name='{name}' type='{stype}'>"
    if not name or not stype:
        raise URDFError(f"{label}: a sensor needs a name and a type")
    simple = {c.tag: (c.text or "").strip() for c in elem if isinstance(c.tag, str) and not len(c)}
    v = ElementValues(simple, label)
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
    plugins = tuple(_plugin(p, label, name, link, model_name) for p in elem.findall("plugin"))
    rate = v.non_negative("update_rate", 0.0)
    if stype == "imu":
        plugins = tuple(_sensor_imu_plugin(p, imu, rate) for p in plugins)
    elif any(p.filename == "libgazebo_ros_imu_sensor.so" for p in plugins):
        raise URDFError(f"{label}: libgazebo_ros_imu_sensor.so needs a sensor of type 'imu'")
    return GazeboSensor(
        name=name,
        type=stype,
        reference_link=link,
        pose=_pose(simple.get("pose"), label),
        update_rate_hz=rate,
        always_on=v.flag("always_on", False),
        visualize=v.flag("visualize", False),
        ray=ray,
        camera=camera,
        imu=imu,
        plugins=plugins,
        params=MappingProxyType({k: t for k, t in simple.items() if k not in _SENSOR_KEYS}),
    )


# <gazebo reference> elements read into GazeboReference (URDF tag -> field)
REFERENCE_KEYS: Final = {
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
    v = ElementValues(values, where)

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
        params=MappingProxyType({k: t for k, t in values.items() if k not in REFERENCE_KEYS}),
    )


def parse_gazebo(
    elements: Iterable[ET.Element], source: str, *, model_name: str = ""
) -> GazeboExtensions:
    """Read the top-level ``<gazebo>`` elements of a URDF, in document order.

    ``model_name`` (the ``<robot name>``, which is the Gazebo model's name when spawned
    with ``-model`` the same) is the default namespace of plugins that use it.

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
                sensor = _sensor(child, ref, where, model_name)
                sensors.append(sensor)
                plugins.extend(sensor.plugins)
            elif child.tag == "plugin":
                plugins.append(_plugin(child, where, None, ref, model_name))
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
