"""amcl over a recorded laser log (what ``roverlab amcl run`` does, minus files and output).

Each scan is handed to :meth:`Amcl.process_scan` with its odometry pose, and the robot's
pose in the map is taken as a live amcl reports it: ``map -> odom`` of the last published
pose composed with the scan's odometry pose.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.localization.amcl.amcl import Amcl, PoseEstimate
from roverlab.localization.amcl.errors import AmclMapError
from roverlab.localization.amcl.field import AmclMap
from roverlab.localization.amcl.params import AmclParams
from roverlab.maps import OccupancyMap
from roverlab.slam.data.logs import ScanRecord
from roverlab.slam.data.trajectory import Trajectory

__all__ = ["AmclRun", "Snapshot", "localize_log", "map_for_amcl"]

FloatArray = NDArray[np.float64]


def map_for_amcl(occupancy: OccupancyMap, params: AmclParams) -> AmclMap:
    """The amcl map of a loaded map_server map (``laser_likelihood_max_dist`` applied).

    Raises:
        AmclMapError: a rotated origin (amcl ignores the yaw; roverlab refuses it), or a
            map amcl cannot use (see :class:`AmclMap`).
    """
    ox, oy, yaw = occupancy.info.origin
    if abs(yaw) > 1e-9:
        raise AmclMapError(f"the map origin is rotated (yaw {yaw}); amcl needs yaw 0")
    return AmclMap(
        data=occupancy.data,
        resolution_m=occupancy.info.resolution,
        origin_xy=(ox, oy),
        max_dist_m=params.laser_likelihood_max_dist,
    )


@dataclass(frozen=True, eq=False)
class Snapshot:
    """The particles at one moment of a run.

    Attributes:
        scan: index of the scan after which they were taken (-1: before the first).
        particles: ``(N, 3)`` particle poses in the map frame.
        estimate: the last published pose at that moment, or None.
    """

    scan: int
    particles: FloatArray
    estimate: PoseEstimate | None


@dataclass(frozen=True, eq=False)
class AmclRun:
    """The result of :func:`localize_log`.

    Attributes:
        trajectory: the robot's pose in the map at every scan, with the log's timestamps.
        snapshots: particle clouds at the requested moments.
        updates: filter updates.
        resamples: resamplings.
        notes: distinct warnings raised by scans (with how many scans raised each).
    """

    trajectory: Trajectory
    snapshots: list[Snapshot]
    updates: int
    resamples: int
    notes: dict[str, int] = field(default_factory=dict)


def localize_log(
    records: Iterable[ScanRecord], amcl: Amcl, *, snapshot_at: Sequence[int] = ()
) -> AmclRun:
    """Run ``amcl`` over ``records`` (a :class:`~roverlab.slam.data.logs.LaserLog` or any
    iterable of its records).

    Args:
        records: the scans, in order.
        amcl: the filter, initialised.
        snapshot_at: scan indices after which to keep the particles (-1: before the first).

    Raises:
        AmclInputError: a scan amcl cannot read (non-finite odometry, mismatched beams).
    """
    wanted = set(snapshot_at)
    snapshots: list[Snapshot] = []
    if -1 in wanted:
        snapshots.append(Snapshot(-1, amcl.pf.poses.copy(), amcl.last_estimate))
    times: list[float] = []
    texts: list[str] = []
    poses: list[tuple[float, float, float]] = []
    notes: dict[str, int] = {}
    resamples = 0
    for i, rec in enumerate(records):
        off: SE2 = rec.laser_offset
        result = amcl.process_scan(
            odom_pose=rec.odom_pose,
            ranges=rec.ranges,
            bearings=rec.angles() + off.theta,
            laser_xy=(off.x, off.y),
            range_min=rec.range_min,
            range_max=rec.range_max,
        )
        resamples += result.resampled
        if result.note:
            notes[result.note] = notes.get(result.note, 0) + 1
        pose = amcl.pose_at(rec.odom_pose)
        assert pose is not None  # the first scan always publishes
        times.append(rec.timestamp)
        texts.append(rec.timestamp_text)
        poses.append((pose.x, pose.y, pose.theta))
        if i in wanted:
            snapshots.append(Snapshot(i, amcl.pf.poses.copy(), amcl.last_estimate))
    trajectory = Trajectory(
        timestamps=np.array(times, dtype=np.float64),
        poses=np.array(poses, dtype=np.float64).reshape(-1, 3),
        timestamp_texts=tuple(texts),
    )
    return AmclRun(trajectory, snapshots, amcl.updates, resamples, notes)
