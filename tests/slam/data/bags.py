"""Write small ROS 1 bags, ROS 2 bags and MCAP files with rosbags, for the log reader tests.

The robot drives ``x = 0.1 t``, ``y = 0.05 t``, ``theta = 0.3 t`` (wrapping past pi); odometry
(``/odom`` or ``odom -> base_footprint`` on ``/tf``) comes at 20 Hz from t = 0, scans at
about 5 Hz at times between odometry samples, and ``/tf_static`` mounts the laser at
``base_footprint -> base_link -> laser`` (see :data:`LASER_OFFSET`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Literal

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from roverlab.geometry import SE2

#: base_footprint -> base_link, and base_link -> laser.
BASE_LINK = SE2(0.1, 0.0, 0.0)
LASER = SE2(0.05, 0.02, 0.1)
LASER_OFFSET = BASE_LINK * LASER
BEAMS = 90
ODOM_RATE_HZ = 20.0
SCAN_TIMES_S = tuple(0.013 + 0.2 * k for k in range(25))  # inside [0, 5] s


def true_pose(t: float) -> SE2:
    return SE2(0.1 * t, 0.05 * t, math.remainder(0.3 * t * 4.0, 2 * math.pi))


def scan_ranges(k: int) -> np.ndarray:
    return (1.0 + 0.01 * k + 0.001 * np.arange(BEAMS)).astype(np.float32)


def _ros1_store() -> Typestore:
    store = get_typestore(Stores.ROS1_NOETIC)
    store.register(
        get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
    )
    return store


class _Messages:
    def __init__(self, store: Typestore, ros1: bool) -> None:
        self.t = store.types
        self.ros1 = ros1

    def header(self, ns: int, frame: str) -> Any:
        stamp = self.t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
        if self.ros1:
            return self.t["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame)
        return self.t["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    def quat(self, yaw: float) -> Any:
        return self.t["geometry_msgs/msg/Quaternion"](
            x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)
        )

    def vec(self, x: float, y: float, z: float = 0.0) -> Any:
        return self.t["geometry_msgs/msg/Vector3"](x=x, y=y, z=z)

    def scan(self, ns: int, k: int) -> Any:
        inc = math.radians(2.0)
        return self.t["sensor_msgs/msg/LaserScan"](
            header=self.header(ns, "laser"),
            angle_min=-1.5,
            angle_max=-1.5 + (BEAMS - 1) * inc,
            angle_increment=inc,
            time_increment=0.0,
            scan_time=0.1,
            range_min=0.05,
            range_max=12.0,
            ranges=scan_ranges(k),
            intensities=np.zeros(0, dtype=np.float32),
        )

    def odom(self, ns: int, p: SE2) -> Any:
        t = self.t
        pose = t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=p.x, y=p.y, z=0.0),
            orientation=self.quat(p.theta),
        )
        twist = t["geometry_msgs/msg/Twist"](linear=self.vec(0, 0), angular=self.vec(0, 0))
        return t["nav_msgs/msg/Odometry"](
            header=self.header(ns, "odom"),
            child_frame_id="base_footprint",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=np.zeros(36)),
        )

    def tf(self, ns: int, parent: str, child: str, p: SE2) -> Any:
        t = self.t
        return t["geometry_msgs/msg/TransformStamped"](
            header=self.header(ns, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=self.vec(p.x, p.y, 0.05), rotation=self.quat(p.theta)
            ),
        )

    def tf_message(self, transforms: list[Any]) -> Any:
        return self.t["tf2_msgs/msg/TFMessage"](transforms=transforms)


def messages(
    msgs: _Messages, *, odometry: Literal["odom", "tf"], static: bool = True
) -> list[tuple[str, str, int, Any]]:
    """(topic, type, log time ns, message) in log-time order."""
    out: list[tuple[str, str, int, Any]] = []
    if static:
        out.append(
            (
                "/tf_static",
                "tf2_msgs/msg/TFMessage",
                0,
                msgs.tf_message(
                    [
                        msgs.tf(0, "base_footprint", "base_link", BASE_LINK),
                        msgs.tf(0, "base_link", "laser", LASER),
                    ]
                ),
            )
        )
    for k in range(int(5.0 * ODOM_RATE_HZ) + 1):
        ns = int(round(k / ODOM_RATE_HZ * 1e9))
        p = true_pose(ns * 1e-9)
        if odometry == "odom":
            out.append(("/odom", "nav_msgs/msg/Odometry", ns, msgs.odom(ns, p)))
        else:
            tf = msgs.tf(ns, "odom", "base_footprint", p)
            out.append(("/tf", "tf2_msgs/msg/TFMessage", ns, msgs.tf_message([tf])))
    for k, t in enumerate(SCAN_TIMES_S):
        ns = int(round(t * 1e9))
        out.append(("/scan", "sensor_msgs/msg/LaserScan", ns, msgs.scan(ns, k)))
    out.sort(key=lambda m: m[2])
    return out


def write_ros1_bag(path: Path, *, odometry: Literal["odom", "tf"] = "odom") -> Path:
    store = _ros1_store()
    items = messages(_Messages(store, ros1=True), odometry=odometry)
    with Writer1(path) as writer:
        conns: dict[str, Any] = {}
        for topic, msgtype, ns, msg in items:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], ns, store.serialize_ros1(msg, msgtype))
    return path


def write_ros2_bag(
    path: Path,
    *,
    odometry: Literal["odom", "tf"] = "odom",
    storage: StoragePlugin = StoragePlugin.SQLITE3,
    static: bool = True,
) -> Path:
    store = get_typestore(Stores.ROS2_JAZZY)
    items = messages(_Messages(store, ros1=False), odometry=odometry, static=static)
    with Writer2(path, version=9, storage_plugin=storage) as writer:
        conns: dict[str, Any] = {}
        for topic, msgtype, ns, msg in items:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], ns, store.serialize_cdr(msg, msgtype))
    return path


def write_mcap(path: Path, *, odometry: Literal["odom", "tf"] = "odom") -> Path:
    """A bare ``.mcap`` file (the one inside a ROS 2 bag folder written with MCAP storage)."""
    folder = write_ros2_bag(path.with_suffix(""), odometry=odometry, storage=StoragePlugin.MCAP)
    (inner,) = folder.glob("*.mcap")
    return inner.rename(path)
