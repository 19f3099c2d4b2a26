"""Turn a URDF/xacro robot's ``<gazebo>`` extensions into the simulator's configuration."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull, QhullError

from roverlab.description import (
    Box,
    CameraPluginSpec,
    Cylinder,
    DiffDriveSpec,
    GazeboSensor,
    ImuPluginSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    NoiseSpec,
    PlanarMoveSpec,
    RobotModel,
    Sphere,
)
from roverlab.description.errors import DescriptionError
from roverlab.description.meshes import mesh_points
from roverlab.description.model import Mesh
from roverlab.geometry import Transform3
from roverlab.sim.config import (
    CameraSensor,
    DepthSensor,
    DiffDriveConfig,
    ImuSensor,
    LidarSensor,
    PlanarMoveConfig,
    RobotSimConfig,
)
from roverlab.sim.diff_drive import DiffDriveParams
from roverlab.sim.ros_control import (
    DIFF_DRIVE_CONTROLLER,
    DiffDriveControllerConfig,
    diff_drive_controller_config,
)
from roverlab.sim.sensors import CameraParams, ImuNoise, LidarParams

__all__ = ["sim_config_from_model"]

# the controller types driven as diff_drive_controller (Jackal's own fork has its names)
CONTROLLER_TYPES = (DIFF_DRIVE_CONTROLLER, "jackal_diff_drive_controller/DiffDriveController")

F64 = NDArray[np.float64]


def _geometry_points(geom: object, source: str = "<string>") -> F64:
    """Sample points on a geometry's surface, in its own frame (a mesh: its parts' hull
    vertices; none when the file cannot be read, which ``robot_warnings`` reports)."""
    if isinstance(geom, Box):
        sx, sy, sz = (0.5 * v for v in geom.size)
        return np.array(
            [[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)], dtype=np.float64
        )
    a = np.linspace(0, 2 * math.pi, 16, endpoint=False)
    if isinstance(geom, Cylinder):
        ring = np.stack([geom.radius * np.cos(a), geom.radius * np.sin(a)], axis=1)
        h = 0.5 * geom.length
        return np.vstack(
            [np.column_stack([ring, np.full(16, -h)]), np.column_stack([ring, np.full(16, h)])]
        )
    if isinstance(geom, Sphere):
        r = geom.radius
        ring = np.stack([r * np.cos(a), r * np.sin(a), np.zeros(16)], axis=1)
        return np.vstack([ring, [[0, 0, r], [0, 0, -r]]])
    if isinstance(geom, Mesh):
        try:
            return mesh_points(geom, source)
        except DescriptionError:
            return np.zeros((0, 3))
    return np.zeros((0, 3))


def _body_points(model: RobotModel, base: str) -> F64:
    """Surface points of every collision (or, if the robot has none, visual) shape."""
    use_collisions = any(link.collisions for link in model.links.values())
    poses = model.link_transforms()
    base_inv = ~poses[base]
    pts: list[F64] = []
    for name, link in model.links.items():
        shapes = link.collisions if use_collisions else link.visuals
        for shape in shapes:
            local = _geometry_points(shape.geometry, model.source)
            if len(local):
                pts.append((base_inv * poses[name] * shape.origin).apply(local))
    return np.vstack(pts) if pts else np.zeros((0, 3))


def _wheel_acceleration(model: RobotModel, dd: DiffDriveSpec) -> float:
    """The wheels' surface acceleration limit: ``wheelAcceleration``, and what
    ``wheelTorque`` (skid steer: ``torque``) can give the robot's mass (n wheels pushing:
    n T / (r m)); 0 means unlimited, as the plugin's ``wheelAcceleration`` 0."""
    mass = sum(link.inertial.mass for link in model.links.values() if link.inertial is not None)
    limits = [dd.wheel_acceleration] if dd.wheel_acceleration > 0 else []
    if mass > 0 and dd.wheel_torque_nm > 0:
        n = dd.wheel_count
        limits.append(n * dd.wheel_torque_nm / (0.5 * dd.wheel_diameter_m * mass))
    return min(limits) if limits else 0.0


def _footprint(points: F64) -> F64:
    xy = points[:, :2]
    if len(xy) < 3:
        return np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]])
    try:
        hull = ConvexHull(xy)
    except QhullError:
        lo, hi = xy.min(axis=0), xy.max(axis=0) + 1e-3
        return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    return np.ascontiguousarray(xy[hull.vertices])


_NOISY = ("gaussian", "gaussian_quantized")  # Gazebo's types that add noise (no quantizing here)


