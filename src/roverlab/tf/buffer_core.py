"""tf2's ``BufferCore``: the transform tree without threads, clock or messages.

:class:`BufferCore` is tf2's ``BufferCore`` on plain values: a tree of frames, one
time-sorted cache per child frame (each sample remembers its parent, so a frame can be
re-parented, the latest data winning), static edges valid at every time, lookups that
interpolate (lerp + slerp) between the two samples around the requested time, and the same
error kinds and messages as tf2. It has no threads, no clock and no messages.

:class:`roverlab.tf.buffer.Buffer` adds what ``tf2_ros.Buffer`` adds.

Conventions (tf2's): ``lookup_transform(target, source, t)`` returns ``target_T_source``,
the transform that maps a point expressed in ``source`` into ``target``; ``Time(0)`` asks for
the latest time at which every edge of the chain has data.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from typing import Final

from roverlab.core.time import Duration, Time
from roverlab.geometry import Transform3
from roverlab.tf._cache import (
    IDENTITY,
    Cache,
    Pose,
    Sample,
    StaticCache,
    TimeCache,
    display,
    inv,
    mul,
)
from roverlab.tf.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)

__all__ = ["DEFAULT_AUTHORITY", "DEFAULT_CACHE_TIME", "MAX_GRAPH_DEPTH", "BufferCore"]

DEFAULT_CACHE_TIME: Final = Duration(10_000_000_000)
"""How long a dynamic edge keeps its past (tf2's default: 10 s)."""
MAX_GRAPH_DEPTH: Final = 1000
"""Longest chain walked before the tree is declared to contain a loop (as tf2)."""
_FOUND_MAX: Final = 256
"""Lookups remembered between two changes of the data (then all forgotten at once)."""
DEFAULT_AUTHORITY: Final = "default_authority"
"""Authority recorded when the broadcaster is unknown (what tf2_ros' Python listener uses)."""

_QUATERNION_NORMALIZATION_TOLERANCE: Final = 10e-3
_NO_PARENT: Final = "NO_PARENT"
_NS: Final = 1_000_000_000
_MAX_NS: Final = 1 << 62


def _to_transform3(p: Pose) -> Transform3:
    return Transform3((p[0], p[1], p[2]), (p[3], p[4], p[5], p[6]))


def _duration_ns(value: Duration | float) -> int:
    if isinstance(value, Duration):
        return value.nanoseconds
    return Duration.from_seconds(float(value)).nanoseconds


def _strip_slash(frame_id: str) -> str:
    """tf2's stripSlash: drop one leading '/' (ROS 1 style ids) from incoming data."""
    return frame_id[1:] if frame_id.startswith("/") else frame_id


# --------------------------------------------------------------------------- BufferCore
class BufferCore:
    """tf2's BufferCore: a time-indexed tree of coordinate frames. Not thread-safe.

    Args:
        cache_time: how long dynamic data is kept behind the newest sample of each edge
            (a :class:`Duration` or seconds).

    Raises:
        InvalidArgumentException: ``cache_time`` is not positive.
    """

    def __init__(self, *, cache_time: Duration | float = DEFAULT_CACHE_TIME) -> None:
        ns = _duration_ns(cache_time)
        if ns <= 0:
            raise InvalidArgumentException(f"cache_time must be > 0, got {ns / _NS} s")
        self._cache_ns = ns
        self._frames: dict[str, None] = {}  # every frame id ever seen, in order of arrival
        self._caches: dict[str, Cache] = {}  # child frame id -> its data
        # (target, source, stamp) -> the pose found, until the data next changes: a
        # message is looked up several times at its stamp (message filters, costmaps)
        self._found: dict[tuple[str, str, int], Pose] = {}
        # (target, source) -> (pose, latest common time) of a Time(0) lookup, the same way
        # (a robot pose is asked for by both costmaps and move_base between two TF updates)
        self._found_latest: dict[tuple[str, str], tuple[Pose, int]] = {}
        self._authority: dict[str, str] = {}

    @property
    def cache_time(self) -> Duration:
        return Duration(self._cache_ns)

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
        """Store ``parent_T_child`` at ``stamp`` (tf2's setTransform).

        A leading '/' of either id is dropped. A child has one parent at a time: the latest
        data decides. Data of the same stamp replaces what was there. Sending static data
        for a dynamic child (or the reverse) replaces its cache, as tf2 does.

        Args:
            parent: the frame the transform maps into (``header.frame_id``).
            child: the frame the transform maps from (``child_frame_id``).
            stamp: time of the data (ignored for lookups of static data).
            transform: ``parent_T_child``; its quaternion must be unit length within 1e-2.
            authority: who sent it (shown by :meth:`all_frames_as_yaml`).
            is_static: static data is valid at every time and survives :meth:`clear`.

        Returns:
            False when the data was older than the cache keeps (tf2's TF_OLD_DATA) and was
            dropped; True when it was stored.

        Raises:
            InvalidArgumentException: empty frame id, frame equal to its parent, NaN or
                infinity in the transform, or a quaternion far from unit length.
        """
        parent = _strip_slash(parent)
        child = _strip_slash(child)
        if not child:
            raise InvalidArgumentException(
                f'TF_NO_CHILD_FRAME_ID: transform from authority "{authority}" '
                "has no child_frame_id"
            )
        if not parent:
            raise InvalidArgumentException(
                f'TF_NO_FRAME_ID: transform with child_frame_id "{child}" from authority '
                f'"{authority}" has no frame_id'
            )
        if child == parent:
            raise InvalidArgumentException(
                f'TF_SELF_TRANSFORM: transform from authority "{authority}" has frame_id and '
                f'child_frame_id "{child}" the same'
            )
        tx, ty, tz = transform.translation
        qx, qy, qz, qw = transform.rotation
        tx, ty, tz, qx, qy, qz, qw = (
            float(tx),
            float(ty),
            float(tz),
            float(qx),
            float(qy),
            float(qz),
            float(qw),
        )
        if not math.isfinite(tx + ty + tz + qx + qy + qz + qw) and not all(
            math.isfinite(v) for v in (tx, ty, tz, qx, qy, qz, qw)
        ):
            raise InvalidArgumentException(
                f'TF_NAN_INPUT: transform for child_frame_id "{child}" from authority '
                f'"{authority}" has a nan value in the transform '
                f"({tx:f} {ty:f} {tz:f}) ({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        n2 = qx * qx + qy * qy + qz * qz + qw * qw
        if abs(n2 - 1.0) >= _QUATERNION_NORMALIZATION_TOLERANCE:
            raise InvalidArgumentException(
                f'TF_DENORMALIZED_QUATERNION: transform for child_frame_id "{child}" from '
                f'authority "{authority}" has an invalid quaternion in the transform '
                f"({qx:f} {qy:f} {qz:f} {qw:f})"
            )
        n = math.sqrt(n2)
        sample: Sample = (parent, (tx, ty, tz, qx / n, qy / n, qz / n, qw / n))
        self._found.clear()
        self._found_latest.clear()
        self._frames.setdefault(child, None)
        self._frames.setdefault(parent, None)
        cache = self._caches.get(child)
        if cache is None or cache.is_static != is_static:
            if is_static:
                self._caches[child] = StaticCache(child, sample)
                self._authority[child] = authority
                return True
            cache = self._caches[child] = TimeCache(child, self._cache_ns)
        if not cache.insert(stamp.nanoseconds, sample):
            return False
        self._authority[child] = authority
        return True

    def clear(self) -> None:
        """Drop all dynamic data (static transforms and known frame ids stay), as tf2."""
        self._found.clear()
        self._found_latest.clear()
        for cache in self._caches.values():
            cache.clear()

    # ------------------------------------------------------------------ lookups
    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Time
    ) -> tuple[Transform3, Time]:
        """``target_T_source`` at ``time`` (``Time(0)``: latest common time).

        Returns:
            The transform mapping points in ``source_frame`` into ``target_frame``, and the
            time it is valid at (the resolved latest common time for ``Time(0)``).

        Raises:
            LookupException: a frame is unknown (or the tree contains a loop).
            ConnectivityException: the frames are in different trees.
            ExtrapolationException: ``time`` is outside the data of an edge of the chain.
            InvalidArgumentException: an empty frame id or one starting with '/'.
        """
        pose, t_ns = self._lookup_pose(target_frame, source_frame, time.nanoseconds)
        return _to_transform3(pose), (time if t_ns == time.nanoseconds else Time(t_ns))

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
    ) -> tuple[Transform3, Time]:
        """Transform from ``source_frame`` at ``source_time`` to ``target_frame`` at
        ``target_time``, assuming ``fixed_frame`` does not move in between (tf2's advanced
        lookupTransform). The returned time is the one used for the target side.

        Raises:
            The same errors as :meth:`lookup_transform`.
        """
        pose, t_ns = self._lookup_full_pose(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )
        return _to_transform3(pose), Time(t_ns)

    def can_transform(self, target_frame: str, source_frame: str, time: Time) -> bool:
        """True when :meth:`lookup_transform` with these arguments would succeed."""
        return self._succeeds(
            lambda: self._lookup_pose(target_frame, source_frame, time.nanoseconds)
        )

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
    ) -> bool:
        """True when :meth:`lookup_transform_full` with these arguments would succeed."""
        return self._succeeds(
            lambda: self._lookup_full_pose(
                target_frame, target_time, source_frame, source_time, fixed_frame
            )
        )

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Time:
        """Latest time at which every dynamic edge between the two frames has data.

        ``Time(0)`` when the chain is all static.

        Raises:
            LookupException, ConnectivityException, InvalidArgumentException.
        """
        self._validate("getLatestCommonTime argument target_frame", target_frame)
        self._validate("getLatestCommonTime argument source_frame", source_frame)
        if target_frame == source_frame:
            cache = self._caches.get(target_frame)
            return Time(cache.latest_stamp() if cache is not None else 0)
        return Time(self._latest_common_time(target_frame, source_frame))

    # ------------------------------------------------------------------ introspection
    def frames(self) -> list[str]:
        """Every frame id seen (as parent or child), in order of first arrival."""
        return list(self._frames)

    def has_frame(self, frame_id: str) -> bool:
        return frame_id in self._frames

    def all_frames_as_string(self) -> str:
        """tf2's allFramesAsString: ``Frame <child> exists with parent <parent>.`` lines."""
        lines = []
        for frame in self._frames:
            cache = self._caches.get(frame)
            if cache is None:
                continue
            parent = cache.latest()[1] or _NO_PARENT
            lines.append(f"Frame {frame} exists with parent {parent}.\n")
        return "".join(lines)

    def all_frames_as_yaml(self, current_time: Time | None = None) -> str:
        """tf2's allFramesAsYAML: per child frame its parent, broadcaster, rate, most recent
        and oldest transform, (delay to ``current_time``,) and buffer length."""
        if not self._frames:
            return "[]"
        out = []
        for frame in self._frames:
            cache = self._caches.get(frame)
            if cache is None:
                continue
            parent = cache.latest()[1]
            if parent is None:
                continue
            latest, oldest = cache.latest_stamp(), cache.oldest_stamp()
            out.append(f"{frame}: \n")
            out.append(f"  parent: '{parent}'\n")
            out.append(f"  broadcaster: '{self._authority.get(frame, 'no recorded authority')}'\n")
            out.append(f"  rate: {self._rate(cache):.3f}\n")
            out.append(f"  most_recent_transform: {display(latest)}\n")
            out.append(f"  oldest_transform: {display(oldest)}\n")
            if current_time is not None and current_time.nanoseconds != 0:
                out.append(f"  transform_delay: {(current_time.nanoseconds - latest) / _NS:.3f}\n")
            out.append(f"  buffer_length: {(latest - oldest) / _NS:.3f}\n")
        return "".join(out)

    def tree_as_text(self) -> str:
        """The frame tree as indented text (what view_frames draws), roots first.

        Each child line shows its edge: broadcaster, average rate, most recent stamp and
        buffer length, or ``static``.
        """
        if not self._frames:
            return "no tf data received\n"
        children: dict[str, list[str]] = {}
        has_parent: set[str] = set()
        for child, cache in self._caches.items():
            parent = cache.latest()[1]
            if parent is not None:
                children.setdefault(parent, []).append(child)
                has_parent.add(child)
        lines: list[str] = []
        visited: set[str] = set()

        def emit(frame: str, prefix: str, connector: str) -> None:
            visited.add(frame)
            label = frame if not connector else f"{frame}  [{self._edge_label(frame)}]"
            lines.append(f"{prefix}{connector}{label}")
            kids = sorted(children.get(frame, ()))
            child_prefix = prefix + (
                "" if not connector else ("    " if connector == "└── " else "│   ")
            )
            for i, kid in enumerate(kids):
                if kid not in visited:
                    emit(kid, child_prefix, "└── " if i == len(kids) - 1 else "├── ")

        for root in sorted(f for f in self._frames if f not in has_parent):
            emit(root, "", "")
        stray = [f for f in self._frames if f not in visited]
        if stray:
            lines.append("frames in a loop (the tree is invalid):")
            lines.extend(
                f"  {f} -> {self._caches[f].latest()[1]}  [{self._edge_label(f)}]" for f in stray
            )
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------------ internals
    def _rate(self, cache: Cache) -> float:
        span = max(cache.latest_stamp() - cache.oldest_stamp(), 100_000)  # 100 us, as tf2
        return len(cache) * _NS / span

    def _edge_label(self, child: str) -> str:
        cache = self._caches[child]
        authority = self._authority.get(child, "no recorded authority")
        if cache.is_static:
            return f"static, broadcaster: {authority}"
        latest, oldest = cache.latest_stamp(), cache.oldest_stamp()
        return (
            f"broadcaster: {authority}, rate: {self._rate(cache):.3f} Hz, "
            f"most recent: {display(latest)}, buffer: {(latest - oldest) / _NS:.3f} s"
        )

    def _validate(self, arg: str, frame_id: str) -> None:
        """tf2's validateFrameId, raising."""
        if frame_id in self._frames:
            return
        if not frame_id:
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {arg} - in tf2 frame_ids cannot be empty'
            )
        if frame_id.startswith("/"):
            raise InvalidArgumentException(
                f'Invalid argument "{frame_id}" passed to {arg} - '
                "in tf2 frame_ids cannot start with a '/'"
            )
        raise LookupException(f'"{frame_id}" passed to {arg} does not exist.')

    @staticmethod
    def _succeeds(lookup: Callable[[], object]) -> bool:
        """True when ``lookup()`` raises no :class:`TransformException`."""
        try:
            lookup()
        except TransformException:
            return False
        return True

    def _lookup_full_pose(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
    ) -> tuple[Pose, int]:
        for arg, frame in (
            ("target_frame", target_frame),
            ("source_frame", source_frame),
            ("fixed_frame", fixed_frame),
        ):
            self._validate(f"lookupTransform argument {arg}", frame)
        fixed_t_source, _ = self._lookup_pose(fixed_frame, source_frame, source_time.nanoseconds)
        target_t_fixed, t_ns = self._lookup_pose(target_frame, fixed_frame, target_time.nanoseconds)
        return mul(target_t_fixed, fixed_t_source), t_ns

    def _lookup_pose(self, target: str, source: str, t_ns: int) -> tuple[Pose, int]:
        if target == source:  # identity needs no validation, as tf2
            if t_ns == 0:
                cache = self._caches.get(target)
                t_ns = cache.latest_stamp() if cache is not None else 0
            return IDENTITY, t_ns
        if t_ns != 0:
            key = (target, source, t_ns)
            found = self._found.get(key)
            if found is None:
                found = self._lookup_pose_at(target, source, t_ns)[0]
                if len(self._found) >= _FOUND_MAX:
                    self._found.clear()
                self._found[key] = found
            return found, t_ns
        hit = self._found_latest.get((target, source))
        if hit is None:
            hit = self._lookup_pose_at(target, source, 0)
            if len(self._found_latest) >= _FOUND_MAX:
                self._found_latest.clear()
            self._found_latest[(target, source)] = hit
        return hit

    def _lookup_pose_at(self, target: str, source: str, t_ns: int) -> tuple[Pose, int]:
        frames = self._frames
        if target not in frames:
            self._validate("lookupTransform argument target_frame", target)
        if source not in frames:
            self._validate("lookupTransform argument source_frame", source)
        if t_ns == 0:
            t_ns = self._latest_common_time(target, source)
        return self._walk(target, source, t_ns), t_ns

    def _walk(self, target: str, source: str, t_ns: int) -> Pose:
        """tf2's walkToTopParent: compose up from source, then up from target."""
        caches = self._caches
        # Up from the source, accumulating top_T_source, until the target or a dead end.
        acc = IDENTITY
        frame = source
        top = source
        extrapolation: ExtrapolationException | None = None
        depth = 0
        while True:
            if frame == target:  # target is an ancestor of source
                return acc
            cache = caches.get(frame)
            if cache is None:  # the root of a tree
                top = frame
                break
            sample = cache.sample_at(t_ns)
            if sample is None:  # there may still be a path through the target side
                top = frame
                extrapolation = cache.extrapolation_error(t_ns)
                break
            acc = sample[1] if acc is IDENTITY else mul(sample[1], acc)
            frame = sample[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()
        # Up from the target, accumulating top_T_target, until the source's top.
        tacc = IDENTITY
        frame = target
        depth = 0
        while frame != top:
            if frame == source:  # source is an ancestor of target
                return inv(tacc)
            cache = caches.get(frame)
            if cache is None:
                break
            sample = cache.sample_at(t_ns)
            if sample is None:
                err = cache.extrapolation_error(t_ns)
                raise type(err)(f"{err}{self._suffix(source, target)}")
            tacc = sample[1] if tacc is IDENTITY else mul(sample[1], tacc)
            frame = sample[0]
            depth += 1
            if depth > MAX_GRAPH_DEPTH:
                raise self._loop_error()
        if frame != top:
            if extrapolation is not None:
                raise type(extrapolation)(f"{extrapolation}{self._suffix(source, target)}")
            raise self._connectivity_error(source, target)
        if tacc is IDENTITY:  # the source's top is the target
            return acc
        return mul(inv(tacc), acc)

    def _latest_common_time(self, target: str, source: str) -> int:
        """tf2's getLatestCommonTime: the oldest of the newest stamps of the dynamic edges
        between the two frames (0 if all static)."""
        chain: list[tuple[int, str]] = []  # (latest stamp, parent) from the source up
        common = _MAX_NS
        for stamp, parent in self._latest_edges(source):
            if stamp:
                common = min(common, stamp)
            chain.append((stamp, parent))
            if parent == target:
                return 0 if common == _MAX_NS else common
        source_ancestors = {parent for _, parent in chain}
        common = _MAX_NS
        common_parent: str | None = None
        for stamp, parent in self._latest_edges(target):
            if stamp:
                common = min(common, stamp)
            if parent in source_ancestors:
                common_parent = parent
                break
            if parent == source:
                return 0 if common == _MAX_NS else common
        if common_parent is None:
            raise self._connectivity_error(source, target)
        for stamp, parent in chain:
            if stamp:
                common = min(common, stamp)
            if parent == common_parent:
                break
        return 0 if common == _MAX_NS else common

    def _latest_edges(self, frame: str) -> Iterator[tuple[int, str]]:
        """``(newest stamp, parent)`` of each edge from ``frame`` up to its root.

        Raises:
            LookupException: more than :data:`MAX_GRAPH_DEPTH` edges (a loop).
        """
        caches = self._caches
        for _ in range(MAX_GRAPH_DEPTH + 1):
            cache = caches.get(frame)
            if cache is None:
                return
            stamp, parent = cache.latest()
            if parent is None:
                return
            yield stamp, parent
            frame = parent
        raise self._loop_error()

    @staticmethod
    def _suffix(source: str, target: str) -> str:
        return f", when looking up transform from frame [{source}] to frame [{target}]"

    @staticmethod
    def _connectivity_error(source: str, target: str) -> ConnectivityException:
        return ConnectivityException(
            f"Could not find a connection between '{target}' and '{source}' because they are "
            "not part of the same tree. Tf has two or more unconnected trees."
        )

    def _loop_error(self) -> LookupException:
        return LookupException(
            "The tf tree is invalid because it contains a loop.\n" + self.all_frames_as_string()
        )
