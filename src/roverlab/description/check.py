"""``check_urdf``'s report of a robot, plus what its ``<gazebo>`` tags declare.

The first part is byte for byte what urdfdom's ``check_urdf`` prints (children in the
order urdfdom keeps them: by joint name)::

    robot name is: mybot
    ---------- Successfully Parsed XML ---------------
    root Link: base_footprint has 1 child(ren)
        child(1):  base_link
            child(1):  ball_wheel_link
            ...

then the sensors and plugins, each marked supported or not by roverlab.
"""

from __future__ import annotations

import math
from typing import Final

from roverlab.description.errors import DescriptionError
from roverlab.description.gazebo import DISTORTION_KEYS, REFERENCE_KEYS
from roverlab.description.gazebo_specs import (
    CameraPluginSpec,
    DiffDriveSpec,
    GazeboPlugin,
    GazeboSensor,
    ImuPluginSpec,
    ImuSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    PlanarMoveSpec,
    RosControlSpec,
)
from roverlab.description.meshes import mesh_points
from roverlab.description.model import Mesh, RobotModel

__all__ = ["format_check", "format_tree", "robot_notes", "robot_warnings"]

# <gazebo reference> settings that the 2D simulator reads nowhere: its drive is kinematic
# (wheel slip is the gazebo node's wheel_slip) and a contact stops the body, so ODE's
# friction and contact parameters have nothing to act on. Only the material is used.
_CONTACT_SETTINGS = {tag: attr for tag, attr in REFERENCE_KEYS.items() if tag != "material"}


def robot_warnings(model: RobotModel) -> list[str]:
    """Everything about the robot a simulation will not do as the file says, one line
    each: urdfdom's accepted oddities, unsupported Gazebo plugins and sensors, and
    ``<gazebo reference>`` names that match nothing."""
    out = list(model.warnings)
    src = model.source
    plugins = list(dict.fromkeys(p.filename for p in model.gazebo.unsupported_plugins))
    sensors = list(dict.fromkeys(s.type for s in model.gazebo.unsupported_sensors))
    if plugins:
        out.append(f"{src}: Gazebo plugins not simulated (ignored): {', '.join(plugins)}")
    if sensors:
        out.append(f"{src}: Gazebo sensor types not simulated (ignored): {', '.join(sensors)}")
    out += _shape_warnings(model)
    out += _drive_warnings(model)
    out += _ray_warnings(model)
    out += [
        f"{src}: sensor '{s.name}': <camera><distortion> not simulated: the image is "
        "rendered without lens distortion (Gazebo distorts it)"
        for s in model.gazebo.sensors
        if s.camera is not None and any(s.camera.lens_distortion or ())
    ]
    unknown = [r for r in model.gazebo.references if r not in model.links and r not in model.joints]
    if unknown:
        out.append(
            f"{src}: <gazebo reference> names no link or joint (ignored): "
            + ", ".join(f"'{r}'" for r in unknown)
        )
    return out


def robot_notes(model: RobotModel, *, detail: bool = False) -> list[str]:
    """Settings of the robot that Gazebo's physics uses and the 2D simulator does not, by
    name: ODE friction and contact parameters of the links (``mu1``, ``kp``,
    ``selfCollide``...), other simple elements of a ``<gazebo reference>``, the
    model-level ones (``static``...), inertia tensors, joint ``<dynamics>`` and
    ``<safety_controller>``; and plugin elements Gazebo does not read either (a camera's
    ``<baseline>``, an IMU's ``xyzOffset``). Only ``material`` (the dashboard's colour) is
    read from a reference. Notes, not warnings: the bundled robots set them for Gazebo
    too, and nothing the simulation does depends on them. ``detail`` names the links (and
    joints) of each."""
    src = model.source
    settings: dict[str, list[str]] = {}
    for name, ref in model.gazebo.references.items():
        keys = [tag for tag, attr in _CONTACT_SETTINGS.items() if getattr(ref, attr) is not None]
        for tag in [*keys, *ref.params]:
            settings.setdefault(tag, []).append(name)
    out: list[str] = []
    if settings:
        if detail:
            listed = "; ".join(f"{tag} ({', '.join(links)})" for tag, links in settings.items())
        else:
            n = len({link for links in settings.values() for link in links})
            listed = f"{', '.join(settings)} on {n} link{'s' if n != 1 else ''}"
        out.append(
            f"{src}: <gazebo reference> settings not simulated (the drive is kinematic, a "
            f"contact stops the body): {listed}"
        )
    if model.gazebo.model_params:
        out.append(
            f"{src}: <gazebo> model settings not simulated: " + ", ".join(model.gazebo.model_params)
        )
    out += _physics_notes(model, detail)
    out += _camera_notes(model)
    out += [
        f"{src}: <plugin {p.filename}>: xyzOffset has no effect (sensor_msgs/Imu has no "
        "position: Gazebo's plugin adds the offset to a position it does not publish)"
        for p in model.gazebo.plugins
        if isinstance(p.spec, ImuPluginSpec) and any(p.spec.xyz_offset)
    ]
    return out