def _noise(n: NoiseSpec | None) -> ImuNoise:
    if n is None or n.type not in _NOISY:  # Gazebo adds nothing for type "none"
        return ImuNoise()
    return ImuNoise(n.mean, n.stddev, n.bias_mean, n.bias_stddev)


def _mount(model: RobotModel, base: str, sensor: GazeboSensor) -> Transform3:
    poses = model.link_transforms()
    return (~poses[base]) * poses[sensor.reference_link] * sensor.pose


def _plumb_bob(
    spec: CameraPluginSpec | KinectPluginSpec,
) -> tuple[float, float, float, float, float]:
    """CameraInfo ``d`` as GazeboRosCameraUtils fills it: k1, k2, t1, t2, k3."""
    return (
        spec.distortion_k1,
        spec.distortion_k2,
        spec.distortion_t1,
        spec.distortion_t2,
        spec.distortion_k3,
    )


def _rate(plugin_rate: float, sensor_rate: float, default: float) -> float:
    for r in (plugin_rate, sensor_rate):
        if r > 0:
            return r
    return default


def _controller(
    model: RobotModel, controllers: Mapping[str, Any] | None, source: str
) -> DiffDriveControllerConfig | None:
    """The first diff_drive_controller among ``controllers`` (the parameter tree of
    gazebo_ros_control's namespace: controller name -> its parameters), when the robot
    has ``libgazebo_ros_control.so``."""
    rc = model.gazebo.ros_control
    if rc is None or not controllers:
        return None
    ns = rc.robot_namespace.strip("/")
    tree: Any = controllers
    for part in ns.split("/") if ns else ():
        tree = tree.get(part, {}) if isinstance(tree, Mapping) else {}
    for name, params in tree.items() if isinstance(tree, Mapping) else ():
        if isinstance(params, Mapping) and params.get("type") in CONTROLLER_TYPES:
            return diff_drive_controller_config(
                model, str(name), params, namespace=rc.robot_namespace,
                control_period_s=rc.control_period_s, source=source,
            )  # fmt: skip
    return None


