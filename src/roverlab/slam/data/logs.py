"""Laser logs: scans with the robot's odometry pose, from CARMEN logs and ROS bags.

A :class:`LaserLog` is a sequence of :class:`ScanRecord` (one laser scan: ranges, beam
geometry, the robot's odometry pose at the scan and the laser's pose on the robot) with
numpy columns for the per-scan values. Readers are generators, so a long log can be
processed as it is read; :func:`load_log` collects one into a :class:`LaserLog`.

Formats (:func:`iter_log` picks by content and name):

* CARMEN ``.clf`` logs, plain, gzip or bzip2 (:func:`read_clf`): ``FLASER``,
  ``ROBOTLASER1`` and (on request) ``RAWLASER1`` front-laser lines, ``ODOM`` lines for
  scans that carry no pose. The scan timestamp is the line's ``ipc_timestamp``, kept as
  the original text (:attr:`ScanRecord.timestamp_text`) so that trajectory files can
  repeat it byte for byte.
* ROS 1 ``.bag`` files, ROS 2 bag folders and ``.mcap`` files (:func:`read_bag`), via
  rosbags: ``sensor_msgs/LaserScan`` on ``/scan``, odometry from ``nav_msgs/Odometry`` on
  ``/odom`` or else from the ``odom -> base`` transforms on ``/tf``, the laser's mounting
  from ``/tf_static``.

Every problem with a file is a :class:`~roverlab.slam.data.errors.LogError` naming the file
(and, for text logs, the line).
"""

from __future__ import annotations

import bisect
import bz2
import gzip
import inspect
import io
import math
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, overload

import numpy as np
from numpy.typing import NDArray
from rosbags.highlevel import AnyReader, AnyReaderError

from roverlab.geometry import SE2, wrap_angle, yaw_from_quat
from roverlab.msgs import STORE
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.reversing import ReversingRepair
from roverlab.slam.data.trajectory import Trajectory

__all__ = [
    "CLF_RANGE_MAX_M",
    "LaserLog",
    "ScanRecord",
    "carmen_beam_geometry",
    "iter_log",
    "load_log",
    "read_bag",
    "read_clf",
]

FloatArray = NDArray[np.float64]

#: Range limit given to FLASER scans, which do not carry one: CARMEN's ``maximum_range``
#: for the old laser messages. SICK scanners report "no return" as 81.83 or 81.91 m, which
#: lies above it, so those beams are invalid as in a ROS ``LaserScan``.
CLF_RANGE_MAX_M: Final = 80.0

#: Front-laser lines of :func:`read_clf`: those with the robot's pose, and the raw one
#: (read only on request, posed from the ODOM lines).
_POSE_LASERS: Final = ("FLASER", "ROBOTLASER1")
_RAW_LASERS: Final = ("RAWLASER1",)


# ----------------------------------------------------------------------------- records