def _physics_notes(model: RobotModel, detail: bool) -> list[str]:
    """URDF settings for Gazebo's dynamics: links' inertia tensors and centres of mass
    (the masses are read: they bound the drive's acceleration under ``wheelTorque``),
    joints' ``<dynamics>`` damping and friction, ``<safety_controller>`` soft limits."""
    found = {
        "<inertial> inertia and centre of mass": [
            name for name, link in model.links.items() if link.inertial is not None
        ],
        "<dynamics> damping and friction": [
            name
            for name, j in model.joints.items()
            if j.dynamics is not None and (j.dynamics.damping or j.dynamics.friction)
        ],
        "<safety_controller>": [name for name, j in model.joints.items() if j.safety is not None],
    }
    parts = []
    for what, names in found.items():
        if not names:
            continue
        kind = "link" if what.startswith("<inertial>") else "joint"
        if detail:
            parts.append(f"{what} ({', '.join(names)})")
        else:
            parts.append(f"{what} of {len(names)} {kind}{'s' if len(names) != 1 else ''}")
    if not parts:
        return []
    return [
        f"{model.source}: settings of Gazebo's dynamics not simulated (the body moves "
        f"kinematically; only link masses are read, for wheelTorque): {'; '.join(parts)}"
    ]


# names tutorials give camera plugins that GazeboRosCameraUtils reads under other names
_CAMERA_MISNAMED: Final = ("baseline", *(f"distortion_{k}" for k in DISTORTION_KEYS))


def _camera_notes(model: RobotModel) -> list[str]:
    """Camera plugin elements that Gazebo's plugin does not read either (so the published
    CameraInfo ignores them there too): ``<baseline>`` and ``distortion_k1``..."""
    out: list[str] = []
    for plugin in model.gazebo.plugins:
        if not isinstance(plugin.spec, CameraPluginSpec | KinectPluginSpec):
            continue
        unread = [k for k in _CAMERA_MISNAMED if k in plugin.params]
        if unread:
            out.append(
                f"{model.source}: <plugin {plugin.filename}> on sensor '{plugin.reference}': "
                f"{', '.join(unread)} not read by the plugin (Gazebo ignores them too; "
                "CameraInfo's P[3] comes from hackBaseline, its D from distortionK1, "
                "distortionK2, distortionT1, distortionT2, distortionK3)"
            )
    return out


def _drive_warnings(model: RobotModel) -> list[str]:
    """gazebo_ros_diff_drive settings the simulator's kinematic drive does not act on, and
    drive plugins beyond the first (Gazebo would run them all, fighting over the body)."""
    out: list[str] = []
    drives = [p for p in model.gazebo.plugins if isinstance(p.spec, DiffDriveSpec | PlanarMoveSpec)]
    if len(drives) > 1:
        out.append(
            f"{model.source}: {len(drives)} drive plugins: the first "
            f"({drives[0].filename}) moves the robot; not simulated: "
            + ", ".join(p.filename for p in drives[1:])
        )
    for plugin in model.gazebo.plugins:
        spec = plugin.spec
        if not isinstance(spec, DiffDriveSpec):
            continue
        where = f"{model.source}: <plugin {plugin.filename}>"
        if spec.publish_wheel_tf:
            out.append(
                f"{where}: publishWheelTF is not simulated; with publishWheelJointState, "
                "robot_state_publisher gives the wheels' transforms"
            )
        if spec.legacy_mode and spec.publish_wheel_joint_state:
            out.append(
                f"{where}: legacyMode true swaps the wheels' speeds in Gazebo (an old bug "
                "kept for old URDFs); the simulated joint states report each wheel's own"
            )
    return out