def sim_config_from_model(
    model: RobotModel,
    *,
    controllers: Mapping[str, Any] | None = None,
    controllers_source: str = "<parameters>",
) -> RobotSimConfig:
    """Body outline, drive and sensors of a robot, as its Gazebo plugins configure them.

    ``controllers``: the parameter tree ros_control reads (as a ``control.yaml`` loaded
    at the root: ``{"jackal_velocity_controller": {"type": ..., ...}}``); a robot with
    ``libgazebo_ros_control.so`` and a ``diff_drive_controller/DiffDriveController`` in
    its namespace is driven by it.

    Raises:
        DescriptionError: a sensor or plugin refers to something the model lacks.
        RosControlError: a controller configuration the controller would refuse.
    """
    gz = model.gazebo
    controller = _controller(model, controllers, controllers_source)
    plugin = gz.drive
    base = (
        controller.robot_base_frame
        if controller is not None and plugin is None
        else plugin.robot_base_frame
        if plugin is not None
        else model.root_link
    )
    if base not in model.links:
        kind = "planar move" if isinstance(plugin, PlanarMoveSpec) else "diff drive"
        raise DescriptionError(
            f"{model.source}: {kind} robotBaseFrame '{base}' is not a link of the robot"
        )
    points = _body_points(model, base)
    zs = points[:, 2] if len(points) else np.array([0.0, 0.3])
    drive: DiffDriveConfig | PlanarMoveConfig | DiffDriveControllerConfig | None = None
    if plugin is None and controller is not None:
        drive = controller
    elif isinstance(plugin, PlanarMoveSpec):
        drive = PlanarMoveConfig(
            command_topic=plugin.command_topic,
            odometry_topic=plugin.odometry_topic,
            odometry_frame=plugin.odometry_frame,
            robot_base_frame=plugin.robot_base_frame,
            odometry_rate_hz=plugin.odometry_rate_hz,
            cmd_timeout_s=plugin.cmd_timeout_s,
            publish_odom_tf=plugin.publish_odometry_tf,
        )
    elif isinstance(plugin, DiffDriveSpec):
        dd = plugin
        drive = DiffDriveConfig(
            params=DiffDriveParams(
                wheel_separation_m=dd.wheel_separation_m,
                wheel_diameter_m=dd.wheel_diameter_m,
                wheel_acceleration=_wheel_acceleration(model, dd),
            ),
            command_topic=dd.command_topic,
            odometry_topic=dd.odometry_topic,
            odometry_frame=dd.odometry_frame,
            robot_base_frame=dd.robot_base_frame,
            publish_odom_tf=dd.publish_odom_tf and dd.publish_tf,
            publish_wheel_joint_state=dd.publish_wheel_joint_state,
            odometry_source=dd.odometry_source,
            update_rate_hz=dd.update_rate_hz if dd.update_rate_hz > 0 else 100.0,
            left_joint=dd.left_joint,
            right_joint=dd.right_joint,
        )
    lidars: list[LidarSensor] = []
    cameras: list[CameraSensor] = []
    depths: list[DepthSensor] = []
    unsupported = [p.filename for p in gz.unsupported_plugins]
    for sensor in gz.sensors:
        mount = _mount(model, base, sensor)
        if sensor.ray is not None:
            laser = next(
                (p.spec for p in sensor.plugins if isinstance(p.spec, LaserPluginSpec)), None
            )
            if laser is None:
                continue  # a ray sensor without the ROS plugin publishes nothing in ROS
            r = sensor.ray
            lidars.append(
                LidarSensor(
                    name=sensor.name,
                    params=LidarParams(
                        samples=r.range_count,
                        min_angle=r.min_angle,
                        max_angle=r.max_angle,
                        range_min=r.range_min,
                        range_max=r.range_max,
                        range_resolution=r.range_resolution,
                        noise_mean=r.noise_mean if r.noise_type in _NOISY else 0.0,
                        noise_stddev=r.noise_stddev if r.noise_type in _NOISY else 0.0,
                    ),
                    mount=mount,
                    update_rate_hz=_rate(0.0, sensor.update_rate_hz, 10.0),
                    topic=laser.topic,
                    frame_id=laser.frame_id,
                )
            )
        elif sensor.camera is not None:
            c = sensor.camera
            params = CameraParams(
                width=c.width,
                height=c.height,
                horizontal_fov=c.horizontal_fov,
                clip_near=c.clip_near,
                clip_far=c.clip_far,
                noise_mean=c.noise_mean if c.noise_type in _NOISY else 0.0,
                noise_stddev=c.noise_stddev if c.noise_type in _NOISY else 0.0,
            )
            cam = next(
                (p.spec for p in sensor.plugins if isinstance(p.spec, CameraPluginSpec)), None
            )
            kin = next(
                (p.spec for p in sensor.plugins if isinstance(p.spec, KinectPluginSpec)), None
            )
            if kin is not None:
                depths.append(
                    DepthSensor(
                        name=sensor.name,
                        params=params,
                        mount=mount,
                        update_rate_hz=_rate(kin.update_rate_hz, sensor.update_rate_hz, 10.0),
                        image_topic=kin.image_topic,
                        info_topic=kin.camera_info_topic,
                        depth_topic=kin.depth_image_topic,
                        depth_info_topic=kin.depth_image_camera_info_topic,
                        points_topic=kin.point_cloud_topic,
                        frame_id=kin.frame_id,
                        point_cloud_cutoff=kin.point_cloud_cutoff_m,
                        point_cloud_cutoff_max=kin.point_cloud_cutoff_max_m,
                        distortion=_plumb_bob(kin),
                        hack_baseline_m=kin.hack_baseline,
                    )
                )
            elif cam is not None:
                cameras.append(
                    CameraSensor(
                        name=sensor.name,
                        params=params,
                        mount=mount,
                        update_rate_hz=_rate(cam.update_rate_hz, sensor.update_rate_hz, 30.0),
                        image_topic=cam.image_topic,
                        info_topic=cam.camera_info_topic,
                        frame_id=cam.frame_id,
                        distortion=_plumb_bob(cam),
                        hack_baseline_m=cam.hack_baseline,
                    )
                )
    imus: list[ImuSensor] = []
    for imu_plugin in gz.plugins:
        spec = imu_plugin.spec
        if not isinstance(spec, ImuPluginSpec):
            continue
        noise = spec.noise
        imus.append(
            ImuSensor(
                name=spec.body_name,
                rate=_noise(noise.rate if noise else None),
                accel=_noise(noise.accel if noise else None),
                gaussian_noise=spec.gaussian_noise,
                update_rate_hz=spec.update_rate_hz,
                topic=spec.topic,
                frame_id=spec.frame_id,
                rpy_offset=spec.rpy_offset,
                offset_turns_rates=imu_plugin.filename == "libgazebo_ros_imu.so",
            )
        )
    return RobotSimConfig(
        name=model.name,
        footprint=_footprint(points) if len(points) else _footprint(np.zeros((0, 3))),
        height_band=(0.02, float(max(zs.max(), 0.05))),
        drive=drive,
        lidars=tuple(lidars),
        imus=tuple(imus),
        cameras=tuple(cameras),
        depth_cameras=tuple(depths),
        base_frame=base,
        unsupported=tuple(unsupported),
    )
