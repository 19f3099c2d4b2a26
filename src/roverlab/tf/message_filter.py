"""tf2_ros' MessageFilter for roverlab's single-threaded executor, and a log throttle.

:class:`TfMessageFilter` holds stamped messages until their frame can be transformed into
the target frames at their stamp, retrying whenever ``/tf`` or ``/tf_static`` brings data
(it never blocks the executor); :class:`Throttle` repeats a warning at most once per
period of the node's clock (``ROS_WARN_THROTTLE``).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

from roverlab.core import Node, QoSProfile, Time
from roverlab.tf.buffer import Buffer
from roverlab.tf.convert import TF_MESSAGE_TYPE
from roverlab.tf.errors import BackwardExtrapolationException, TransformException
from roverlab.tf.ros import TF_STATIC_TOPIC, TF_TOPIC

__all__ = ["TfMessageFilter", "Throttle"]

# seconds between two repetitions of the same warning (ROS_WARN_THROTTLE-like)
_WARN_PERIOD_S = 10.0
# tf2_ros MessageFilter::checkFailures: first look 15 s after the first message, warn when
# more than 95% were dropped, then look again a minute later
_FIRST_CHECK_S = 15.0
_CHECK_AGAIN_S = 60.0
_DROP_SHARE = 0.95


class Throttle:
    """Lets a message through at most once per ``period_s`` of the node's clock.

    Args:
        node: whose clock and logger are used.
        period_s: seconds between two messages of the same key.
    """

    def __init__(self, node: Node, period_s: float = _WARN_PERIOD_S) -> None:
        self._node = node
        self._period_ns = round(period_s * 1e9)
        self._last: dict[str, int] = {}

    def warning(self, key: str, text: str) -> bool:
        """Log ``text`` as a warning unless ``key`` was logged less than a period ago."""
        now = self._node.get_clock().now_ns()
        last = self._last.get(key)
        if last is not None and now - last < self._period_ns:
            return False
        self._last[key] = now
        self._node.get_logger().warning(text)
        return True


class TfMessageFilter:
    """Holds stamped messages until ``target_frame <- msg.header.frame_id`` is in the buffer
    at the message's stamp, then hands them to ``callback`` in arrival order (tf2_ros
    MessageFilter, for an executor that must not block).

    Waiting messages are retried whenever ``/tf`` or ``/tf_static`` brings data. A message is
    dropped when ``queue_size`` newer ones wait behind it, when its stamp is older than the
    buffer's data (it can never be transformed), or, with ``timeout_s``, when it has waited
    that long on the node's clock. Drops are counted and reported as tf2_ros does
    (``checkFailures``): first 15 s after the first message, then at most once a minute,
    and only while more than 95% of the messages handled were dropped, so the few
    messages a node drops while its TF buffer fills at start are no warning.
    ``optional_frames`` are waited for too, but only up to ``timeout_s``: then the message
    is handed on without them (hector's ``waitForTransform`` before a lookup that may fail).

    Args:
        node: the node that subscribes ``/tf`` and ``/tf_static`` for the retries.
        buffer: the TF buffer (fed by a :class:`~roverlab.tf.TransformListener` created
            before this filter, so that a retry sees the data that triggered it).
        target_frames: frames every message must be transformable into.
        queue_size: how many messages may wait.
        callback: called with each message once it can be transformed.
        timeout_s: drop a message that waited this long (None: never).
        optional_frames: frames waited for at most ``timeout_s``.
        on_timeout: called with each message dropped for waiting ``timeout_s`` (instead of
            the throttled warning; it is still counted).

    Attributes:
        dropped: messages dropped so far.
        passed: messages handed on so far.
    """

    def __init__(
        self,
        node: Node,
        buffer: Buffer,
        target_frames: list[str],
        queue_size: int,
        callback: Callable[[Any], Any],
        *,
        timeout_s: float | None = None,
        optional_frames: list[str] | None = None,
        on_timeout: Callable[[Any], Any] | None = None,
    ) -> None:
        if queue_size < 1:
            raise ValueError(f"queue_size must be >= 1, got {queue_size}")
        self._node = node
        self._buffer = buffer
        self.target_frames = list(target_frames)
        self.optional_frames = list(optional_frames or [])
        self._callback = callback
        self._on_timeout = on_timeout
        self._timeout_ns = None if timeout_s is None else round(timeout_s * 1e9)
        self._queue: deque[tuple[Any, int]] = deque()
        self._queue_size = queue_size
        self._next_check_ns: int | None = None
        self._last_drop = ""
        self.dropped = 0
        self.passed = 0
        node.create_subscription(TF_MESSAGE_TYPE, TF_TOPIC, self._on_tf, 100)
        node.create_subscription(
            TF_MESSAGE_TYPE,
            TF_STATIC_TOPIC,
            self._on_tf,
            QoSProfile(depth=100, durability="transient_local"),
        )

    @property
    def waiting(self) -> int:
        """Messages waiting for their transform."""
        return len(self._queue)

    def add(self, msg: Any) -> None:
        """Queue ``msg`` and hand on every message that can now be transformed."""
        now = self._node.get_clock().now_ns()
        self._queue.append((msg, now))
        self._drain()
        while len(self._queue) > self._queue_size:
            old, _ = self._queue.popleft()
            self._drop(old, "discarding message because the queue is full")
        self._check_failures(now)

    def _check_failures(self, now: int) -> None:
        if self._next_check_ns is None:
            self._next_check_ns = now + round(_FIRST_CHECK_S * 1e9)
        if now < self._next_check_ns:
            return
        total = self.dropped + self.passed
        if not total or self.dropped / total <= _DROP_SHARE:
            return
        self._next_check_ns = now + round(_CHECK_AGAIN_S * 1e9)
        self._node.get_logger().warning(
            f"MessageFilter [target={', '.join(self.target_frames)}]: dropped "
            f"{100.0 * self.dropped / total:.2f}% of messages so far ({self._last_drop})"
        )

    def _on_tf(self, _msg: Any) -> None:
        if self._queue:
            self._drain()

    def _drain(self) -> None:
        now = self._node.get_clock().now_ns()
        while self._queue:
            msg, arrived = self._queue[0]
            expired = self._timeout_ns is not None and now - arrived >= self._timeout_ns
            state = self._ready(msg, self.target_frames)
            if state == "ready" and not expired:
                state = self._ready(msg, self.optional_frames)
            if state == "ready":
                self._queue.popleft()
                self.passed += 1
                self._callback(msg)
                continue
            if state == "too_old":
                self._queue.popleft()
                self._drop(msg, "the transform is older than the TF buffer's data")
                continue
            if expired:
                self._queue.popleft()
                if self._on_timeout is None:
                    self._drop(msg, "timed out waiting for the transform")
                else:
                    self.dropped += 1
                    self._on_timeout(msg)
                continue
            return

    def _ready(self, msg: Any, targets: list[str]) -> str:
        if not targets:  # no optional frames (the usual case)
            return "ready"
        frame = str(msg.header.frame_id).lstrip("/")
        stamp = Time.from_msg(msg.header.stamp)
        for target in targets:
            try:
                self._buffer.lookup_transform(target, frame, stamp)
            except BackwardExtrapolationException:
                return "too_old"
            except TransformException:
                return "too_old" if self._never_transformable(target, frame, stamp) else "wait"
        return "ready"

    def _never_transformable(self, target: str, frame: str, stamp: Time) -> bool:
        """tf2's test (``addTransformableRequest``): the stamp is more than the cache time
        behind the chain's latest common time, so its data is gone for good. A failed
        lookup's exception does not say it: with ``odom`` as the target, a scan older
        than the odometry kept can fail on the stale ``map -> odom`` edge above the target
        (the error tf2 reports too) and look as if it should wait, for ever when the
        process that publishes ``map -> odom`` (amcl) is the one waiting."""
        buffer = self._buffer
        try:
            latest = buffer.get_latest_common_time(target, frame)
        except TransformException:
            return False
        return bool(latest.nanoseconds) and stamp + buffer.cache_time < latest

    def _drop(self, msg: Any, reason: str) -> None:
        self.dropped += 1
        self._last_drop = f"last: frame {str(msg.header.frame_id)!r}: {reason}"