@dataclass(frozen=True, slots=True, eq=False)
class ScanRecord:
    """One laser scan of a log, with the robot's odometry pose at that time.

    Attributes:
        timestamp: Scan time, s (as in the log: CARMEN ``ipc_timestamp``, ROS header stamp).
        ranges: ``(N,)`` float32 ranges, m, read-only; beam ``i`` points at
            ``angle_min + i * angle_increment`` in the laser frame.
        angle_min: Angle of the first beam, rad.
        angle_increment: Angle between beams, rad.
        range_min: Shortest valid range, m.
        range_max: Longest valid range, m (readings above it mean "no return").
        odom_pose: Robot (base frame) pose in the odometry frame at the scan, interpolated
            from the odometry stream when the format gives odometry separately.
        laser_offset: Laser pose in the robot's base frame.
        timestamp_text: The timestamp exactly as the log wrote it (CARMEN), or
            ``sec.nanosec`` with 9 digits (ROS stamps): writers repeat it byte for byte.
    """

    timestamp: float
    ranges: NDArray[np.float32]
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float
    odom_pose: SE2
    laser_offset: SE2 = field(default_factory=SE2)
    timestamp_text: str = ""

    def __post_init__(self) -> None:
        r = np.array(self.ranges, dtype=np.float32).reshape(-1)  # a private, frozen copy
        r.setflags(write=False)
        object.__setattr__(self, "ranges", r)
        if not self.timestamp_text:
            object.__setattr__(self, "timestamp_text", f"{self.timestamp:.6f}")

    @property
    def angle_max(self) -> float:
        """Angle of the last beam, rad."""
        return self.angle_min + (self.ranges.shape[0] - 1) * self.angle_increment

    @property
    def laser_pose(self) -> SE2:
        """Laser pose in the odometry frame: ``odom_pose * laser_offset``."""
        return self.odom_pose * self.laser_offset

    def angles(self) -> FloatArray:
        """``(N,)`` beam angles in the laser frame, rad."""
        count = self.ranges.shape[0]
        return self.angle_min + np.arange(count, dtype=np.float64) * self.angle_increment

    def points(self) -> FloatArray:
        """``(K, 2)`` end points of the valid beams (finite, within the range limits), m,
        in the laser frame."""
        r = self.ranges.astype(np.float64)
        a = self.angles()
        ok = np.isfinite(r) & (r >= self.range_min) & (r <= self.range_max)
        return np.stack([r[ok] * np.cos(a[ok]), r[ok] * np.sin(a[ok])], axis=1).astype(np.float64)


class LaserLog(Sequence[ScanRecord]):
    """A log's scans in order, with numpy columns of the per-scan values.

    Attributes:
        source: Where the scans came from (a path), for messages.
        timestamps: ``(M,)`` scan times, s.
        timestamp_texts: The scan times as the log wrote them.
        odom_poses: ``(M, 3)`` robot odometry poses ``(x, y, theta)``.
        laser_offsets: ``(M, 3)`` laser poses in the robot frame.
    """

    def __init__(self, records: Iterable[ScanRecord], *, source: str = "") -> None:
        self._records = tuple(records)
        self.source = source
        recs = self._records
        self.timestamps: FloatArray = np.array([r.timestamp for r in recs], dtype=np.float64)
        self.timestamp_texts: tuple[str, ...] = tuple(r.timestamp_text for r in recs)
        self.odom_poses: FloatArray = np.array(
            [(r.odom_pose.x, r.odom_pose.y, r.odom_pose.theta) for r in recs], dtype=np.float64
        ).reshape(-1, 3)
        self.laser_offsets: FloatArray = np.array(
            [(r.laser_offset.x, r.laser_offset.y, r.laser_offset.theta) for r in recs],
            dtype=np.float64,
        ).reshape(-1, 3)
        for arr in (self.timestamps, self.odom_poses, self.laser_offsets):
            arr.setflags(write=False)
        self._index: dict[str, int] | None = None

    def __len__(self) -> int:
        return len(self._records)

    @overload
    def __getitem__(self, i: int) -> ScanRecord: ...
    @overload
    def __getitem__(self, i: slice) -> LaserLog: ...
    def __getitem__(self, i: int | slice) -> ScanRecord | LaserLog:
        if isinstance(i, slice):
            return LaserLog(self._records[i], source=self.source)
        return self._records[i]

    def __iter__(self) -> Iterator[ScanRecord]:
        return iter(self._records)

    def __repr__(self) -> str:
        return f"LaserLog({len(self)} scans, {self.duration_s:.1f} s, source={self.source!r})"

    @property
    def duration_s(self) -> float:
        """Time from the first to the last scan, s (0 for fewer than two scans)."""
        if len(self) < 2:
            return 0.0
        return float(self.timestamps[-1] - self.timestamps[0])

    def index_of(self, timestamp: str | float) -> int:
        """Position of the scan with this timestamp: the exact text, or a float within 1 us.

        Raises:
            ValueError: no scan has that timestamp.
        """
        if isinstance(timestamp, str):
            if self._index is None:
                self._index = {}
                for k, text in enumerate(self.timestamp_texts):
                    self._index.setdefault(text, k)
            k = self._index.get(timestamp, -1)
            if k < 0:
                raise ValueError(f"no scan at {timestamp}")
            return k
        hits = np.flatnonzero(np.abs(self.timestamps - float(timestamp)) <= 1e-6)
        if hits.size == 0:
            raise ValueError(f"no scan at {timestamp}")
        return int(hits[0])

    def laser_poses(self) -> FloatArray:
        """``(M, 3)`` laser poses in the odometry frame (``odom_pose * laser_offset``)."""
        p, o = self.odom_poses, self.laser_offsets
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        out = np.empty_like(p)
        out[:, 0] = p[:, 0] + c * o[:, 0] - s * o[:, 1]
        out[:, 1] = p[:, 1] + s * o[:, 0] + c * o[:, 1]
        out[:, 2] = wrap_angle(p[:, 2] + o[:, 2])
        return out

    def ranges_matrix(self) -> NDArray[np.float32]:
        """``(M, N)`` float32 ranges of all scans.

        Raises:
            LogError: the scans do not all have the same number of beams.
        """
        counts = {r.ranges.shape[0] for r in self._records}
        if len(counts) > 1:
            raise LogError(f"{self.source}: scans have different beam counts {sorted(counts)}")
        if not self._records:
            return np.zeros((0, 0), dtype=np.float32)
        return np.stack([r.ranges for r in self._records])

    def odometry(self, *, frame: str = "robot") -> Trajectory:
        """The raw odometry as a trajectory, with the log's timestamps (texts kept).

        Args:
            frame: ``"robot"`` (the base frame's poses) or ``"laser"`` (the laser's).

        Raises:
            LogError: unknown ``frame``.
        """
        if frame == "robot":
            poses = self.odom_poses
        elif frame == "laser":
            poses = self.laser_poses()
        else:
            raise LogError(f"unknown frame {frame!r} (robot or laser)")
        return Trajectory(
            timestamps=self.timestamps, poses=poses, timestamp_texts=self.timestamp_texts
        )


