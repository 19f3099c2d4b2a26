"""The simulator node (what ``gazebo_ros`` + the robot's ``<gazebo>`` plugins are in ROS).

Thin: it wires :mod:`roverlab.sim.diff_drive`, :mod:`roverlab.sim.planar_move`,
:mod:`roverlab.sim.collision` and :mod:`roverlab.sim.sensors` to topics, TF and
parameters. Every random draw comes from a generator spawned from the ``seed``
parameter, so a seeded run is reproducible.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from roverlab.core import Node
from roverlab.core.node import pausing_timer
from roverlab.geometry import Transform3, quat_from_rpy, quat_rotate, rpy_from_quat, wrap_angle
from roverlab.msgs import builders as build
from roverlab.msgs import classes as mc
from roverlab.msgs import xyz_to_pointcloud2
from roverlab.perception.image_transport.publisher import CompressedPublisher
from roverlab.raycast import Scene
from roverlab.raycast.camera import camera_intrinsics, depth_to_points
from roverlab.sim.collision import Obstacles, inner_radius
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
from roverlab.sim.dynamics import (
    DRIVE_DIFF,
    DRIVE_HOLONOMIC,
    S_AL,
    S_AR,
    S_CONTACT,
    S_CONTACTS,
    S_CVX,
    S_CVY,
    S_CW,
    S_DV,
    S_ETH,
    S_EX,
    S_EY,
    S_LAT,
    S_TH,
    S_TL,
    S_TR,
    S_V,
    S_VL,
    S_VR,
    S_VY,
    S_W,
    S_X,
    S_Y,
    STATE_SIZE,
    PhysicsPack,
    advance_packed,
    compiled_entry,
)
from roverlab.sim.odometry import publish_planar_odometry
from roverlab.sim.planar_move import PlanarMovePlugin
from roverlab.sim.ros_control import DiffDriveControllerConfig, DiffDriveControllerPlugin
from roverlab.sim.sensors import CameraModel, ImuModel, LidarModel
from roverlab.tf import TransformBroadcaster

__all__ = ["SimulatorNode", "SpawnPose"]

_ODOM_POSE_COV = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)  # as gazebo_ros_diff_drive
_ODOM_TWIST_COV = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


@dataclass(frozen=True)
class SpawnPose:
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


def _stamp(ns: int) -> Any:
    sec, nsec = divmod(ns, 1_000_000_000)
    return mc.Time(sec, nsec)


def _header(ns: int, frame: str) -> Any:
    return mc.Header(_stamp(ns), frame)


def _diag_cov(values: tuple[float, ...]) -> np.ndarray:
    """A 6x6 diagonal covariance, flat and read-only: every odometry message shares it."""
    cov = np.zeros(36)
    cov[[0, 7, 14, 21, 28, 35]] = values
    cov.flags.writeable = False
    return cov


class SimulatorNode(Node):
    """Simulates one differential-drive (or holonomic) robot in a static 2.5-D world.

    Publishes what the robot's Gazebo plugins would: odometry and the odom -> base
    transform (diff drive, skid steer or planar move), scans, IMU, camera and depth
    images and point clouds; plus the ground truth on ``/ground_truth/state``
    (nav_msgs/Odometry in the ``world`` frame, like the p3d plugin: the pose and, as p3d,
    the twist in the world frame too, not the child frame). ``/clock`` comes from the
    context.

    Parameters: ``seed`` (int), ``physics_rate`` (Hz, default 100), ``wheel_slip``
    (relative 1-sigma slip per wheel and step, default 0.02: the ground moves the body a
    little differently from what the wheels turned, so odometry from the encoders drifts
    from the true pose; ``world`` odometry is the true pose), ``ground_truth_rate`` (Hz,
    default 50), ``ground_truth_topic``.
    """

    def __init__(
        self,
        *,
        context: Any,
        scene: Scene,
        robot: RobotSimConfig,
        spawn: SpawnPose | None = None,
        seed: int = 0,
        **kwargs: Any,
    ) -> None:
        super().__init__(kwargs.pop("node_name", "gazebo"), context=context, **kwargs)
        self.scene = scene
        self.robot = robot
        spawn = spawn or SpawnPose()
        self.seed = int(self.declare_parameter("seed", seed).value)
        self.physics_rate = float(self.declare_parameter("physics_rate", 100.0).value)
        self.wheel_slip = float(self.declare_parameter("wheel_slip", 0.02).value)
        gt_rate = float(self.declare_parameter("ground_truth_rate", 50.0).value)
        gt_topic = str(self.declare_parameter("ground_truth_topic", "/ground_truth/state").value)
        if not (self.physics_rate > 0 and math.isfinite(self.physics_rate)):
            raise ValueError(f"physics_rate must be > 0, got {self.physics_rate}")
        seeds = np.random.SeedSequence(self.seed).spawn(
            2 + len(robot.lidars) + len(robot.imus) + len(robot.cameras) + len(robot.depth_cameras)
        )
        rngs = [np.random.default_rng(s) for s in seeds]
        self._slip_rng = rngs.pop(0)
        self._spare_rng = rngs.pop(0)
        # the physics state, advanced lazily in whole steps (see roverlab.sim.dynamics)
        self._state = np.zeros(STATE_SIZE)
        self._state[S_X], self._state[S_Y] = spawn.x, spawn.y
        self._state[S_TH] = float(wrap_angle(spawn.yaw))
        self._state_view = self._state.data  # a memoryview: entries read as Python floats
        self._executor = context.executor
        self._step_ns = round(1e9 / self.physics_rate)
        self._physics_ns = self.get_clock().now_ns()
        self._slip_block = 1 << 14
        self._noise = self._slip_rng.standard_normal((self._slip_block, 2))
        self._noise_pos = 0
        self.obstacles = Obstacles(scene, z_min=robot.height_band[0], z_max=robot.height_band[1])
        self._footprint = np.ascontiguousarray(robot.footprint, dtype=np.float64)
        if self.obstacles.hits(robot.footprint, self.x, self.y, self.yaw):
            self.get_logger().warning(
                f"robot spawned in collision at ({self.x:.2f}, {self.y:.2f}): it cannot move"
            )
        # drive
        self.drive = robot.drive
        d = self.drive if isinstance(self.drive, DiffDriveConfig) else None
        # the node's wheel_slip parameter sets the drive's slip (DiffDriveParams validates)
        wheels = self.drive if isinstance(self.drive, DiffDriveControllerConfig) else d
        p = replace(
            wheels.params if wheels else DiffDriveParams(1.0, 1.0), slip_stddev=self.wheel_slip
        )
        self._params = np.array(
            [
                p.wheel_separation_m,
                p.wheel_diameter_m,
                p.wheel_acceleration,
                p.slip_stddev,
                inner_radius(self._footprint),
                DRIVE_HOLONOMIC if isinstance(self.drive, PlanarMoveConfig) else DRIVE_DIFF,
            ]
        )
        self._dt = self._step_ns / 1e9
        obs = self.obstacles
        self._near = np.zeros(len(obs.segments) + len(obs.circles), dtype=np.int64)
        # the kernel's float64 arguments in one array (two arrays unboxed per call, not
        # seven); the state and the noise become views into it
        pack = PhysicsPack(
            self._state, self._params, self._dt, self._footprint, obs.segments, obs.circles,
            self._noise,
        )  # fmt: skip
        self._pack = pack.array
        self._state = pack.state
        self._state_view = self._state.data
        self._noise = pack.noise
        self._advance = compiled_entry(advance_packed, self._pack, self._near, 0, 0)
        self.tf = TransformBroadcaster(self)
        self._tf_pub = self.tf.publisher
        self._wheel_k = 2.0 / d.params.wheel_diameter_m if d else 0.0
        self._mounts: dict[int, tuple[float, float, float, float, float]] = {}
        self.planar_move = None
        if isinstance(self.drive, PlanarMoveConfig):
            self.planar_move = PlanarMovePlugin(
                node=self, config=self.drive, state=self._state, advance=self.advance,
                tf_publisher=self._tf_pub,
            )  # fmt: skip
        self.controller = None
        if isinstance(self.drive, DiffDriveControllerConfig):  # gazebo_ros_control
            self.controller = DiffDriveControllerPlugin(
                node=self, config=self.drive, state=self._state, advance=self.advance,
                tf_publisher=self._tf_pub, physics_period_s=self._dt,
            )  # fmt: skip
        if d is not None:
            self.create_subscription(mc.Twist, d.command_topic, self._on_cmd, 10)
            self.odom_pub = self.create_publisher(mc.Odometry, d.odometry_topic, 10)
            self.joint_pub = (
                self.create_publisher(mc.JointState, "joint_states", 10)
                if d.publish_wheel_joint_state
                else None
            )
            self.create_timer(1.0 / d.update_rate_hz, self._publish_odometry)
        self._pose_cov = _diag_cov(_ODOM_POSE_COV)
        self._twist_cov = _diag_cov(_ODOM_TWIST_COV)
        self.gt_pub = self.create_publisher(mc.Odometry, gt_topic, 10)
        pausing_timer(self, 1.0 / gt_rate, self.gt_pub, self._publish_ground_truth)
        for lidar in robot.lidars:
            self._add_lidar(lidar, rngs.pop(0))
        for imu in robot.imus:
            self._add_imu(imu, rngs.pop(0))
        for cam in robot.cameras:
            self._add_camera(cam, rngs.pop(0))
        for depth in robot.depth_cameras:
            self._add_depth(depth, rngs.pop(0))

    # ----------------------------------------------------------------- state
    @property
    def x(self) -> float:
        return self._state_view[S_X]

    @property
    def y(self) -> float:
        return self._state_view[S_Y]

    @property
    def yaw(self) -> float:
        return self._state_view[S_TH]

    @property
    def v(self) -> float:
        return self._state_view[S_V]

    @property
    def vy(self) -> float:
        """Lateral (body-frame y) velocity: zero but for a holonomic base."""
        return self._state_view[S_VY]

    @property
    def w(self) -> float:
        return self._state_view[S_W]

    @property
    def contact(self) -> bool:
        """The body touched an obstacle in the last physics step."""
        return bool(self._state[S_CONTACT])

    @property
    def contacts(self) -> int:
        """Contact events so far: physics steps in contact after one that was not (a
        robot pushing against a wall for a second is one event)."""
        self.advance()
        return int(self._state[S_CONTACTS])

    def advance(self) -> None:
        """Run every physics step up to the current clock time."""
        now = self._executor.now_ns
        if now < self._physics_ns + self._step_ns:
            return
        steps = (now - self._physics_ns) // self._step_ns
        self._physics_ns += steps * self._step_ns
        if self.drive is None:
            return
        if self._noise_pos + steps <= self._slip_block:  # the usual case: one call
            self._noise_pos = self._advance(self._pack, self._near, self._noise_pos, steps)
            return
        self._noise[...] = self._slip_rng.standard_normal((self._slip_block, 2))
        self._noise_pos = 0
        while steps > 0:
            chunk = min(steps, self._slip_block - self._noise_pos)
            self._noise_pos = self._advance(self._pack, self._near, self._noise_pos, chunk)
            steps -= chunk
            if steps > 0:
                self._noise[...] = self._slip_rng.standard_normal((self._slip_block, 2))
                self._noise_pos = 0

    def teleport(self, x: float, y: float, yaw: float) -> None:
        """Put the robot at ``(x, y, yaw)`` in the world at once, at rest (Gazebo's
        ``set_model_state``). Encoder odometry does not see the jump; world-source
        odometry does (it reports the world pose, as Gazebo's plugin).

        Raises:
            ValueError: a non-finite pose.
        """
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(f"teleport pose must be finite, got ({x}, {y}, {yaw})")
        self.advance()
        st = self._state
        st[S_X], st[S_Y], st[S_TH] = x, y, float(wrap_angle(yaw))
        for i in (S_VL, S_VR, S_TL, S_TR, S_V, S_W, S_DV, S_VY, S_LAT, S_CVX, S_CVY, S_CW):
            st[i] = 0.0
        if self.planar_move is not None:  # its command, timeout and odometry start over
            self.planar_move.reset()
        if self.controller is not None:
            self.controller.reset()

    # ----------------------------------------------------------------- commands
    def _on_cmd(self, msg: Any) -> None:
        v, w = float(msg.linear.x), float(msg.angular.z)
        if not (math.isfinite(v) and math.isfinite(w)):
            self.get_logger().warning("ignoring a cmd_vel with a NaN or infinite velocity")
            return
        assert isinstance(self.drive, DiffDriveConfig)
        self.advance()
        p = self.drive.params
        half = 0.5 * p.wheel_separation_m * w
        lim = p.max_wheel_speed_mps
        self._state[S_TL] = max(-lim, min(lim, v - half))
        self._state[S_TR] = max(-lim, min(lim, v + half))

    # ----------------------------------------------------------------- odometry
    def odometry_pose(self) -> tuple[float, float, float]:
        """The pose the drive plugin reports (world pose, or integrated encoders)."""
        self.advance()
        st = self._state
        if isinstance(self.drive, DiffDriveConfig) and self.drive.odometry_source == "encoder":
            return float(st[S_EX]), float(st[S_EY]), float(st[S_ETH])
        return float(st[S_X]), float(st[S_Y]), float(st[S_TH])

    def _publish_odometry(self) -> None:
        d = self.drive
        assert isinstance(d, DiffDriveConfig)
        ns = self._executor.now_ns  # a timer callback: the event's time
        if ns >= self._physics_ns + self._step_ns:
            self.advance()
        st = self._state_view
        if d.odometry_source == "encoder":
            x, y, yaw = st[S_EX], st[S_EY], st[S_ETH]
            v = 0.5 * (st[S_VL] + st[S_VR])
            w = (st[S_VR] - st[S_VL]) / d.params.wheel_separation_m
        else:
            x, y, yaw = st[S_X], st[S_Y], st[S_TH]
            v, w = st[S_V], st[S_W]
        publish_planar_odometry(
            self.odom_pub, self._tf_pub if d.publish_odom_tf else None, ns,
            d.odometry_frame, d.robot_base_frame, (x, y, yaw), (v, 0.0, w),
            self._pose_cov, self._twist_cov,
        )  # fmt: skip
        sec, nsec = divmod(ns, 1_000_000_000)
        if self.joint_pub is not None:
            # one buffer for position, velocity (wheel surface speed / radius) and effort
            k = self._wheel_k
            values = np.array((st[S_AL], st[S_AR], st[S_VL] * k, st[S_VR] * k, 0.0, 0.0))
            self.joint_pub.publish(
                build.joint_state(
                    sec,
                    nsec,
                    "",
                    [d.left_joint, d.right_joint],
                    values[0:2],
                    values[2:4],
                    values[4:6],
                )
            )

    def _publish_ground_truth(self) -> None:
        # as gazebo_ros_p3d: the twist in the world frame (the link's world velocity)
        self.advance()
        sec, nsec = divmod(self._executor.now_ns, 1_000_000_000)
        yaw, v, vy = self.yaw, self.v, self.vy
        c, s = math.cos(yaw), math.sin(yaw)
        zero = np.zeros(36)
        self.gt_pub.publish(
            build.odometry(
                sec, nsec, "world", self.robot.base_frame, self.x, self.y, 0.0,
                0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw), zero,
                c * v - s * vy, s * v + c * vy, 0.0, 0.0, 0.0, self.w, zero,
            )
        )  # fmt: skip

    # ----------------------------------------------------------------- sensors
    def sensor_pose(self, mount: Transform3) -> tuple[float, float, float, float, float]:
        """World (x, y, z, yaw, pitch) of a sensor mounted at ``mount`` on the base.

        The base moves in the plane (no roll or pitch), so this is planar arithmetic on
        the mount's offsets, cached per mount.
        """
        self.advance()
        m = self._mounts.get(id(mount))
        if m is None:
            _, pitch, myaw = rpy_from_quat(mount.rotation)
            m = self._mounts[id(mount)] = (*mount.translation, myaw, pitch)
        mx, my, mz, myaw, pitch = m
        st = self._state_view
        x, y, yaw = st[S_X], st[S_Y], st[S_TH]
        c, s = math.cos(yaw), math.sin(yaw)
        return (
            x + c * mx - s * my,
            y + s * mx + c * my,
            mz,
            float(wrap_angle(yaw + myaw)),
            pitch,
        )

    def _add_lidar(self, sensor: LidarSensor, rng: np.random.Generator) -> None:
        model = LidarModel(sensor.params, rng)
        pub = self.create_publisher(mc.LaserScan, sensor.topic, 10)
        p = sensor.params
        scan_time = 1.0 / sensor.update_rate_hz

        empty = np.zeros(0, dtype=np.float32)

        def tick() -> None:
            x, y, z, yaw, _ = self.sensor_pose(sensor.mount)
            # the ranges are cast when a reader first asks for them (a costmap casts the
            # scans its updates use; most of the 50 a second are replaced unread): the
            # same values, the noise drawn now in the same order
            ranges = model.scan_later(self.scene, x, y, z, yaw)
            sec, nsec = divmod(self._executor.now_ns, 1_000_000_000)
            pub.publish(
                build.laser_scan_later(
                    sec, nsec, sensor.frame_id, p.min_angle, p.max_angle, p.angle_increment,
                    0.0, scan_time, p.range_min, p.range_max, ranges, empty,
                )
            )  # fmt: skip

        self.create_timer(scan_time, tick)

    def _add_imu(self, sensor: ImuSensor, rng: np.random.Generator) -> None:
        model = ImuModel(sensor.rate, sensor.accel, rng, gaussian_noise=sensor.gaussian_noise)
        pub = self.create_publisher(mc.Imu, sensor.topic, 10)
        rate = sensor.update_rate_hz if sensor.update_rate_hz > 0 else self.physics_rate
        cov = np.zeros(9)  # shared by the three fields of every message: read-only
        cov.flags.writeable = False
        if any(sensor.rpy_offset):  # decided once: the usual tick below stays as lean
            self.create_timer(1.0 / rate, self._imu_offset_tick(sensor, model, pub, cov))
            return

        ex = self._executor
        frame = sensor.frame_id
        # the state is updated in place, never replaced: a memoryview reads single
        # entries as Python floats, cheaper than the whole state's tolist()
        state = self._state_view
        rows = iter(model.take_rows())
        take_rows = model.take_rows
        advance, nxt, sin, cos = self.advance, next, math.sin, math.cos
        physics, pack, near, slip_block = self._advance, self._pack, self._near, self._slip_block
        driven = self.drive is not None
        publish = pub.publish
        imu = build.imu

        step_ns = self._step_ns

        def tick() -> None:
            # runs at the physics rate: ImuModel.measure and the usual one-step advance()
            # inlined, names bound once
            now = ex.now_ns
            if now >= self._physics_ns + step_ns:
                if driven and now < self._physics_ns + 2 * step_ns and self._noise_pos < slip_block:
                    self._physics_ns += step_ns
                    self._noise_pos = physics(pack, near, self._noise_pos, 1)
                else:
                    advance()
            nonlocal rows
            n = nxt(rows, None)
            if n is None:
                rows = iter(take_rows())
                n = nxt(rows)
            w = state[S_W]
            half = 0.5 * state[S_TH]
            sec, nsec = divmod(now, 1_000_000_000)
            publish(
                imu(
                    sec, nsec, frame, 0.0, 0.0, sin(half), cos(half), cov,
                    n[0], n[1], w + n[2], cov,
                    state[S_DV] + n[3], state[S_LAT] + n[4], n[5], cov,
                )
            )  # fmt: skip

        self.create_timer(1.0 / rate, tick)

    def _imu_offset_tick(
        self, sensor: ImuSensor, model: ImuModel, pub: Any, cov: np.ndarray
    ) -> Callable[[], None]:
        """The tick of an IMU plugin with an ``rpyOffset``, as the plugins apply it: the
        orientation is ``q_offset * q_body``, and ``libgazebo_ros_imu.so`` turns the
        angular velocity and linear acceleration by that rotation too (the sensor
        plugin publishes them as measured)."""
        ox, oy, oz, ow = (float(c) for c in quat_from_rpy(*sensor.rpy_offset))
        turn = sensor.offset_turns_rates
        # the offset's rotation matrix, row by row, as plain floats
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = quat_rotate(
            (ox, oy, oz, ow), np.eye(3)
        ).T.tolist()
        state = self._state_view
        frame = sensor.frame_id
        rows = iter(model.take_rows())

        def tick() -> None:
            nonlocal rows
            self.advance()
            n = next(rows, None)
            if n is None:
                rows = iter(model.take_rows())
                n = next(rows)
            half = 0.5 * state[S_TH]
            s, c = math.sin(half), math.cos(half)
            # q_offset * (0, 0, s, c)
            qx, qy, qz, qw = ox * c + oy * s, oy * c - ox * s, ow * s + oz * c, ow * c - oz * s
            wx, wy, wz = n[0], n[1], state[S_W] + n[2]
            ax, ay, az = state[S_DV] + n[3], state[S_LAT] + n[4], n[5]
            if turn:
                wx, wy, wz = (
                    r00 * wx + r01 * wy + r02 * wz,
                    r10 * wx + r11 * wy + r12 * wz,
                    r20 * wx + r21 * wy + r22 * wz,
                )
                ax, ay, az = (
                    r00 * ax + r01 * ay + r02 * az,
                    r10 * ax + r11 * ay + r12 * az,
                    r20 * ax + r21 * ay + r22 * az,
                )
            sec, nsec = divmod(self._executor.now_ns, 1_000_000_000)
            pub.publish(
                build.imu(sec, nsec, frame, qx, qy, qz, qw, cov, wx, wy, wz, cov, ax, ay, az, cov)
            )

        return tick

    def _camera_info(
        self, ns: int, frame: str, model: CameraModel, sensor: CameraSensor | DepthSensor
    ) -> Any:
        # as GazeboRosCameraUtils: d from the plugin's distortion coefficients (reported,
        # not applied to the image), p[3] = -fx * hackBaseline
        p = model.params
        k = camera_intrinsics(p.width, p.height, p.horizontal_fov).k
        proj = np.zeros((3, 4))
        proj[:, :3] = k
        if sensor.hack_baseline_m:
            proj[0, 3] = -k[0, 0] * sensor.hack_baseline_m
        return mc.CameraInfo(
            header=_header(ns, frame),
            height=p.height,
            width=p.width,
            distortion_model="plumb_bob",
            d=np.array(sensor.distortion, dtype=np.float64),
            k=k.reshape(-1),
            r=np.eye(3).reshape(-1),
            p=proj.reshape(-1),
            binning_x=0,
            binning_y=0,
            roi=mc.RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False),
        )

    def _add_camera(self, sensor: CameraSensor, rng: np.random.Generator) -> None:
        model = CameraModel(sensor.params, rng)
        image_pub = self.create_publisher(mc.Image, sensor.image_topic, 2)
        info_pub = self.create_publisher(mc.CameraInfo, sensor.info_topic, 2)
        compressed = CompressedPublisher(self, sensor.image_topic, 2)  # image_transport's

        pubs = (image_pub, info_pub, compressed)

        def tick() -> None:
            # rendered only while someone looks, as gazebo_ros_camera activates its sensor
            if not any(pub.has_listeners for pub in pubs):
                return
            ns = self.get_clock().now_ns()
            x, y, z, yaw, pitch = self.sensor_pose(sensor.mount)
            rgb = model.capture_rgb(self.scene, x, y, z, yaw, pitch)
            image = _image(ns, sensor.frame_id, rgb, "rgb8")
            if image_pub.has_listeners:  # as image_transport: each transport to its readers
                image_pub.publish(image)
            compressed.publish(image)
            info_pub.publish(self._camera_info(ns, sensor.frame_id, model, sensor))

        self.create_timer(1.0 / sensor.update_rate_hz, tick)

    def _add_depth(self, sensor: DepthSensor, rng: np.random.Generator) -> None:
        model = CameraModel(sensor.params, rng)
        image_pub = self.create_publisher(mc.Image, sensor.image_topic, 2)
        info_pub = self.create_publisher(mc.CameraInfo, sensor.info_topic, 2)
        depth_pub = self.create_publisher(mc.Image, sensor.depth_topic, 2)
        dinfo_pub = self.create_publisher(mc.CameraInfo, sensor.depth_info_topic, 2)
        points_pub = self.create_publisher(mc.PointCloud2, sensor.points_topic, 2)
        compressed = CompressedPublisher(self, sensor.image_topic, 2)
        p = sensor.params

        pubs = (image_pub, info_pub, depth_pub, dinfo_pub, points_pub, compressed)

        def tick() -> None:
            if not any(pub.has_listeners for pub in pubs):  # as the colour camera
                return
            ns = self.get_clock().now_ns()
            x, y, z, yaw, pitch = self.sensor_pose(sensor.mount)
            rgb, depth = model.capture(self.scene, x, y, z, yaw, pitch)
            image = _image(ns, sensor.frame_id, rgb, "rgb8")
            image_pub.publish(image)
            compressed.publish(image)
            depth_pub.publish(_image(ns, sensor.frame_id, depth, "32FC1"))
            info = self._camera_info(ns, sensor.frame_id, model, sensor)
            info_pub.publish(info)
            dinfo_pub.publish(info)
            pts = depth_to_points(depth, p.horizontal_fov)
            valid = (np.isfinite(depth) & (depth > 0)).reshape(-1)
            colors = rgb.reshape(-1, 3)[valid]
            keep = (pts[:, 2] >= sensor.point_cloud_cutoff) & (
                pts[:, 2] <= sensor.point_cloud_cutoff_max
            )
            points_pub.publish(xyz_to_pointcloud2(pts[keep], sensor.frame_id, ns, rgb=colors[keep]))

        self.create_timer(1.0 / sensor.update_rate_hz, tick)


def _image(ns: int, frame: str, arr: np.ndarray, encoding: str) -> Any:
    height, width = arr.shape[:2]
    data = np.ascontiguousarray(arr)
    return mc.Image(
        header=_header(ns, frame),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=data.strides[0],
        data=data.reshape(-1).view(np.uint8),
    )
