"""tf2_ros's ``Buffer``: :class:`~roverlab.tf.buffer_core.BufferCore` plus a lock, lookups
that wait up to a timeout for data to arrive, futures, and message conversion. Frames,
times and lookups follow :mod:`roverlab.tf.buffer_core`'s conventions (tf2's).
"""

from __future__ import annotations

import functools
import threading
import time as _walltime
from collections.abc import Callable
from concurrent.futures import Future, InvalidStateError
from typing import Any

from roverlab.core.time import Duration, Time
from roverlab.geometry import Transform3
from roverlab.tf.buffer_core import (
    _NS,
    DEFAULT_AUTHORITY,
    DEFAULT_CACHE_TIME,
    MAX_GRAPH_DEPTH,
    BufferCore,
    _duration_ns,
    _to_transform3,
)
from roverlab.tf.convert import transform_from_msg, transform_to_msg
from roverlab.tf.errors import (
    ExtrapolationException,
    TimeoutException,
    TransformException,
)

__all__ = ["DEFAULT_AUTHORITY", "DEFAULT_CACHE_TIME", "MAX_GRAPH_DEPTH", "Buffer", "BufferCore"]


# --------------------------------------------------------------------------- Buffer
class Buffer(BufferCore):
    """Thread-safe :class:`BufferCore` whose lookups can wait for data (tf2_ros.Buffer).

    Every method takes one lock; :meth:`set_transform` wakes lookups waiting with a timeout
    and resolves the futures of :meth:`wait_for_transform_async`. Timeouts are wall-clock
    seconds (or a :class:`Duration`), as in tf2_ros.

    Args:
        cache_time: how long dynamic data is kept (see :class:`BufferCore`).
    """

    def __init__(self, *, cache_time: Duration | float = DEFAULT_CACHE_TIME) -> None:
        super().__init__(cache_time=cache_time)
        self._cond = threading.Condition(threading.RLock())
        self._waiters = 0  # lookups waiting in _wait: set_transform wakes them only then
        self._requests: list[tuple[str, str, Time, Future[tuple[Transform3, Time]]]] = []

    # ------------------------------------------------------------------ input
    def set_transform(
        self,
        parent: str,
        child: str,
        stamp: Time,
        transform: Transform3,
        authority: str = DEFAULT_AUTHORITY,
        *,
        is_static: bool = False,
    ) -> bool:
        with self._cond:
            stored = super().set_transform(
                parent, child, stamp, transform, authority, is_static=is_static
            )
            if not stored:
                return False
            if self._waiters:
                self._cond.notify_all()
            done = self._test_requests() if self._requests else []
        for fut, result, error in done:
            try:
                if error is None:
                    fut.set_result(result)  # type: ignore[arg-type]
                else:
                    fut.set_exception(error)
            except InvalidStateError:  # cancelled meanwhile
                pass
        return True

    def set_transform_msg(
        self, msg: Any, authority: str = DEFAULT_AUTHORITY, *, is_static: bool = False
    ) -> bool:
        """:meth:`set_transform` from a ``geometry_msgs/msg/TransformStamped``."""
        parent, child, stamp, transform = transform_from_msg(msg)
        return self.set_transform(parent, child, stamp, transform, authority, is_static=is_static)

    def clear(self) -> None:
        with self._cond:
            super().clear()

    # ------------------------------------------------------------------ lookups
    def lookup_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Time,
        timeout: Duration | float = 0.0,
    ) -> tuple[Transform3, Time]:
        """:meth:`BufferCore.lookup_transform`, first waiting up to ``timeout`` for the
        transform to become available; then the lookup's own error is raised, as tf2_ros."""
        if type(timeout) is not Duration and timeout == 0.0:
            # no wait (every lookup of the executor's callbacks): the lookup under the
            # lock, as _lookup_waiting does it, without building its closure
            with self._cond:
                return BufferCore.lookup_transform(self, target_frame, source_frame, time)
        return self._lookup_waiting(
            functools.partial(super().lookup_transform, target_frame, source_frame, time),
            timeout,
        )

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration | float = 0.0,
    ) -> tuple[Transform3, Time]:
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        return self._lookup_waiting(
            functools.partial(super().lookup_transform_full, *args), timeout
        )

    def lookup_transform_msg(
        self,
        target_frame: str,
        source_frame: str,
        time: Time,
        timeout: Duration | float = 0.0,
    ) -> Any:
        """:meth:`lookup_transform` as a ``geometry_msgs/msg/TransformStamped``
        (``header.frame_id`` = target, ``child_frame_id`` = source), like tf2_ros."""
        transform, stamp = self.lookup_transform(target_frame, source_frame, time, timeout)
        return transform_to_msg(target_frame, source_frame, stamp, transform)

    def lookup_transform_full_msg(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration | float = 0.0,
    ) -> Any:
        """:meth:`lookup_transform_full` as a ``geometry_msgs/msg/TransformStamped``."""
        transform, stamp = self.lookup_transform_full(
            target_frame, target_time, source_frame, source_time, fixed_frame, timeout
        )
        return transform_to_msg(target_frame, source_frame, stamp, transform)

    def can_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Time,
        timeout: Duration | float = 0.0,
    ) -> bool:
        ready = functools.partial(super().can_transform, target_frame, source_frame, time)
        with self._cond:
            return self._wait(ready, timeout)

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration | float = 0.0,
    ) -> bool:
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        ready = functools.partial(super().can_transform_full, *args)
        with self._cond:
            return self._wait(ready, timeout)

    def wait_for_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Time,
        timeout: Duration | float,
    ) -> None:
        """Block until the transform is available.

        Raises:
            TimeoutException: not available after ``timeout``; the lookup error that
                remained is chained as its cause.
        """
        ready = functools.partial(super().can_transform, target_frame, source_frame, time)
        with self._cond:
            if self._wait(ready, timeout):
                return
            try:
                super().lookup_transform(target_frame, source_frame, time)
            except TransformException as err:
                raise TimeoutException(
                    f"Timed out after {_duration_ns(timeout) / _NS:.3f} s waiting for the "
                    f"transform from [{source_frame}] to [{target_frame}]: {err}"
                ) from err

    def wait_for_transform_async(
        self, target_frame: str, source_frame: str, time: Time
    ) -> Future[tuple[Transform3, Time]]:
        """A future resolved with the lookup result as soon as it is available.

        The result is set from the thread that calls :meth:`set_transform` (done-callbacks
        run there). The future fails with the lookup's ExtrapolationException when the
        requested time has fallen out of the cache, so the request can never succeed.
        """
        fut: Future[tuple[Transform3, Time]] = Future()
        with self._cond:
            try:
                result = super().lookup_transform(target_frame, source_frame, time)
            except ExtrapolationException as err:
                if not self._too_old(target_frame, source_frame, time):
                    self._requests.append((target_frame, source_frame, time, fut))
                    return fut
                fut.set_exception(err)
                return fut
            except TransformException:
                self._requests.append((target_frame, source_frame, time, fut))
                return fut
        fut.set_result(result)
        return fut

    # ------------------------------------------------------------------ introspection
    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Time:
        with self._cond:
            return super().get_latest_common_time(target_frame, source_frame)

    def frames(self) -> list[str]:
        with self._cond:
            return super().frames()

    def has_frame(self, frame_id: str) -> bool:
        with self._cond:
            return super().has_frame(frame_id)

    def all_frames_as_string(self) -> str:
        with self._cond:
            return super().all_frames_as_string()

    def all_frames_as_yaml(self, current_time: Time | None = None) -> str:
        with self._cond:
            return super().all_frames_as_yaml(current_time)

    def tree_as_text(self) -> str:
        with self._cond:
            return super().tree_as_text()

    # ------------------------------------------------------------------ internals
    def _lookup_waiting(
        self, lookup: Callable[[], tuple[Transform3, Time]], timeout: Duration | float
    ) -> tuple[Transform3, Time]:
        """``lookup()``; if it fails and ``timeout`` is positive, wait until it would succeed
        or the timeout, then ``lookup()`` again (its error is the one raised)."""
        with self._cond:
            try:
                return lookup()
            except TransformException:
                if _duration_ns(timeout) <= 0:
                    raise
            self._wait(lambda: self._succeeds(lookup), timeout)
            return lookup()

    def _wait(self, ready: Callable[[], bool], timeout: Duration | float) -> bool:
        """Wait (lock held, released while waiting) until ``ready()`` or the timeout."""
        if ready():
            return True
        timeout_s = _duration_ns(timeout) / _NS
        if timeout_s <= 0.0:
            return False
        deadline = _walltime.monotonic() + timeout_s
        self._waiters += 1
        try:
            while True:
                remaining = deadline - _walltime.monotonic()
                if remaining <= 0.0:
                    return ready()
                self._cond.wait(remaining)
                if ready():
                    return True
        finally:
            self._waiters -= 1

    def _test_requests(
        self,
    ) -> list[
        tuple[Future[tuple[Transform3, Time]], tuple[Transform3, Time] | None, Exception | None]
    ]:
        """Check pending futures (lock held); return those to resolve."""
        done: list[
            tuple[Future[tuple[Transform3, Time]], tuple[Transform3, Time] | None, Exception | None]
        ] = []
        keep = []
        for request in self._requests:
            target, source, t, fut = request
            if fut.cancelled():
                continue
            try:
                pose, t_ns = self._lookup_pose(target, source, t.nanoseconds)
                done.append((fut, (_to_transform3(pose), Time(t_ns)), None))
                continue
            except ExtrapolationException as err:
                if self._too_old(target, source, t):
                    done.append((fut, None, err))
                    continue
            except TransformException:
                pass
            keep.append(request)
        self._requests = keep
        return done

    def _too_old(self, target: str, source: str, t: Time) -> bool:
        """tf2's test: the request time is more than the cache time behind the newest data."""
        if t.nanoseconds == 0:
            return False
        try:
            latest = self._latest_common_time(target, source)
        except TransformException:
            return False
        return latest != 0 and t.nanoseconds + self._cache_ns < latest