# ----------------------------------------------------------------------------- odometry


class _PoseStream:
    """Odometry samples in time, and scans waiting for the samples that bracket them."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.poses: list[tuple[float, float, float]] = []
        self.pending: deque[tuple[float, Callable[[SE2], ScanRecord]]] = deque()

    def add(self, t: float, x: float, y: float, theta: float) -> None:
        if not self.times or t >= self.times[-1]:
            self.times.append(t)
            self.poses.append((x, y, theta))
        else:  # out of order (CARMEN logs have a few)
            k = bisect.bisect_right(self.times, t)
            self.times.insert(k, t)
            self.poses.insert(k, (x, y, theta))

    def pose_at(self, t: float) -> SE2:
        """Linear interpolation (angles the short way round); held beyond the ends."""
        times = self.times
        k = bisect.bisect_left(times, t)
        if k == 0:
            return SE2(*self.poses[0])
        if k == len(times):
            return SE2(*self.poses[-1])
        t0, t1 = times[k - 1], times[k]
        (x0, y0, a0), (x1, y1, a1) = self.poses[k - 1], self.poses[k]
        u = 0.0 if t1 <= t0 else (t - t0) / (t1 - t0)
        da = wrap_angle(a1 - a0)
        return SE2(x0 + u * (x1 - x0), y0 + u * (y1 - y0), wrap_angle(a0 + u * da))

    def ready(self) -> Iterator[ScanRecord]:
        """Pending scans that the samples so far bracket."""
        while self.pending and self.times and self.pending[0][0] <= self.times[-1]:
            t, make = self.pending.popleft()
            yield make(self.pose_at(t))

    def drain(self) -> Iterator[ScanRecord]:
        """All pending scans (at the end of the log: poses held beyond the last sample)."""
        while self.pending:
            t, make = self.pending.popleft()
            yield make(self.pose_at(t) if self.times else SE2())


# ----------------------------------------------------------------------------- CARMEN


def carmen_beam_geometry(num_readings: int) -> tuple[float, float]:
    """``(angle_min, angle_increment)`` of a FLASER scan of ``num_readings`` beams.

    A FLASER scan spans 180 degrees from -90 degrees. "Evenly" follows CARMEN
    (``carmen_laser_get_angle_increment``): an odd count covers both ends, so 181 beams
    are 1 degree apart and 361 beams 0.5 degrees (``pi / (n - 1)``); an even count is that
    same scanner with the last beam dropped, so 180 beams are 1 degree apart and end at
    +89 degrees, 360 beams 0.5 degrees apart ending at +89.5 (``pi / n``).
    """
    n = int(num_readings)
    if n <= 1:
        return -0.5 * math.pi, 0.0
    return -0.5 * math.pi, math.pi / (n if n % 2 == 0 else n - 1)


def _open_text_log(path: Path) -> io.BufferedIOBase:
    """The file's bytes, decompressed when it starts with a gzip or bzip2 signature."""
    try:
        with open(path, "rb") as fh:
            magic = fh.read(3)
        if magic[:2] == b"\x1f\x8b":
            return gzip.open(path, "rb")
        if magic == b"BZh":
            return bz2.open(path, "rb")
        return open(path, "rb")
    except OSError as err:
        raise LogError(f"{path}: cannot read: {err.strerror or err}") from err


