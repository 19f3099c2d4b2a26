"""Scans of a laser log: :class:`ScanRecord` (one scan with the robot's odometry pose and
the laser's mounting) and :class:`LaserLog` (a sequence of them with numpy columns); the
readers are :mod:`roverlab.slam.data.carmen` and :mod:`roverlab.slam.data.bag_logs`,
chosen by :func:`roverlab.slam.data.logs.iter_log`.
"""

from __future__ import annotations

import bisect
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import overload

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.trajectory import Trajectory

__all__ = ["LaserLog", "ScanRecord"]

FloatArray = NDArray[np.float64]


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
