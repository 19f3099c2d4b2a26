"""hector_mapping's processor: scan to map matching plus thresholded map updates.

Per scan (hector's ``HectorSlamProcessor::update``):

1. the beams are filtered (``range_min < r < range_max``, ``laser_min_dist <= r <
   laser_max_dist``, the laser height within ``laser_z_min/max_value``) and turned into
   endpoints in the robot frame through the laser offset;
2. the pose is predicted: the previous estimate (hector's default), the previous estimate
   moved by the odometry delta when ``use_odometry`` is set, or moved by the previous
   scan-to-scan motion with ``motion_prediction="constant_velocity"``;
3. the prediction is refined by the coarse-to-fine Gauss-Newton matcher
   (:mod:`roverlab.slam.hector.matcher`);
4. the map pyramid is updated only when the estimate has moved more than
   ``map_update_distance_thresh`` or turned more than ``map_update_angle_thresh`` since the
   last update (the first scan always updates).

Poses are of the robot (base) frame in the map frame, whose origin is the first pose.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.maps.grid import scan_arrays
from roverlab.slam.common import Runaway, ScanLike
from roverlab.slam.data.trajectory import Trajectory
from roverlab.slam.degeneracy import odometry_along, scan_constraint
from roverlab.slam.hector.degeneracy import map_values
from roverlab.slam.hector.errors import HectorInputError, OutOfMapError
from roverlab.slam.hector.grid import HectorMap, MultiResGrid
from roverlab.slam.hector.matcher import match
from roverlab.slam.hector.params import HectorParams
from roverlab.slam.hector.revisit import OCCUPIED_ABOVE, SEARCH_EVERY, Revisit
from roverlab.slam.laser import beam_endpoints

__all__ = ["GuardCounts", "HectorRun", "HectorSLAM", "Runaway", "ScanLike", "run_log"]

#: A cell the map holds free has a value below this (two free observations: 0.31).
_FREE_BELOW = 0.35

_IDENTITY = SE2()


class HectorRun(NamedTuple):
    """Result of a batch run: unpacks as ``poses, map, trajectory``.

    Attributes:
        poses: (N, 3) robot pose ``x, y, theta`` per scan in the map frame.
        map: the finest map level after the last scan.
        trajectory: the same poses with the scans' timestamps (and their exact texts), for
            ``roverlab.slam.data.write_tum`` and ``roverlab.slam.data.evaluate``.
    """

    poses: NDArray[np.float64]
    map: HectorMap
    trajectory: Trajectory


@dataclass(slots=True)
class GuardCounts:
    """How often the odometry guards of :meth:`HectorSLAM.process` acted.

    Attributes:
        degenerate: matches whose weak direction took the odometry increment.
        jumps: matches rejected for moving faster than the robot can.
        collapsed: matches rejected for putting the scan on free space.
        rival: matches started from the scan-only prediction that fitted the map better
            than the one started from the odometry's.
        revisits: corrections found by the wide search on a revisit and taken
            (:mod:`roverlab.slam.hector.revisit`).
        unmapped: scans not mapped while such a correction waited for its confirmations.
    """

    degenerate: int = 0
    jumps: int = 0
    collapsed: int = 0
    rival: int = 0
    revisits: int = 0
    unmapped: int = 0


class HectorSLAM:
    """hector_mapping's algorithm on plain arrays (no node, no clock, no TF).

    Args:
        params: algorithm parameters (ROS names and defaults).
        laser_offset: pose of the laser in the robot frame (``base_frame -> laser``).
        laser_z_m: height of the laser in the robot frame (m), checked against
            ``laser_z_min_value`` / ``laser_z_max_value`` as hector filters endpoints.
        initial_pose: robot pose in the map frame before the first scan.

    Attributes:
        params: the parameters.
        grid: the map pyramid (:class:`MultiResGrid`).
        last_hessian: Gauss-Newton Hessian (3, 3) of the last match on the finest level
            (metres, radians): its inverse, scaled, is hector's pose covariance.
        scans_processed: scans given to :meth:`process` since the last reset.
    """

    def __init__(
        self,
        params: HectorParams | None = None,
        *,
        laser_offset: SE2 = _IDENTITY,
        laser_z_m: float = 0.0,
        initial_pose: SE2 = _IDENTITY,
        grow_max_size: int = 0,
    ) -> None:
        """``grow_max_size``: when the robot or a scan's end point falls outside the map,
        double the map (around its centre) until it holds them, up to this many cells per
        side (0: hector_mapping's fixed map, which drops such end points and raises
        :class:`OutOfMapError` when the robot leaves)."""
        self.params = params if params is not None else HectorParams()
        self.grow_max_size = int(grow_max_size)
        self.laser_offset = laser_offset
        self.laser_z_m = float(laser_z_m)
        self.grid = MultiResGrid(self.params)
        self._initial = np.array([initial_pose.x, initial_pose.y, initial_pose.theta])
        self.reset()

    def reset(self) -> None:
        """Back to an empty map at the initial pose (hector's ``syscommand reset``)."""
        self.grid.reset()
        self._pose = self._initial.copy()
        self._last_update_pose: NDArray[np.float64] | None = None
        self._last_odom: NDArray[np.float64] | None = None
        self._last_motion: NDArray[np.float64] | None = None
        self.last_hessian = np.zeros((3, 3))
        self.scans_processed = 0
        self._last_stamp: float | None = None
        self._period = 0.0
        self.guard_counts = GuardCounts()
        self._revisits = Revisit()
        self.largest_jump = (0.0, math.nan)
        self.runaway: Runaway | None = None

    @property
    def pose(self) -> SE2:
        """The latest robot pose estimate in the map frame."""
        return SE2(float(self._pose[0]), float(self._pose[1]), float(self._pose[2]))

    @property
    def map_updates(self) -> int:
        """How many scans were integrated into the map."""
        return self.grid.updates

    def occupancy(self, level: int = 0) -> HectorMap:
        """A map level (0 is the finest) as an int8 occupancy grid."""
        if not 0 <= level < self.params.map_multi_res_levels:
            raise HectorInputError(f"no map level {level}")
        return self.grid.occupancy(level)

    def scan_points(
        self,
        ranges: ArrayLike,
        angles: ArrayLike,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
    ) -> NDArray[np.float64]:
        """The usable endpoints of a scan, (N, 2) in the robot frame (m).

        Args:
            ranges: (N,) ranges (m).
            angles: (N,) beam angles in the laser frame (rad).
            range_min: readings at or below this are dropped (m).
            range_max: readings at or above this are dropped (m).
            laser_offset: laser pose in the robot frame (default: the constructor's).

        Raises:
            HectorInputError: mismatched shapes or non-finite angles.
        """
        r, a = scan_arrays(ranges, angles, HectorInputError)
        p = self.params
        if not p.laser_z_min_value <= self.laser_z_m <= p.laser_z_max_value:
            return np.zeros((0, 2))
        keep = (
            np.isfinite(r)
            & (r > range_min)
            & (r < range_max)
            & (r >= p.laser_min_dist)
            & (r < p.laser_max_dist)
        )
        off = self.laser_offset if laser_offset is None else laser_offset
        return beam_endpoints(r[keep], a[keep], off)

    def process(
        self,
        scan_ranges: ArrayLike,
        angles: ArrayLike,
        odom_pose: ArrayLike | SE2 | None = None,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
        stamp: float | None = None,
    ) -> SE2:
        """Match one scan, update the map if the robot moved enough, return the pose.

        With ``use_odometry`` the match is checked (:meth:`_guard`): along a direction the
        scan cannot fix the odometry increment is kept, and a match that jumps faster than
        the robot can move or puts the scan on free space is replaced by the odometry
        prediction and not mapped.

        Args:
            scan_ranges: (N,) ranges (m); non-finite ones are dropped.
            angles: (N,) beam angles in the laser frame (rad).
            odom_pose: the odometry pose ``(x, y, theta)`` at the scan, used only when
                ``use_odometry`` (delta since the previous scan) or ``map_with_known_poses``
                (the pose itself) is set.
            range_min: the sensor's minimum range (m); shorter readings are dropped.
            range_max: the sensor's maximum range (m); readings at or beyond are dropped.
            laser_offset: this scan's laser pose in the robot frame (default: the
                constructor's).
            stamp: the scan's time (s), for the velocity check; None skips it.

        Returns:
            The robot pose in the map frame.

        Raises:
            HectorInputError: mismatched shapes, non-finite angles or odometry, or an
                odometry pose missing when the parameters need it.
            OutOfMapError: the estimate left the fixed-size map.
        """
        p = self.params
        off = self.laser_offset if laser_offset is None else laser_offset
        pts = self.scan_points(
            scan_ranges, angles, range_min=range_min, range_max=range_max, laser_offset=off
        )
        odom = _odom_array(odom_pose)
        if odom is None and (p.map_with_known_poses or p.use_odometry):
            raise HectorInputError(
                "odom_pose is required with map_with_known_poses or use_odometry"
            )

        accept, snapped = True, False
        odom_step: NDArray[np.float64] | None = None
        if p.map_with_known_poses:
            assert odom is not None
            pose = odom.copy()
        else:
            pose = self._pose.copy()
            scan_only = pose
            if p.motion_prediction == "constant_velocity" and self._last_motion is not None:
                scan_only = _compose(pose, self._last_motion)
            guarded = p.use_odometry and odom is not None and self._last_odom is not None
            if guarded:
                assert odom is not None and self._last_odom is not None
                odom_step = _relative(self._last_odom, odom)
                pose = _compose(pose, odom_step)
            else:
                pose = scan_only
            if pts.shape[0] and self.grid.updates:
                predicted = pose
                if odom_step is not None:
                    pose, accept = self._guarded_match(pts, predicted, scan_only, stamp)
                    pose, accept, snapped = self._revisit(pts, pose, accept, odom_step)
                else:
                    pose, self.last_hessian = self._match(pts, predicted)
        pose[2] = wrap_angle(float(pose[2]))
        if self.scans_processed:
            self._note_jump(pose, stamp)
        self._grow_to_hold(pose, pts)
        self._check_inside(pose)
        self._last_odom = odom
        # (a revisit's correction is no motion to repeat)
        self._last_motion = (
            odom_step if snapped and odom_step is not None else _relative(self._pose, pose)
        )
        self._pose = pose
        self._last_stamp = stamp
        self.scans_processed += 1

        if (
            pts.shape[0]
            and accept
            and (
                p.map_with_known_poses
                or self._last_update_pose is None
                or _moved(self._last_update_pose, pose, p)
            )
        ):
            self.grid.update(pose, np.array([off.x, off.y]), pts)
            self._last_update_pose = pose.copy()
        return self.pose

    def _guarded_match(
        self,
        pts: NDArray[np.float64],
        predicted: NDArray[np.float64],
        scan_only: NDArray[np.float64],
        stamp: float | None,
    ) -> tuple[NDArray[np.float64], bool]:
        """Match from the odometry's prediction and, when the scan-only prediction differs
        from it by more than ``rival_match_threshold``, from that one too; each match is
        checked (:meth:`_guard`) and the one whose endpoints fit the map best (hector's
        cost ``sum (1 - M)^2``) is taken. Returns the pose and whether the scan may update
        the map: when no match passes, the odometry prediction, unmapped."""
        p = self.params
        dt = self._scan_period(stamp)
        starts = [predicted]
        gap = p.rival_match_threshold
        if gap > 0.0 and (
            math.hypot(scan_only[0] - predicted[0], scan_only[1] - predicted[1]) > gap
            or abs(wrap_angle(float(scan_only[2] - predicted[2]))) > gap
        ):
            starts.append(scan_only)
        best = None
        verdicts = []
        for i, start in enumerate(starts):
            matched, hessian = self._match(pts, start)
            pose, verdict, values, degenerate = self._guard(pts, predicted, matched, dt)
            verdicts.append(verdict)
            if verdict != "ok":
                continue
            cost = float(np.sum((1.0 - values) ** 2))
            if best is None or cost < best[0]:
                best = (cost, pose, hessian, i, degenerate)
        if best is None:
            if verdicts[0] == "jump":
                self.guard_counts.jumps += 1
            else:
                self.guard_counts.collapsed += 1
            return predicted.copy(), False
        _, pose, self.last_hessian, i, degenerate = best
        self.guard_counts.rival += int(i == 1)
        self.guard_counts.degenerate += int(degenerate)
        return pose, True

    def _guard(
        self,
        pts: NDArray[np.float64],
        predicted: NDArray[np.float64],
        matched: NDArray[np.float64],
        dt: float,
    ) -> tuple[NDArray[np.float64], str, NDArray[np.float64], bool]:
        """Check a match against the odometry prediction (see :class:`HectorParams`' odometry
        guards); return the pose (along a degenerate direction: the odometry's), the
        verdict (``"ok"``, ``"jump"``: faster than the robot can move, ``"collapsed"``: the
        scan on free space), the map values under the endpoints at the pose and whether
        the scan was degenerate."""
        p = self.params
        if dt > 0.0 and _too_fast(self._pose, predicted, matched, dt, p):
            return matched, "jump", np.zeros(0), False
        pose = matched.copy()
        degenerate = False
        prob, k = self.grid.level_view(0), float(self.grid.inv_res[0])
        centre = (float(self.grid.centers[0, 0]), float(self.grid.centers[0, 1]))
        values = map_values(prob, k, centre, pose, pts)
        if p.degenerate_eigen_ratio > 0.0:
            # only surfaces the map already holds fix the robot against the map
            ratio, weak = scan_constraint(pts, values > OCCUPIED_ABOVE)
            if ratio < p.degenerate_eigen_ratio:
                pose = odometry_along(pose, predicted, weak)
                degenerate = True
                values = map_values(prob, k, centre, pose, pts)
        if p.max_free_endpoints < 1.0 and pts.shape[0]:
            share = float(np.count_nonzero(values < _FREE_BELOW)) / pts.shape[0]
            if share > p.max_free_endpoints:
                return pose, "collapsed", values, degenerate
        return pose, "ok", values, degenerate

    def _revisit(
        self,
        pts: NDArray[np.float64],
        pose: NDArray[np.float64],
        accept: bool,
        odom_step: NDArray[np.float64],
    ) -> tuple[NDArray[np.float64], bool, bool]:
        """The revisit check (:mod:`roverlab.slam.hector.revisit`) of the guarded match
        ``pose``; returns the pose, whether the scan may be mapped and whether the pose is
        a confirmed correction."""
        p = self.params
        if p.revisit_search <= 0.0 or (
            self._revisits.count == 0 and self.scans_processed % SEARCH_EVERY
        ):
            return pose, accept, False
        hit = self._revisits.search(self.grid, p, pts, pose)
        if hit is None:
            self._revisits.reset()
            return pose, accept, False
        found, hessian = hit
        if self._revisits.offer(found, odom_step) < p.revisit_confirmations:
            self.guard_counts.unmapped += int(accept)
            return pose, False, False
        self._revisits.reset()
        self.guard_counts.revisits += 1
        self.last_hessian = hessian
        return found, True, True

    def _scan_period(self, stamp: float | None) -> float:
        """The time since the previous scan, at least the usual scan period (a running
        mean of the positive gaps: logs such as intel's write scans in bursts 1 ms apart);
        0 when unknown (no stamps, or time went backwards)."""
        if stamp is None or self._last_stamp is None or stamp <= self._last_stamp:
            return 0.0
        dt = stamp - self._last_stamp
        self._period = dt if self._period == 0.0 else 0.9 * self._period + 0.1 * min(dt, 1.0)
        return max(dt, self._period)

    def _note_jump(self, pose: NDArray[np.float64], stamp: float | None) -> None:
        """Remember the largest step of the estimate between two scans, and when."""
        size = math.hypot(pose[0] - self._pose[0], pose[1] - self._pose[1])
        if size > self.largest_jump[0]:
            self.largest_jump = (size, math.nan if stamp is None else float(stamp))

    def match_scan(
        self,
        scan_ranges: ArrayLike,
        angles: ArrayLike,
        start: SE2,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
    ) -> SE2:
        """Match one scan against the current map from ``start``; change nothing.

        Returns ``start`` itself when the map is empty or the scan has no usable beam.
        """
        pts = self.scan_points(
            scan_ranges, angles, range_min=range_min, range_max=range_max, laser_offset=laser_offset
        )
        begin = start.as_array()
        if not pts.shape[0] or not self.grid.updates:
            return start
        pose, _ = self._match(pts, begin)
        return SE2(float(pose[0]), float(pose[1]), float(pose[2]))

    def _match(
        self, pts: NDArray[np.float64], start: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        p = self.params
        return match(
            self.grid.prob,
            self.grid.offsets,
            self.grid.sizes,
            self.grid.inv_res,
            self.grid.centers,
            pts,
            start,
            iters_coarse=p.scan_match_iterations_coarse,
            iters_fine=p.scan_match_iterations_fine,
            angle_search=p.scan_match_angle_search,
            angle_search_step=p.scan_match_angle_search_step,
            translation_search_cells=p.translation_search_cells(),
            damped=p.scan_match_damping,
        )

    def run_log(
        self,
        log: Iterable[ScanLike],
        *,
        use_laser_offset: bool = True,
        stop_on_runaway: bool = False,
    ) -> HectorRun:
        """Process every scan of a laser log (a ``roverlab.slam.data.LaserLog``) in order.

        Each record's ``laser_offset`` places the laser on the robot (hector's
        ``use_tf_scan_transformation``; ``use_laser_offset=False``: the scan is taken in the
        robot frame); the poses returned are of the robot (odometry) frame, one per scan.

        Args:
            log: the scans.
            use_laser_offset: place each scan by its record's laser offset.
            stop_on_runaway: when the estimate leaves the map (beyond ``grow_max_size``),
                stop and return what was mapped so far, with :attr:`runaway` telling where
                (instead of raising :class:`OutOfMapError`).
        """
        poses: list[NDArray[np.float64]] = []
        stamps: list[str] = []
        self.runaway = None
        for k, rec in enumerate(log):
            ranges = np.asarray(rec.ranges)
            angles = rec.angle_min + rec.angle_increment * np.arange(ranges.size)
            try:
                pose = self.process(
                    ranges,
                    angles,
                    rec.odom_pose,
                    range_min=float(rec.range_min),
                    range_max=float(rec.range_max),
                    laser_offset=rec.laser_offset if use_laser_offset else _IDENTITY,
                    stamp=float(rec.timestamp),
                )
            except OutOfMapError as err:
                if not stop_on_runaway:
                    raise
                size, when = self.largest_jump
                self.runaway = Runaway(k, float(rec.timestamp), when, size, str(err))
                break
            poses.append(pose.as_array())
            stamps.append(rec.timestamp_text or f"{rec.timestamp:.6f}")
        arr = np.array(poses, dtype=np.float64).reshape(-1, 3)
        return HectorRun(
            poses=arr, map=self.occupancy(0), trajectory=Trajectory.from_poses(stamps, arr)
        )

    def _grow_to_hold(self, pose: NDArray[np.float64], pts: NDArray[np.float64]) -> None:
        """Double the map until it holds the robot and this scan's end points."""
        x, y, th = float(pose[0]), float(pose[1]), float(pose[2])
        if not (self.grow_max_size and math.isfinite(x) and math.isfinite(y)):
            return
        c, s = math.cos(th), math.sin(th)
        xs = np.append(x + c * pts[:, 0] - s * pts[:, 1], x)
        ys = np.append(y + s * pts[:, 0] + c * pts[:, 1], y)
        lo, hi = (float(xs.min()), float(ys.min())), (float(xs.max()), float(ys.max()))
        while not (self.grid.contains(*lo, 2.0) and self.grid.contains(*hi, 2.0)):
            if 2 * int(self.grid.sizes[0]) > self.grow_max_size:
                return
            self.grid.grow()

    def _check_inside(self, pose: NDArray[np.float64]) -> None:
        x, y = float(pose[0]), float(pose[1])
        if not (math.isfinite(x) and math.isfinite(y)) or not self.grid.contains(x, y, 2.0):
            x0, y0, x1, y1 = self.grid.extent()
            raise OutOfMapError(
                f"the robot at ({x:.2f}, {y:.2f}) m left the map "
                f"[{x0:.2f}, {x1:.2f}] x [{y0:.2f}, {y1:.2f}] m"
                + (
                    f"; it cannot grow beyond {self.grow_max_size} cells per side"
                    if self.grow_max_size
                    else "; increase map_size (or map_resolution) or move map_start_x/map_start_y"
                )
            )


def run_log(log: Iterable[ScanLike], params: HectorParams | None = None) -> HectorRun:
    """Run hector_mapping over a whole laser log; see :meth:`HectorSLAM.run_log`."""
    return HectorSLAM(params).run_log(log)


def _odom_array(odom_pose: ArrayLike | SE2 | None) -> NDArray[np.float64] | None:
    if odom_pose is None:
        return None
    if isinstance(odom_pose, SE2):
        arr = odom_pose.as_array()
    else:
        arr = np.asarray(odom_pose, dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise HectorInputError(f"odom_pose must be 3 finite numbers (x, y, theta), got {arr}")
    return arr


def _relative(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a^-1 * b`` for poses ``(x, y, theta)``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    dx, dy = b[0] - a[0], b[1] - a[1]
    return np.array([c * dx + s * dy, -s * dx + c * dy, wrap_angle(float(b[2] - a[2]))])


def _compose(a: NDArray[np.float64], d: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a * d`` for poses ``(x, y, theta)``."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return np.array(
        [a[0] + c * d[0] - s * d[1], a[1] + s * d[0] + c * d[1], wrap_angle(float(a[2] + d[2]))]
    )


def _too_fast(
    last: NDArray[np.float64],
    predicted: NDArray[np.float64],
    matched: NDArray[np.float64],
    dt: float,
    p: HectorParams,
) -> bool:
    """Whether the match moves the estimate faster than the robot can (and farther than
    the odometry says it went) in ``dt`` seconds."""
    moved = math.hypot(matched[0] - last[0], matched[1] - last[1])
    odo = math.hypot(predicted[0] - last[0], predicted[1] - last[1])
    turned = abs(wrap_angle(float(matched[2] - last[2])))
    odo_turn = abs(wrap_angle(float(predicted[2] - last[2])))
    if p.max_linear_velocity > 0.0 and moved > max(p.max_linear_velocity * dt, odo):
        return True
    return p.max_angular_velocity > 0.0 and turned > max(p.max_angular_velocity * dt, odo_turn)


def _moved(last: NDArray[np.float64], pose: NDArray[np.float64], p: HectorParams) -> bool:
    """hector's ``poseDifferenceLargerThan``: moved beyond either update threshold."""
    if math.hypot(pose[0] - last[0], pose[1] - last[1]) > p.map_update_distance_thresh:
        return True
    return abs(wrap_angle(float(pose[2] - last[2]))) > p.map_update_angle_thresh