def _ranges(parts: list[bytes], start: int, n: int) -> NDArray[np.float32]:
    r = np.array(parts[start : start + n], dtype=np.float32)
    if r.shape != (n,):
        raise ValueError(f"expected {n} ranges")
    return r


def _pose(parts: list[bytes], start: int) -> SE2:
    return SE2(float(parts[start]), float(parts[start + 1]), float(parts[start + 2]))


def read_clf(
    path: str | Path,
    *,
    laser_message: str | None = None,
    range_min_m: float = 0.0,
    range_max_m: float | None = None,
    reversing: ReversingRepair | None = None,
) -> Iterator[ScanRecord]:
    """Stream the front-laser scans of a CARMEN log (plain, gzip or bzip2).

    Lines::

        FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname
            logger_timestamp
        ROBOTLASER1 type start_angle fov resolution max_range accuracy remission_mode n r1..rn
            m v1..vm x y theta odom_x odom_y odom_theta tv rv fwd_safety side_safety
            turn_axis ipc_timestamp ipc_hostname logger_timestamp
        RAWLASER1 type start_angle fov resolution max_range accuracy remission_mode n r1..rn
            m v1..vm ipc_timestamp ipc_hostname logger_timestamp
        ODOM x y theta tv rv accel ipc_timestamp ipc_hostname logger_timestamp

    In FLASER and ROBOTLASER1 the first pose is the laser's and the second the robot's
    odometry pose; :attr:`ScanRecord.laser_offset` is the laser pose in the robot frame,
    ``odom^-1 * laser``. FLASER beams follow :func:`carmen_beam_geometry`. A FLASER line
    without the six pose values (old logs) and RAWLASER1 lines take the odometry pose
    interpolated from the ODOM lines at the scan time, and the offset ``x`` from
    ``PARAM robot_frontlaser_offset``. The timestamp is ``ipc_timestamp``, its text kept.
    Comments (``#``), PARAM, other lasers (RLASER, ROBOTLASER2, ...) and other messages
    are skipped.

    Args:
        path: The log.
        laser_message: Which line type to read: ``"FLASER"``, ``"ROBOTLASER1"`` or
            ``"RAWLASER1"``. Default: the first of FLASER / ROBOTLASER1 in the file (logs
            often hold both for the same scans; the other kind is then skipped).
        range_min_m: ``range_min`` of the scans, m.
        range_max_m: ``range_max`` of the scans, m. Default: the line's maximum range
            (ROBOTLASER1, RAWLASER1) or :data:`CLF_RANGE_MAX_M` (FLASER).
        reversing: repair odometry steps that went forward while ``ODOM``'s ``tv`` was
            negative (see :mod:`roverlab.slam.data.reversing`; its counters tell how many);
            None: the poses as logged.

    Yields:
        The scans in file order (pose-less scans once the odometry around them is read).

    Raises:
        LogError: the file cannot be read or a laser / ODOM line is malformed (the message
            names the file and line number).
    """
    p = Path(path)
    if laser_message is not None and laser_message not in (*_POSE_LASERS, *_RAW_LASERS):
        raise LogError(
            f"unknown CARMEN laser message {laser_message!r} (FLASER, ROBOTLASER1 or RAWLASER1)"
        )
    chosen = laser_message
    stream = _PoseStream()
    front_offset = 0.0
    lineno = 0
    with _open_text_log(p) as fh:
        try:
            for lineno, raw in enumerate(fh, start=1):  # noqa: B007 - used in messages
                parts = raw.split()
                if not parts:
                    continue
                tag = parts[0].decode("ascii", "replace")
                if tag.startswith("#"):
                    continue
                if tag == "ODOM":
                    if len(parts) != 10:
                        raise ValueError(f"ODOM needs 9 values, got {len(parts) - 1}")
                    x, y, a = float(parts[1]), float(parts[2]), float(parts[3])
                    if reversing is not None:
                        fixed = reversing.odom(SE2(x, y, a), float(parts[4]))
                        x, y, a = fixed.x, fixed.y, fixed.theta
                    stream.add(float(parts[7]), x, y, a)
                    yield from stream.ready()
                    continue
                if tag == "PARAM":
                    if len(parts) >= 3 and parts[1] == b"robot_frontlaser_offset":
                        front_offset = float(parts[2])
                    continue
                if tag not in _POSE_LASERS and tag not in _RAW_LASERS:
                    continue
                if chosen is None and tag in _POSE_LASERS:
                    chosen = tag
                if tag != chosen:
                    continue
                fix = _as_logged if reversing is None else reversing.scan
                if tag == "FLASER":
                    rec = _flaser(parts, range_min_m, range_max_m, stream, front_offset, fix)
                else:
                    rec = _carmen_laser(
                        parts, tag, range_min_m, range_max_m, stream, front_offset, fix
                    )
                if rec is not None:
                    yield rec
        except (ValueError, IndexError) as err:
            raise LogError(f"{p}:{lineno}: malformed line: {err}") from err
        except (OSError, EOFError) as err:
            raise LogError(f"{p}:{lineno}: cannot read: {err}") from err
    yield from stream.drain()