def _ray_warnings(model: RobotModel) -> list[str]:
    """Multi-row ray sensors published by a laser plugin: roverlab scans one level row."""
    out: list[str] = []
    for sensor in model.gazebo.sensors:
        r = sensor.ray
        if r is None or r.vertical is None or r.vertical.samples <= 1:
            continue
        laser = [p.filename for p in sensor.plugins if isinstance(p.spec, LaserPluginSpec)]
        if not laser:
            continue  # nothing published in ROS either
        rows = r.vertical.range_count
        out.append(
            f"{model.source}: sensor '{sensor.name}': <vertical> samples {r.vertical.samples} "
            f"not simulated: only one level row of {r.range_count} rays is scanned (Gazebo's "
            f"{laser[0]} publishes the {rows} rows, "
            f"{_num(r.vertical.min_angle)} to {_num(r.vertical.max_angle)} rad, one after "
            f"another in one LaserScan of {rows * r.range_count} ranges)"
        )
    return out


def _shape_warnings(model: RobotModel) -> list[str]:
    """Meshes the simulator cannot read, and a robot left with no shape at all."""
    out: list[str] = []
    use_collisions = any(link.collisions for link in model.links.values())
    usable = 0
    for name, link in model.links.items():
        for shape in link.collisions if use_collisions else link.visuals:
            geom = shape.geometry
            if not isinstance(geom, Mesh):
                usable += 1
                continue
            try:
                mesh_points(geom, model.source)
                usable += 1
            except DescriptionError as err:
                out.append(f"{model.source}: link '{name}': mesh left out of the body: {err}")
    if not usable:
        out.append(
            f"{model.source}: no {'collision' if use_collisions else 'visual'} shape the "
            "simulator can use: the body is a 0.2 m square"
        )
    return out


def format_tree(model: RobotModel) -> str:
    """The ``check_urdf`` part: robot name, banner, root link and the indented tree."""
    root = model.root_link
    lines = [
        f"robot name is: {model.name}",
        "---------- Successfully Parsed XML ---------------",
        f"root Link: {root} has {len(model.child_joints(root))} child(ren)",
    ]

    def walk(link: str, level: int) -> None:
        level += 2
        joints = sorted(model.child_joints(link), key=lambda j: j.name)
        for count, j in enumerate(joints, start=1):
            lines.append("  " * level + f"child({count}):  {j.child}")
            walk(j.child, level)

    walk(root, 0)
    return "\n".join(lines)


def _num(value: float) -> str:
    return f"{value:g}"


def _sensor_line(s: GazeboSensor) -> str:
    head = f"  {s.name} ({s.type}) on {s.reference_link}"
    rate = f", {_num(s.update_rate_hz)} Hz" if s.update_rate_hz else ""
    if s.ray is not None:
        r = s.ray
        detail = (
            f": {r.samples} samples over [{r.min_angle:.4f}, {r.max_angle:.4f}] rad, "
            f"range {_num(r.range_min)}-{_num(r.range_max)} m"
        )
        if r.vertical is not None:
            detail += f", {r.vertical.samples} vertical samples"
    elif s.camera is not None:
        c = s.camera
        detail = (
            f": {c.width}x{c.height} {c.format}, hfov {c.horizontal_fov:.6g} rad "
            f"({math.degrees(c.horizontal_fov):.1f} deg), clip {_num(c.clip_near)}-"
            f"{_num(c.clip_far)} m"
        )
    elif s.imu is not None:
        detail = ": " + _imu_noise(s.imu)
    else:
        detail = ": not supported by roverlab"
    return head + detail + rate


def _imu_noise(imu: ImuSpec) -> str:
    return f"rate noise {_num(imu.rate.stddev)}, accel noise {_num(imu.accel.stddev)}"


