"""tf for ROS 1 scripts: ``TransformListener``, ``TransformBroadcaster``, ``transformations``.

The ROS 1 API on roverlab's tf2 (:mod:`roverlab.tf`), joined to the script's rospy node:

* ``TransformListener()``: ``waitForTransform(target, source, time, timeout)``,
  ``lookupTransform(target, source, time)`` -> ``([x, y, z], [x, y, z, w])``,
  ``canTransform``, ``getLatestCommonTime``, ``frameExists``, ``getFrameStrings``;
* ``TransformBroadcaster()``: ``sendTransform(translation, rotation, time, child, parent)``
  (ROS 1's argument order: the child frame before the parent);
* ``tf.Exception``, ``tf.LookupException``, ``tf.ConnectivityException``,
  ``tf.ExtrapolationException`` (tf2's classes, so ``except tf.Exception`` catches all).

Frame names may start with '/' as ROS 1's tf allowed: it is dropped.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from roverlab.core.time import Duration as CoreDuration
from roverlab.core.time import Time as CoreTime
from roverlab.msgs import classes as mc
from roverlab.ros1.rospy.runtime import RUNTIME
from roverlab.ros1.tf import transformations
from roverlab.tf import Buffer
from roverlab.tf import ConnectivityException as ConnectivityException
from roverlab.tf import ExtrapolationException as ExtrapolationException
from roverlab.tf import LookupException as LookupException
from roverlab.tf import TransformBroadcaster as _Broadcaster
from roverlab.tf import TransformException as Exception
from roverlab.tf import TransformListener as _Listener

__all__ = [
    "ConnectivityException",
    "Exception",
    "ExtrapolationException",
    "LookupException",
    "TransformBroadcaster",
    "TransformListener",
    "transformations",
]


def _frame(name: str) -> str:
    return name.lstrip("/")


def _ns(value: Any) -> int:
    if value is None:
        return 0
    if hasattr(value, "nanoseconds"):
        return int(value.nanoseconds)
    if hasattr(value, "sec") and hasattr(value, "nanosec"):
        return int(value.sec) * 1_000_000_000 + int(value.nanosec)
    return int(round(float(value) * 1e9))


def _time(value: Any) -> CoreTime:
    return CoreTime(nanoseconds=_ns(value))


class TransformListener:
    """ROS 1 ``tf.TransformListener``: fills a tf2 buffer from ``/tf`` and ``/tf_static``."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._buffer = Buffer()
        self._listener = _Listener(self._buffer, RUNTIME.require_node())

    def waitForTransform(
        self,
        target_frame: str,
        source_frame: str,
        time: Any,
        timeout: Any,
        polling_sleep_duration: Any = None,
    ) -> None:
        """Wait until the transform is available; raises ``tf.Exception`` on timeout."""
        self._buffer.lookup_transform(
            _frame(target_frame),
            _frame(source_frame),
            _time(time),
            timeout=CoreDuration(nanoseconds=_ns(timeout)),
        )

    def canTransform(self, target_frame: str, source_frame: str, time: Any) -> bool:
        return self._buffer.can_transform(_frame(target_frame), _frame(source_frame), _time(time))

    def lookupTransform(
        self, target_frame: str, source_frame: str, time: Any
    ) -> tuple[list[float], list[float]]:
        """``(translation, rotation)`` of ``source_frame`` in ``target_frame`` as lists."""
        tf, _ = self._buffer.lookup_transform(
            _frame(target_frame), _frame(source_frame), _time(time)
        )
        return list(tf.translation), list(tf.rotation)

    def getLatestCommonTime(self, source_frame: str, target_frame: str) -> Any:
        from roverlab.ros1.rospy.rostime import Time

        t = self._buffer.get_latest_common_time(_frame(target_frame), _frame(source_frame))
        return Time(0, t.nanoseconds)

    def frameExists(self, frame_id: str) -> bool:
        return self._buffer.has_frame(_frame(frame_id))

    def getFrameStrings(self) -> list[str]:
        return self._buffer.frames()


class TransformBroadcaster:
    """ROS 1 ``tf.TransformBroadcaster`` on the script's node (``/tf``)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        self._broadcaster = _Broadcaster(RUNTIME.require_node())

    def sendTransform(
        self,
        translation: Sequence[float],
        rotation: Sequence[float],
        time: Any,
        child: str,
        parent: str,
    ) -> None:
        x, y, z = (float(v) for v in translation)
        qx, qy, qz, qw = (float(v) for v in rotation)
        ns = _ns(time)
        stamp = mc.Time(ns // 1_000_000_000, ns % 1_000_000_000)
        self._broadcaster.send_transform(
            mc.TransformStamped(
                mc.Header(stamp, _frame(parent)),
                _frame(child),
                mc.Transform(mc.Vector3(x, y, z), mc.Quaternion(qx, qy, qz, qw)),
            )
        )

    def sendTransformMessage(self, transform: Any) -> None:
        self._broadcaster.send_transform(transform)