def _as_logged(pose: SE2) -> SE2:
    return pose


def _timestamp(parts: list[bytes]) -> tuple[float, str]:
    text = parts[-3].decode("ascii")
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"timestamp {text!r} is not finite")
    return value, text


def _flaser(
    parts: list[bytes],
    range_min: float,
    range_max: float | None,
    stream: _PoseStream,
    front_offset: float,
    fix: Callable[[SE2], SE2],
) -> ScanRecord | None:
    n = int(parts[1])
    if n < 0:
        raise ValueError(f"negative beam count {n}")
    has_pose = len(parts) == n + 11
    if not has_pose and len(parts) != n + 5:
        raise ValueError(
            f"FLASER with {n} ranges needs {n + 10} or {n + 4} values, got {len(parts) - 1}"
        )
    ranges = _ranges(parts, 2, n)
    t, text = _timestamp(parts)
    a0, inc = carmen_beam_geometry(n)
    rmax = CLF_RANGE_MAX_M if range_max is None else range_max

    def make(odom: SE2, offset: SE2) -> ScanRecord:
        return ScanRecord(t, ranges, a0, inc, range_min, rmax, odom, offset, text)

    if has_pose:
        laser, odom = _pose(parts, n + 2), _pose(parts, n + 5)
        return make(fix(odom), ~odom * laser)
    offset = SE2(front_offset, 0.0, 0.0)
    stream.pending.append((t, lambda odom: make(odom, offset)))
    return None


