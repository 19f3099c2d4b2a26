"""``fake_localization`` (ROS 1 ``fake_localization/fake_localization``): localization from
the simulator's ground truth, for runs that should not depend on amcl.

As ROS's node: every ``base_pose_ground_truth`` message (``nav_msgs/Odometry``, the
robot's true pose; roverlab's simulator publishes it on ``/ground_truth/state``, remap
it) is moved by the offset ``delta_x``, ``delta_y``, ``delta_yaw``, waits until TF has
``odom_frame_id <- base_frame_id`` at its stamp (a message filter, 100 messages), and
becomes

* the transform ``global_frame_id -> odom_frame_id`` (``truth * odom_T_base^-1``) stamped
  ``stamp + transform_tolerance``, as amcl broadcasts it;
* ``amcl_pose`` (``PoseWithCovarianceStamped``, zero covariance) and ``particlecloud``
  (``PoseArray``: one pose), in ``global_frame_id``.

``initialpose`` (rviz's 2D Pose Estimate) moves the offset so that the robot's current
pose becomes the one given (``offset = pose * base_T_map * offset``, ``base_T_map`` from
TF at the message's stamp); a pose in another frame than ``global_frame_id`` is used all
the same, with a warning, as ROS does.

Parameters (ROS names and defaults): ``odom_frame_id`` ("odom"), ``base_frame_id``
("base_link"), ``global_frame_id`` ("/map"), ``delta_x``, ``delta_y``, ``delta_yaw`` (0),
``transform_tolerance`` (0.1 s).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from roverlab.core import Context, Duration, Node, QoSProfile, Time
from roverlab.geometry import SE2, Transform3
from roverlab.msgs import (
    PoseArray,
    PoseWithCovarianceStamped,
    pose_from_xytheta,
    poses_from_xytheta,
    xytheta_from_pose,
)
from roverlab.msgs import classes as mc
from roverlab.tf import (
    Buffer,
    TfMessageFilter,
    TransformBroadcaster,
    TransformException,
    TransformListener,
    transform_to_msg,
)

__all__ = ["FakeLocalization"]

_QUEUE = 100  # fake_localization's message filter queue
_LATCHED = QoSProfile(depth=1, durability="transient_local")
_ZERO = np.zeros(36)


@dataclass
class _Header:
    frame_id: str
    stamp: Any


@dataclass
class _Waiting:
    """A ground-truth message as the filter sees it: stamped in the base frame (the filter
    then waits for ``odom <- base`` at that stamp, as ROS's filter targeting the base)."""

    header: _Header
    msg: Any


class FakeLocalization(Node):
    """``fake_localization``: see the module docstring.

    Args:
        context: the context the node joins.
        node_name: defaults to ``fake_localization``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Attributes:
        map_to_odom: the last transform broadcast, or None.
    """

    def __init__(
        self, context: Context, *, node_name: str = "fake_localization", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)

        def param(name: str, default: Any) -> Any:
            return self.declare_parameter(name, default).value

        self.odom_frame = str(param("odom_frame_id", "odom")).lstrip("/")
        self.base_frame = str(param("base_frame_id", "base_link")).lstrip("/")
        self.global_frame = str(param("global_frame_id", "/map")).lstrip("/")
        dx, dy = float(param("delta_x", 0.0)), float(param("delta_y", 0.0))
        dyaw = float(param("delta_yaw", 0.0))
        self.transform_tolerance = float(param("transform_tolerance", 0.1))
        # ROS: offset = Transform(RPY(0, 0, -delta_yaw), (-delta_x, -delta_y, 0))
        self._offset = SE2(-dx, -dy, -dyaw)
        self.map_to_odom: Transform3 | None = None
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.tf_broadcaster = TransformBroadcaster(self)
        self.pose_pub = self.create_publisher(PoseWithCovarianceStamped, "amcl_pose", _LATCHED)
        self.cloud_pub = self.create_publisher(PoseArray, "particlecloud", _LATCHED)
        self._filter = TfMessageFilter(
            self, self.tf_buffer, [self.odom_frame], _QUEUE, self._update
        )
        self.create_subscription(mc.Odometry, "base_pose_ground_truth", self._on_truth, _QUEUE)
        self.create_subscription(
            mc.PoseWithCovarianceStamped, "initialpose", self._on_initialpose, 1
        )

    def _on_initialpose(self, msg: Any) -> None:
        frame = str(msg.header.frame_id).lstrip("/")
        if frame != self.global_frame:
            self.get_logger().warning(
                f'Frame ID of "initialpose" ({msg.header.frame_id}) is different from the '
                f"global frame {self.global_frame}"
            )
        try:
            base_in_map, _ = self.tf_buffer.lookup_transform(
                self.base_frame, self.global_frame, Time.from_msg(msg.header.stamp)
            )
        except TransformException:
            self.get_logger().warning("Failed to lookup transform!")
            return
        pose = SE2(*xytheta_from_pose(msg.pose.pose))
        self._offset = pose * base_in_map.to_se2() * self._offset

    def _on_truth(self, msg: Any) -> None:
        self._filter.add(_Waiting(_Header(self.base_frame, msg.header.stamp), msg))

    def _update(self, waiting: _Waiting) -> None:
        msg = waiting.msg
        stamp = Time.from_msg(msg.header.stamp)
        truth = self._offset * SE2(*xytheta_from_pose(msg.pose.pose))
        try:
            odom_base, _ = self.tf_buffer.lookup_transform(self.odom_frame, self.base_frame, stamp)
        except TransformException as err:
            self.get_logger().error(f"Failed to transform to {self.odom_frame} from "
                                    f"{self.base_frame}: {err}")  # fmt: skip
            return
        self.map_to_odom = Transform3.from_se2(truth * ~odom_base.to_se2())
        expiry = stamp + Duration.from_seconds(self.transform_tolerance)
        self.tf_broadcaster.send_transform(
            transform_to_msg(self.global_frame, self.odom_frame, expiry, self.map_to_odom)
        )
        header = {"frame_id": self.global_frame, "stamp": msg.header.stamp}
        pose = {"pose": pose_from_xytheta(truth.x, truth.y, truth.theta), "covariance": _ZERO}
        self.pose_pub.publish(PoseWithCovarianceStamped(header=header, pose=pose))
        self.cloud_pub.publish(
            PoseArray(header=header, poses=poses_from_xytheta(np.array([truth.as_array()])))
        )