def _plugin_line(p: GazeboPlugin) -> str:
    owner = f"sensor '{p.reference}'" if p.reference is not None else "model"
    head = f"  {p.name or '(unnamed)'} [{p.filename}] on {owner}"
    spec = p.spec
    if isinstance(spec, DiffDriveSpec):
        joints = f"{spec.left_joint}/{spec.right_joint}"
        if spec.rear_joints is not None:
            joints += f" + {spec.rear_joints[0]}/{spec.rear_joints[1]}"
        detail = (
            f": {joints}, separation "
            f"{_num(spec.wheel_separation_m)} m, diameter {_num(spec.wheel_diameter_m)} m, "
            f"{spec.command_topic} -> {spec.odometry_topic} "
            f"({spec.odometry_frame} -> {spec.robot_base_frame})"
        )
    elif isinstance(spec, PlanarMoveSpec):
        detail = _planar_move_detail(spec)
    elif isinstance(spec, RosControlSpec):
        detail = (
            f": ros_control in namespace {spec.robot_namespace}; a diff_drive_controller's "
            "parameters there move the robot"
        )
    elif isinstance(spec, LaserPluginSpec):
        detail = f": {spec.topic} in frame {spec.frame_id}"
    elif isinstance(spec, CameraPluginSpec):
        detail = f": {spec.image_topic}, {spec.camera_info_topic} in frame {spec.frame_id}"
    elif isinstance(spec, KinectPluginSpec):
        detail = (
            f": {spec.image_topic}, {spec.depth_image_topic}, {spec.point_cloud_topic} "
            f"in frame {spec.frame_id}"
        )
    elif isinstance(spec, ImuPluginSpec):
        detail = f": {spec.topic} from link {spec.body_name} in frame {spec.frame_id}"
        if spec.noise is not None:
            detail += ", " + _imu_noise(spec.noise)
        if spec.gaussian_noise:
            detail += f", gaussianNoise {_num(spec.gaussian_noise)}"
        if p.filename == "libgazebo_ros_imu_sensor.so":  # its 1 Hz default surprises
            detail += f", {_num(spec.update_rate_hz)} Hz" if spec.update_rate_hz else ""
        if any(spec.rpy_offset):
            detail += ", rpyOffset " + " ".join(_num(a) for a in spec.rpy_offset)
    else:
        detail = ": not supported by roverlab (ignored)"
    return head + detail


def _planar_move_detail(spec: PlanarMoveSpec) -> str:
    out = f": holonomic (linear.x, linear.y, angular.z), {spec.command_topic}"
    if spec.odometry_rate_hz > 0:
        out += (
            f" -> {spec.odometry_topic} at {_num(spec.odometry_rate_hz)} Hz "
            f"({spec.odometry_frame} -> {spec.robot_base_frame})"
        )
        if not spec.publish_odometry_tf:
            out += ", no odom transform (publishOdometryTf false: roverlab's switch)"
    else:
        out += ", no odometry (odometryRate 0)"
    if spec.cmd_timeout_s >= 0:
        out += f", stops {_num(spec.cmd_timeout_s)} s after the last command"
    return out


def format_check(model: RobotModel) -> str:
    """The ``check_urdf`` report followed by the robot's Gazebo sensors and plugins.

    Returns:
        Text without a trailing newline.
    """
    lines = [format_tree(model)]
    sensors = model.gazebo.sensors
    plugins = model.gazebo.plugins
    lines.append(f"---------- Gazebo sensors: {len(sensors)} ---------------")
    lines.extend(_sensor_line(s) for s in sensors)
    lines.append(f"---------- Gazebo plugins: {len(plugins)} ---------------")
    lines.extend(_plugin_line(p) for p in plugins)
    unsupported = [f"plugin {p.filename}" for p in model.gazebo.unsupported_plugins]
    unsupported += [f"sensor type {s.type}" for s in model.gazebo.unsupported_sensors]
    unknown = [r for r in model.gazebo.references if r not in model.links and r not in model.joints]
    if unsupported:
        lines.append("unsupported (ignored): " + ", ".join(dict.fromkeys(unsupported)))
    if unknown:
        lines.append(
            "warning: <gazebo reference> names no link or joint: "
            + ", ".join(f"'{r}'" for r in unknown)
        )
    lines.extend(f"warning: {w}" for w in [*model.warnings, *_shape_warnings(model)])
    lines.extend(f"note: {n}" for n in robot_notes(model, detail=True))
    return "\n".join(lines)