def _carmen_laser(
    parts: list[bytes],
    tag: str,
    range_min: float,
    range_max: float | None,
    stream: _PoseStream,
    front_offset: float,
    fix: Callable[[SE2], SE2],
) -> ScanRecord | None:
    start, res, max_range = float(parts[2]), float(parts[4]), float(parts[5])
    n = int(parts[8])
    if n < 0:
        raise ValueError(f"negative beam count {n}")
    ranges = _ranges(parts, 9, n)
    m = int(parts[9 + n])
    tail = 24 if tag == "ROBOTLASER1" else 13
    if m < 0 or len(parts) != n + m + tail:
        raise ValueError(
            f"{tag} with {n} ranges and {m} remissions needs {n + m + tail - 1} values, "
            f"got {len(parts) - 1}"
        )
    t, text = _timestamp(parts)
    rmax = max_range if range_max is None else range_max

    def make(odom: SE2, offset: SE2) -> ScanRecord:
        return ScanRecord(t, ranges, start, res, range_min, rmax, odom, offset, text)

    if tag == "ROBOTLASER1":
        k = 10 + n + m
        laser, odom = _pose(parts, k), _pose(parts, k + 3)
        return make(fix(odom), ~odom * laser)
    offset = SE2(front_offset, 0.0, 0.0)
    stream.pending.append((t, lambda odom: make(odom, offset)))
    return None


# ----------------------------------------------------------------------------- ROS bags


def _stamp(header: Any) -> tuple[int, str]:
    sec, nanosec = int(header.stamp.sec), int(header.stamp.nanosec)
    return sec * 1_000_000_000 + nanosec, f"{sec}.{nanosec:09d}"


def _static_offset(
    static: dict[str, tuple[str, SE2]], base_frame: str, laser_frame: str
) -> SE2 | None:
    """Pose of ``laser_frame`` in ``base_frame`` through the static tree, if connected."""
    chain = SE2()
    frame = laser_frame
    seen = set()
    while frame != base_frame:
        if frame in seen or frame not in static:
            return None
        seen.add(frame)
        parent, t = static[frame]
        chain = t * chain
        frame = parent
    return chain


def _transform_se2(tf: Any) -> tuple[str, str, SE2]:
    tr, q = tf.transform.translation, tf.transform.rotation
    pose = SE2(float(tr.x), float(tr.y), yaw_from_quat((q.x, q.y, q.z, q.w)))
    return tf.header.frame_id.lstrip("/"), tf.child_frame_id.lstrip("/"), pose


