"""tf over topics: broadcasters and a listener, as tf2_ros.

Topics and QoS are tf2_ros': ``/tf`` (volatile, depth 100) and ``/tf_static``
(transient-local, so a late subscriber receives every static transform sent before).
The classes talk to any node with rclpy's ``create_publisher`` / ``create_subscription`` /
``get_clock`` / ``get_logger`` (:class:`NodeLike`), in practice ``roverlab.core.Node``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Final, Protocol

from roverlab.core.qos import QoSProfile
from roverlab.core.time import Time
from roverlab.tf.buffer_core import DEFAULT_AUTHORITY, BufferCore
from roverlab.tf.convert import TF_MESSAGE_TYPE, tf_message, transform_from_msg
from roverlab.tf.errors import InvalidArgumentException

__all__ = [
    "TF_STATIC_TOPIC",
    "TF_TOPIC",
    "NodeLike",
    "StaticTransformBroadcaster",
    "TransformBroadcaster",
    "TransformListener",
]

TF_TOPIC: Final = "/tf"
TF_STATIC_TOPIC: Final = "/tf_static"


class NodeLike(Protocol):
    """The part of a node the tf classes use (rclpy's vocabulary)."""

    def create_publisher(self, msg_type: Any, topic: str, qos: Any, /) -> Any: ...

    def create_subscription(
        self, msg_type: Any, topic: str, callback: Callable[[Any], None], qos: Any, /
    ) -> Any: ...

    def get_clock(self) -> Any: ...

    def get_logger(self) -> Any: ...


def _as_list(transform: Any) -> list[Any]:
    if isinstance(transform, list | tuple):
        return list(transform)
    return [transform]


class TransformBroadcaster:
    """Publishes TransformStamped messages on ``/tf`` (tf2_ros.TransformBroadcaster).

    Args:
        node: the node to publish from.
        qos: history depth or profile of the publisher.
    """

    def __init__(self, node: NodeLike, qos: QoSProfile | int = 100) -> None:
        self._pub = node.create_publisher(TF_MESSAGE_TYPE, TF_TOPIC, qos)

    @property
    def publisher(self) -> Any:
        """The ``/tf`` publisher (for a caller that builds the TFMessage itself)."""
        return self._pub

    def send_transform(self, transform: Any | Sequence[Any]) -> None:
        """Publish one TransformStamped, or a list of them in one TFMessage."""
        self._pub.publish(tf_message(_as_list(transform)))


class StaticTransformBroadcaster:
    """Publishes static transforms on latched ``/tf_static``.

    As tf2_ros, every call republishes one TFMessage holding all static transforms this
    broadcaster was given (one per child frame, the latest replacing earlier ones), so a
    late subscriber gets the whole set from the single latched message.

    Args:
        node: the node to publish from.
        qos: defaults to depth 1, transient-local.
    """

    def __init__(self, node: NodeLike, qos: QoSProfile | int | None = None) -> None:
        if qos is None:
            qos = QoSProfile(depth=1, durability="transient_local")
        self._pub = node.create_publisher(TF_MESSAGE_TYPE, TF_STATIC_TOPIC, qos)
        self._by_child: dict[str, Any] = {}

    def send_transform(self, transform: Any | Sequence[Any]) -> None:
        """Add (or replace, by child frame) transforms and republish the whole set."""
        for t in _as_list(transform):
            self._by_child[str(t.child_frame_id)] = t
        self._pub.publish(tf_message(self._by_child.values()))


class TransformListener:
    """Feeds a buffer from ``/tf`` and ``/tf_static`` (tf2_ros.TransformListener).

    The authority recorded is ``"default_authority"``, as tf2_ros' Python listener (the
    publisher is not known). When the node's clock jumps backwards (a bag or a simulation
    restarted) the buffer's dynamic data is cleared, as ROS 1's listener does. Malformed
    transforms (NaN, empty ids) and data older than the cache are logged and skipped.

    Args:
        buffer: the buffer to fill (usually a :class:`~roverlab.tf.Buffer`).
        node: the node to subscribe with.
        qos: subscription depth or profile for ``/tf``.
        static_qos: profile for ``/tf_static``; defaults to depth 100, transient-local.
    """

    def __init__(
        self,
        buffer: BufferCore,
        node: NodeLike,
        *,
        qos: QoSProfile | int = 100,
        static_qos: QoSProfile | int | None = None,
    ) -> None:
        if static_qos is None:
            static_qos = QoSProfile(depth=100, durability="transient_local")
        self.buffer = buffer
        self._node = node
        self._last_update: Time | None = None
        self._tf_sub = node.create_subscription(TF_MESSAGE_TYPE, TF_TOPIC, self._on_tf, qos)
        self._tf_static_sub = node.create_subscription(
            TF_MESSAGE_TYPE, TF_STATIC_TOPIC, self._on_tf_static, static_qos
        )

    def _on_tf(self, msg: Any) -> None:
        self._check_for_reset()
        for t in msg.transforms:
            self._store(t, is_static=False)

    def _on_tf_static(self, msg: Any) -> None:
        self._check_for_reset()
        for t in msg.transforms:
            self._store(t, is_static=True)

    def _store(self, msg: Any, *, is_static: bool) -> None:
        parent, child, stamp, transform = transform_from_msg(msg)
        try:
            stored = self.buffer.set_transform(
                parent, child, stamp, transform, DEFAULT_AUTHORITY, is_static=is_static
            )
        except InvalidArgumentException as err:
            self._node.get_logger().error(f"{err}; transform ignored")
            return
        if not stored:
            self._node.get_logger().warning(
                f"TF_OLD_DATA ignoring data from the past for frame {child.removeprefix('/')} at "
                f"time {stamp.seconds:.6f} according to authority {DEFAULT_AUTHORITY}"
            )

    def _check_for_reset(self) -> None:
        now = self._node.get_clock().now()
        last = self._last_update
        if last is not None and now < last:
            self._node.get_logger().warning(
                f"Detected jump back in time of {(last - now).seconds:f}s. Clearing TF buffer."
            )
            self.buffer.clear()
        self._last_update = now
