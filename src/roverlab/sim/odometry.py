"""One odometry message and its ``odom -> base`` transform, as the drive plugins (and
ros_control's diff_drive_controller) publish them: a planar pose and a body twist."""

from __future__ import annotations

import math

import numpy as np

from roverlab.core.node import Publisher
from roverlab.msgs import builders as build

__all__ = ["publish_planar_odometry"]


def publish_planar_odometry(
    odom_pub: Publisher | None,
    tf_pub: Publisher | None,
    ns: int,
    frame: str,
    child: str,
    pose: tuple[float, float, float],
    twist: tuple[float, float, float],
    pose_cov: np.ndarray,
    twist_cov: np.ndarray,
) -> None:
    """``nav_msgs/Odometry`` at time ``ns`` (pose ``(x, y, yaw)``, body twist ``(vx, vy,
    wz)``) on ``odom_pub``, and the transform on ``tf_pub`` only while someone reads /tf
    (here or in another process); None skips either."""
    sec, nsec = divmod(ns, 1_000_000_000)
    x, y, yaw = pose
    qz, qw = math.sin(0.5 * yaw), math.cos(0.5 * yaw)
    if odom_pub is not None:
        odom_pub.publish(
            build.odometry(
                sec, nsec, frame, child, x, y, 0.0, 0.0, 0.0, qz, qw, pose_cov,
                twist[0], twist[1], 0.0, 0.0, 0.0, twist[2], twist_cov,
            )
        )  # fmt: skip
    if tf_pub is not None and tf_pub.has_listeners:
        tf_pub.publish(
            build.tf_message(
                [build.transform_stamped(sec, nsec, frame, child, x, y, 0.0, 0.0, 0.0, qz, qw)]
            )
        )