def read_bag(
    path: str | Path,
    *,
    scan_topic: str = "/scan",
    odom_topic: str | None = "/odom",
    tf_topic: str | None = "/tf",
    tf_static_topic: str = "/tf_static",
    odom_frame: str = "odom",
    base_frame: str | None = None,
    laser_frame: str | None = None,
) -> Iterator[ScanRecord]:
    """Stream the scans of a ROS 1 bag, ROS 2 bag folder or MCAP file.

    Odometry comes from ``nav_msgs/Odometry`` on ``odom_topic`` if the bag has it, else
    from the ``odom_frame -> base_frame`` transforms on ``tf_topic``; the robot pose at a
    scan is interpolated (linear, angles the short way) at the scan's header stamp. The
    laser offset is ``base_frame -> laser_frame`` through the transforms of
    ``tf_static_topic`` (zero when they do not connect the two frames).

    Args:
        path: A ``.bag`` file, a ROS 2 bag folder or a ``.mcap`` file.
        scan_topic: ``sensor_msgs/LaserScan`` topic.
        odom_topic: ``nav_msgs/Odometry`` topic (None: do not use one).
        tf_topic: Dynamic transforms, used when there is no odometry topic (None: never).
        tf_static_topic: Static transforms, for the laser offset.
        odom_frame: Parent frame of the odometry transforms on ``tf_topic``.
        base_frame: Robot frame. Default: the Odometry messages' ``child_frame_id``, or the
            child of the first ``odom_frame`` transform on ``tf_topic``.
        laser_frame: Laser frame. Default: the scans' ``header.frame_id``.

    Yields:
        The scans in bag order, each once the odometry after it has been read.

    Raises:
        LogError: the bag cannot be read, has no scan topic, or has no odometry while
            ``odom_topic`` or ``tf_topic`` asked for it (pass both as None to read scans
            without odometry: their poses are then the identity).
    """
    p = Path(path)
    if p.is_file() and p.suffix.lower() == ".db3":  # a ROS 2 bag named by its database
        p = p.parent
    try:
        reader = AnyReader([p], default_typestore=STORE.typestore)
        reader.open()
    except (AnyReaderError, OSError, ValueError, KeyError) as err:
        raise LogError(f"{p}: cannot read as a ROS bag or MCAP file: {err}") from err
    try:
        yield from _bag_scans(
            reader,
            p,
            scan_topic=scan_topic,
            odom_topic=odom_topic,
            tf_topic=tf_topic,
            tf_static_topic=tf_static_topic,
            odom_frame=odom_frame.lstrip("/"),
            base_frame=base_frame.lstrip("/") if base_frame else None,
            laser_frame=laser_frame.lstrip("/") if laser_frame else None,
        )
    except LogError:
        raise
    except Exception as err:  # rosbags raises many kinds on corrupt data
        raise LogError(f"{p}: cannot read: {err}") from err
    finally:
        reader.close()


class _Frames:
    """The robot and laser frames of a bag and the laser offset between them."""

    def __init__(
        self, static: dict[str, tuple[str, SE2]], base: str | None, laser: str | None
    ) -> None:
        self.static = static
        self.base = base
        self.laser = laser
        self._offset: SE2 | None = None

    def offset(self) -> SE2:
        """``base -> laser`` through the static transforms (identity if not connected)."""
        if self._offset is None:
            found = _static_offset(self.static, self.base or "base_footprint", self.laser or "")
            self._offset = found if found is not None else SE2()
        return self._offset


def _scan_maker(msg: Any, ns: int, text: str, frames: _Frames) -> Callable[[SE2], ScanRecord]:
    ranges = np.array(msg.ranges, dtype=np.float32)
    fields = (
        float(msg.angle_min),
        float(msg.angle_increment),
        float(msg.range_min),
        float(msg.range_max),
    )

    def make(odom: SE2) -> ScanRecord:
        return ScanRecord(ns * 1e-9, ranges, *fields, odom, frames.offset(), text)

    return make


def _bag_scans(
    reader: Any,
    p: Path,
    *,
    scan_topic: str,
    odom_topic: str | None,
    tf_topic: str | None,
    tf_static_topic: str,
    odom_frame: str,
    base_frame: str | None,
    laser_frame: str | None,
) -> Iterator[ScanRecord]:
    by_topic: dict[str, list[Any]] = {}
    for con in reader.connections:
        by_topic.setdefault(con.topic, []).append(con)
    if scan_topic not in by_topic:
        topics = ", ".join(sorted(by_topic)) or "none"
        raise LogError(f"{p}: no topic {scan_topic} (topics: {topics})")
    use_odom = odom_topic is not None and odom_topic in by_topic
    use_tf = not use_odom and tf_topic is not None and tf_topic in by_topic
    if (odom_topic is not None or tf_topic is not None) and not (use_odom or use_tf):
        asked = " or ".join(t for t in (odom_topic, tf_topic) if t is not None)
        raise LogError(
            f"{p}: no odometry: no topic {asked} (pass odom_topic=None, tf_topic=None to "
            "read the scans without odometry)"
        )
    static: dict[str, tuple[str, SE2]] = {}
    if tf_static_topic in by_topic:  # (no connections would mean every message)
        for con, _, raw in reader.messages(connections=by_topic[tf_static_topic]):
            for tf in reader.deserialize(raw, con.msgtype).transforms:
                parent, child, pose = _transform_se2(tf)
                static[child] = (parent, pose)
    frames = _Frames(static, base_frame, laser_frame)
    conns = list(by_topic[scan_topic])
    if use_odom:
        conns += by_topic[str(odom_topic)]
    elif use_tf:
        conns += by_topic[str(tf_topic)]
    stream = _PoseStream()
    for con, log_ns, raw in reader.messages(connections=conns):
        msg = reader.deserialize(raw, con.msgtype)
        if con.topic == scan_topic:
            ns, text = _stamp(msg.header)
            if ns == 0:  # an unstamped scan: use the recording time
                ns = log_ns
                text = f"{log_ns // 1_000_000_000}.{log_ns % 1_000_000_000:09d}"
            if frames.laser is None:
                frames.laser = msg.header.frame_id.lstrip("/")
            make = _scan_maker(msg, ns, text, frames)
            if not (use_odom or use_tf):
                yield make(SE2())
                continue
            stream.pending.append((ns * 1e-9, make))
        elif use_odom:
            if frames.base is None:
                frames.base = msg.child_frame_id.lstrip("/") or None
            ns, _ = _stamp(msg.header)
            pose = msg.pose.pose
            q = pose.orientation
            stream.add(
                ns * 1e-9,
                float(pose.position.x),
                float(pose.position.y),
                yaw_from_quat((q.x, q.y, q.z, q.w)),
            )
        else:
            for tf in msg.transforms:
                parent, child, se2 = _transform_se2(tf)
                if parent != odom_frame or (frames.base is not None and child != frames.base):
                    continue
                frames.base = child
                ns, _ = _stamp(tf.header)
                stream.add(ns * 1e-9, se2.x, se2.y, se2.theta)
        yield from stream.ready()
    if stream.pending and not stream.times:
        source = (
            f"messages on {odom_topic}"
            if use_odom
            else f"{odom_frame} -> base transforms on {tf_topic}"
        )
        raise LogError(
            f"{p}: no odometry: no {source} (pass odom_topic=None, tf_topic=None to read "
            "the scans without odometry)"
        )
    yield from stream.drain()


# ----------------------------------------------------------------------------- any log

_BAG_SUFFIXES: Final = (".bag", ".mcap", ".db3")


def _reader_for(path: Path) -> Callable[..., Iterator[ScanRecord]]:
    if path.is_dir() or path.suffix.lower() in _BAG_SUFFIXES:
        return read_bag
    return read_clf


def iter_log(path: str | Path, **options: Any) -> Iterator[ScanRecord]:
    """Stream the scans of any supported log: a ROS bag folder, ``.bag``, ``.mcap`` (or a
    ROS 2 ``.db3``) goes to :func:`read_bag`, anything else to :func:`read_clf`.

    Args:
        path: The log.
        **options: Keyword options of the chosen reader.

    Raises:
        LogError: the file does not exist, an option is not one of the reader's, or
            reading fails.
    """
    p = Path(path)
    if not p.exists():
        raise LogError(f"{p}: no such file or directory")
    reader = _reader_for(p)
    allowed = [
        name
        for name, param in inspect.signature(reader).parameters.items()
        if param.kind is inspect.Parameter.KEYWORD_ONLY
    ]
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise LogError(
            f"{p}: unknown option(s) {', '.join(unknown)} for {reader.__name__} "
            f"(accepted: {', '.join(allowed)})"
        )
    return reader(p, **options)


def load_log(path: str | Path, **options: Any) -> LaserLog:
    """All scans of a log (see :func:`iter_log` for the formats and options)."""
    return LaserLog(iter_log(path, **options), source=str(path))
