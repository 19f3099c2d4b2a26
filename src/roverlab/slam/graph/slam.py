"""Graph SLAM in the manner of slam_karto / slam_toolbox (Karto's ``Mapper``), plain arrays.

Per scan (:meth:`GraphSLAM.process`):

1. the beams within ``[min_laser_range, max_laser_range]`` (and the sensor's limits)
   become points in the robot frame through the laser offset;
2. the pose is predicted from the previous estimate and the odometry delta, and corrected
   by Karto's correlative matcher (:mod:`roverlab.slam.graph.matcher`) against the
   correlation grid of the *running buffer* (the last ``scan_buffer_size`` keyframes within
   ``scan_buffer_maximum_scan_distance``), penalised for straying from the prediction;
3. once the odometry moved ``minimum_travel_distance`` or turned ``minimum_travel_heading``
   since the last keyframe, the scan becomes a keyframe, a vertex of the pose graph, with
   Karto's edges (``MapperGraph::AddEdges``): to the previous keyframe, to the closest
   keyframe of the running buffer, and to every *near chain* (older keyframes within
   ``link_scan_maximum_distance``, reached through the graph) that it matches with a
   response above ``link_match_minimum_response_fine``; its pose becomes the
   information-weighted mean of those matches;
4. loop closing (``MapperGraph::TryCloseLoop``): chains of at least
   ``loop_match_minimum_chain_size`` consecutive keyframes within
   ``loop_search_maximum_distance`` that are not reached through the graph within that
   distance are matched coarsely (``loop_search_space_*``, whole chain, no penalty); a
   match with response above ``loop_match_minimum_response_coarse`` and x/y variance
   below ``loop_match_maximum_variance_coarse`` is matched again finely, and with a
   response of at least ``loop_match_minimum_response_fine`` becomes an edge;
5. after new loop edges the graph is optimised (:func:`roverlab.slam.data.pose_solver.optimize`,
   sparse Gauss-Newton / Levenberg-Marquardt, warm-started). A consistency check guards
   against a wrong closure: if afterwards a loop or near-chain edge is off by more than
   ``loop_closure_max_residual``, the new closures are dropped and the poses restored.

The edges, near chains and loop closing of steps 3 to 5 are in
:class:`~roverlab.slam.graph.loops.LoopClosing` (a base class of :class:`GraphSLAM`); the
keyframe record and the pose helpers on plain arrays in :mod:`roverlab.slam.graph.poses`.

Unlike Karto, which drops the scans that are not keyframes, every scan gets a pose: it is
matched against the running buffer like a keyframe and stored relative to its keyframe.
The trajectory (:meth:`GraphSLAM.scan_poses`) places it relative to the optimised poses of
the keyframes before and after it, blended by its position between them, so a correction
of the graph is spread smoothly over the scans.

The map (:meth:`GraphSLAM.occupancy`) is rendered from the optimised poses as Karto's
``OccupancyGrid`` renders it (:mod:`roverlab.slam.graph.outputs`, with the blending of the
scans' poses).

Poses are of the robot (base) frame in the map frame; the map frame starts on the odometry
frame (the first scan's pose is its odometry pose), as in Karto.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.maps.grid import scan_arrays
from roverlab.slam.common import Runaway, RunawayWatch, ScanLike
from roverlab.slam.data.pose_solver import optimize
from roverlab.slam.data.posegraph import PoseGraph
from roverlab.slam.data.trajectory import Trajectory
from roverlab.slam.degeneracy import scan_constraint
from roverlab.slam.graph.errors import GraphSlamInputError
from roverlab.slam.graph.loops import _OPT_ITERATIONS, LoopClosing
from roverlab.slam.graph.matcher import (
    CorrelationGrid,
    MatchResult,
    Penalty,
    block_size,
    build_grid,
    match_scan,
    response,
    valid_points,
)
from roverlab.slam.graph.outputs import GraphMap, blend_scan_poses, render_map
from roverlab.slam.graph.params import GraphParams
from roverlab.slam.graph.poses import (
    _compose,
    _inverse,
    _pose_array,
    _relative,
    _Scan,
    _transform_points,
    _weighted_mean,
    _wrap,
)
from roverlab.slam.laser import beam_endpoints

__all__ = ["GraphMap", "GraphRun", "GraphSLAM", "ScanLike", "run_graph", "run_log"]

FloatArray = NDArray[np.float64]

#: Most re-centred searches when a sequential match lands on the rim of its angular window.
_RIM_SEARCHES = 3


class GraphRun(NamedTuple):
    """Result of a batch run: unpacks as ``poses, map, trajectory``.

    Attributes:
        poses: ``(N, 3)`` final robot pose per scan, map frame.
        map: the map rendered from the optimised poses.
        trajectory: the poses with the scans' timestamps (and their exact texts).
    """

    poses: FloatArray
    map: GraphMap
    trajectory: Trajectory


# ------------------------------------------------------------------------------ the mapper


class GraphSLAM(LoopClosing):
    """Karto / slam_toolbox graph SLAM on plain arrays (no node, no clock, no TF).

    Args:
        params: algorithm parameters (ROS names, slam_toolbox defaults).
        rng: accepted for the common SLAM interface; the method draws no random numbers
            (it is deterministic), so it is unused.
        laser_offset: default laser pose in the robot frame (``base_frame -> laser``).
    """

    def __init__(
        self,
        params: GraphParams | None = None,
        rng: np.random.Generator | None = None,
        *,
        laser_offset: SE2 | None = None,
    ) -> None:
        self.params = params if params is not None else GraphParams()
        self.rng = rng
        self.laser_offset = laser_offset if laser_offset is not None else SE2()
        p = self.params
        self._seq_n = int(
            math.floor(0.5 * p.correlation_search_space_dimension
                       / p.correlation_search_space_resolution + 1e-9)
        )  # fmt: skip
        self._seq_block = block_size(self._seq_n)
        self._loop_block = block_size(
            int(math.floor(0.5 * p.loop_search_space_dimension / p.loop_search_space_resolution))
        )
        self._penalty = Penalty(
            p.distance_variance_penalty,
            p.angle_variance_penalty,
            p.minimum_distance_penalty,
            p.minimum_angle_penalty,
        )
        self.reset()

    # ---------------------------------------------------------------- state
    def reset(self) -> None:
        """Forget everything (an empty graph, no scans)."""
        self._kf_pose = np.zeros((0, 3))
        self._kf_odom = np.zeros((0, 3))
        self._kf_scan_index: list[int] = []
        self._kf_scans: list[_Scan] = []
        self._kf_weak: list[FloatArray | None] = []  # a degenerate keyframe's weak direction
        self._kf_prev_rel = np.zeros((0, 3))  # pose of keyframe k in keyframe k-1 at creation
        self._e_from: list[int] = []
        self._e_to: list[int] = []
        self._e_meas: list[FloatArray] = []
        self._e_info: list[FloatArray] = []
        self._e_kind: list[str] = []  # "sequential", "near", "loop"
        self._buffer: list[int] = []
        self._grid: CorrelationGrid | None = None
        self._scan_ref: list[int] = []
        self._scan_rel: list[FloatArray] = []
        self._all_scans: list[_Scan] = []
        self._last_pose: FloatArray | None = None
        self._last_odom: FloatArray | None = None
        self.loop_closures = 0
        self.rejected_loop_closures = 0
        self.optimisations = 0
        self.rim_searches = 0
        self.degenerate_scans = 0
        self.runaway: Runaway | None = None
        self.last_response = 0.0

    @property
    def num_keyframes(self) -> int:
        """Vertices of the pose graph."""
        return int(self._kf_pose.shape[0])

    @property
    def scans_processed(self) -> int:
        """Scans given to :meth:`process` since the last reset."""
        return len(self._scan_ref)

    @property
    def pose(self) -> SE2:
        """The latest robot pose estimate in the map frame."""
        if self._last_pose is None:
            return SE2()
        return SE2(*(float(v) for v in self._last_pose))

    def map_to_odom(self) -> SE2:
        """The ``map -> odom`` transform: latest pose times the inverse latest odometry."""
        if self._last_pose is None or self._last_odom is None:
            return SE2()
        t = _compose(self._last_pose, _inverse(self._last_odom))
        return SE2(float(t[0]), float(t[1]), float(t[2]))

    # ---------------------------------------------------------------- scans
    def scan_points(
        self,
        ranges: ArrayLike,
        angles: ArrayLike,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
    ) -> FloatArray:
        """The matchable endpoints of a scan, ``(N, 2)`` in the robot frame (m).

        Raises:
            GraphSlamInputError: mismatched shapes or non-finite angles.
        """
        r, a = scan_arrays(ranges, angles, GraphSlamInputError)
        p = self.params
        with np.errstate(invalid="ignore"):
            keep = (
                np.isfinite(r)
                & (r > range_min)
                & (r < range_max)
                & (r >= p.min_laser_range)
                & (r <= p.max_laser_range)
            )
        off = self.laser_offset if laser_offset is None else laser_offset
        return beam_endpoints(r[keep], a[keep], off)

    def process(
        self,
        ranges: ArrayLike,
        angles: ArrayLike,
        odom_pose: ArrayLike | SE2,
        timestamp: float | None = None,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
    ) -> SE2:
        """Process one scan; return the robot pose in the map frame.

        Cheap unless the scan becomes a keyframe (one branch-and-bound match against the
        running buffer's grid).

        Args:
            ranges: ``(N,)`` ranges (m); non-finite ones are dropped.
            angles: ``(N,)`` beam angles in the laser frame (rad).
            odom_pose: robot pose ``(x, y, theta)`` in the odometry frame at the scan.
            timestamp: scan time (s); only checked (it must be finite when given).
            range_min: the sensor's minimum range (m).
            range_max: the sensor's maximum range (m); readings at or beyond it are no
                returns.
            laser_offset: this scan's laser pose in the robot frame (default: the
                constructor's).

        Raises:
            GraphSlamInputError: bad shapes, non-finite angles, odometry or timestamp.
        """
        if timestamp is not None and not math.isfinite(float(timestamp)):
            raise GraphSlamInputError(f"timestamp must be finite, got {timestamp}")
        odom = _pose_array(odom_pose, "odom_pose")
        off = self.laser_offset if laser_offset is None else laser_offset
        pts = self.scan_points(
            ranges, angles, range_min=range_min, range_max=range_max, laser_offset=off
        )
        scan = _Scan(
            points=pts,
            ranges=np.asarray(ranges, dtype=np.float32).reshape(-1).copy(),
            angles=np.asarray(angles, dtype=np.float64).reshape(-1).copy(),
            range_min=float(range_min),
            range_max=float(range_max),
            laser_offset=off.as_array(),
        )
        p = self.params
        if self.params.map_scans == "all":
            self._all_scans.append(scan)
        if self._last_pose is None or self._last_odom is None:
            pose = odom.copy()
            self._add_keyframe(pose, odom, scan, None, None)
            pose = self._kf_pose[-1].copy()
        else:
            pred = _compose(self._last_pose, _relative(self._last_odom, odom))
            last_kf = self.num_keyframes - 1
            d_odom = _relative(self._kf_odom[last_kf], odom)
            keyframe = (
                math.hypot(d_odom[0], d_odom[1]) >= p.minimum_travel_distance
                or abs(d_odom[2]) >= p.minimum_travel_heading
            )
            result: MatchResult | None = None
            weak: FloatArray | None = None
            cov: FloatArray | None = None
            if p.use_scan_matching and pts.shape[0] >= 3 and self._grid is not None:
                result = self._match_sequential(self._grid, pts, pred, penalise=True, cov=keyframe)
                result = self._beyond_the_rim(self._grid, pts, pred, result, keyframe)
                pose, cov = result.pose, result.covariance
                self.last_response = result.response
                if p.degenerate_eigen_ratio > 0.0:
                    ratio, direction = scan_constraint(pts)
                    if ratio < p.degenerate_eigen_ratio:
                        weak = direction
                        self.degenerate_scans += 1
                        pose, cov = self._keep_odometry(weak, pose, pred, cov)
            else:
                pose = pred
            if keyframe:
                self._add_keyframe(pose, odom, scan, cov, weak)
                pose = self._kf_pose[-1].copy()
        k = self.num_keyframes - 1
        self._scan_ref.append(k)
        self._scan_rel.append(_relative(self._kf_pose[k], pose))
        self._last_pose = pose
        self._last_odom = odom
        return SE2(float(pose[0]), float(pose[1]), float(pose[2]))

    # ---------------------------------------------------------------- matching
    def _seq_grid(
        self, frames: list[int], center: FloatArray, viewpoint: FloatArray
    ) -> CorrelationGrid:
        p = self.params
        reach = (
            p.max_laser_range + 0.5 * p.correlation_search_space_dimension
            + p.minimum_travel_distance + 1.0
        )  # fmt: skip
        return build_grid(
            self._world_points(frames, viewpoint),
            resolution=p.correlation_search_space_resolution,
            smear_deviation=p.correlation_search_space_smear_deviation,
            block=self._seq_block,
            bounds=(center[0] - reach, center[1] - reach, center[0] + reach, center[1] + reach),
        )

    def _world_points(self, frames: list[int], viewpoint: FloatArray) -> FloatArray:
        chunks = [
            valid_points(
                _transform_points(self._kf_pose[i], self._kf_scans[i].points),
                (float(viewpoint[0]), float(viewpoint[1])),
            )
            for i in frames
        ]
        return np.concatenate(chunks) if chunks else np.zeros((0, 2))

    def _match_sequential(
        self, grid: CorrelationGrid, pts: FloatArray, pred: FloatArray, *, penalise: bool, cov: bool
    ) -> MatchResult:
        p = self.params
        return match_scan(
            grid,
            pts,
            pred,
            search_dimension=p.correlation_search_space_dimension,
            coarse_angle_offset=p.coarse_search_angle_offset,
            coarse_angle_resolution=p.coarse_angle_resolution,
            fine_angle_offset=p.fine_search_angle_offset,
            penalty=self._penalty if penalise else None,
            refine_angle=True,
            subcell=p.scan_match_refinement,
            covariance=cov,
            response_expansion=p.use_response_expansion,
        )

    def _beyond_the_rim(
        self,
        grid: CorrelationGrid,
        pts: FloatArray,
        pred: FloatArray,
        result: MatchResult,
        cov: bool,
    ) -> MatchResult:
        """A best match on the rim of the angular window is no optimum: the odometry's turn
        was off by more than the window (a log whose odometry stalls for a few scans and
        then catches up at once, as mit-csail's does while turning). Search again centred
        on it, at most ``_RIM_SEARCHES`` times, while the unpenalised response improves."""
        p = self.params
        rim = p.coarse_search_angle_offset - p.coarse_angle_resolution
        centre = pred
        best = response(grid, pts, result.pose)
        for _ in range(_RIM_SEARCHES):
            if abs(_wrap(result.pose[2] - centre[2])) < rim:
                break
            again = self._match_sequential(grid, pts, result.pose, penalise=True, cov=cov)
            score = response(grid, pts, again.pose)
            if score <= best:
                break
            self.rim_searches += 1
            centre, result, best = result.pose, again, score
        return result

    def _laser_position(self, k: int) -> FloatArray:
        return _compose(self._kf_pose[k], self._kf_scans[k].laser_offset)[:2]

    # ---------------------------------------------------------------- graph building
    def _add_keyframe(
        self,
        pose: FloatArray,
        odom: FloatArray,
        scan: _Scan,
        cov: FloatArray | None,
        weak: FloatArray | None,
    ) -> None:
        p = self.params
        k = self.num_keyframes
        self._kf_weak.append(weak)
        prev_rel = np.zeros(3) if k == 0 else _relative(self._kf_pose[k - 1], pose)
        self._kf_pose = np.vstack([self._kf_pose, pose[None, :]])
        self._kf_odom = np.vstack([self._kf_odom, odom[None, :]])
        self._kf_scans.append(scan)
        self._kf_scan_index.append(len(self._scan_ref))
        self._kf_prev_rel = np.vstack([self._kf_prev_rel, prev_rel[None, :]])
        if k > 0:
            if cov is None:
                cov = np.diag([0.25, 0.25, 0.1])  # no match: a loose odometry link
            means = [pose.copy()]
            covs = [cov]
            self._add_edge(k - 1, k, pose, cov, "sequential")
            if self._buffer:
                self._add_edge(self._closest(self._buffer, pose), k, pose, cov, "sequential")
            if p.use_scan_matching and scan.points.shape[0] >= 3:
                for mean, c in self._link_near_chains(k):
                    means.append(mean)
                    covs.append(c)
            if len(means) > 1:
                self._kf_pose[k] = _weighted_mean(means, covs)
                self._kf_prev_rel[k] = _relative(self._kf_pose[k - 1], self._kf_pose[k])
        self._buffer.append(k)
        while len(self._buffer) > p.scan_buffer_size:
            self._buffer.pop(0)
        while len(self._buffer) > 1:
            f = self._kf_pose[self._buffer[0], :2] - self._kf_pose[self._buffer[-1], :2]
            if float(f @ f) > p.scan_buffer_maximum_scan_distance**2 - 1e-9:
                self._buffer.pop(0)
            else:
                break
        if k > 0 and p.do_loop_closing and p.use_scan_matching and scan.points.shape[0] >= 3:
            self._try_close_loop(k)
        self._grid = self._seq_grid(self._buffer, self._kf_pose[k], self._laser_position(k))

    def optimise(self) -> None:
        """Optimise the whole graph now (no consistency check)."""
        if self.num_keyframes > 1 and self._e_from:
            poses, _ = optimize(self.graph(), max_iterations=_OPT_ITERATIONS)
            self.optimisations += 1
            self._kf_pose = np.asarray(poses, dtype=np.float64).copy()
            if self._last_pose is not None:
                k = self._scan_ref[-1]
                self._last_pose = _compose(self._kf_pose[k], self._scan_rel[-1])

    # ---------------------------------------------------------------- outputs
    def graph(self) -> PoseGraph:
        """The pose graph of the keyframes (vertex ``k`` = keyframe ``k``, first fixed),
        at the current estimates; ``roverlab.slam.data.write_g2o`` saves it."""
        k = self.num_keyframes
        if k == 0:
            raise GraphSlamInputError("no scan processed yet: the graph is empty")
        e = len(self._e_from)
        return PoseGraph(
            ids=np.arange(k, dtype=np.int64),
            poses=self._kf_pose.copy(),
            edge_from=np.asarray(self._e_from, dtype=np.intp),
            edge_to=np.asarray(self._e_to, dtype=np.intp),
            measurements=np.asarray(self._e_meas, dtype=np.float64).reshape(e, 3),
            information=np.asarray(self._e_info, dtype=np.float64).reshape(e, 3, 3),
        )

    def keyframe_poses(self) -> FloatArray:
        """``(K, 3)`` current keyframe estimates."""
        return self._kf_pose.copy()

    def scan_poses(self) -> FloatArray:
        """``(N, 3)`` current pose of every processed scan (:func:`blend_scan_poses`)."""
        return blend_scan_poses(
            self._kf_pose, self._kf_prev_rel, self._kf_scan_index, self._scan_ref, self._scan_rel
        )

    def occupancy(self) -> GraphMap:
        """The map rendered from the current (optimised) poses (:func:`render_map`)."""
        if self.params.map_scans == "all":
            return render_map(self.scan_poses(), self._all_scans, self.params)
        return render_map(self._kf_pose, self._kf_scans, self.params)

    # ---------------------------------------------------------------- batch
    def run_log(self, log: Iterable[ScanLike], *, max_extent_m: float = math.inf) -> GraphRun:
        """Process every scan of a laser log (a ``roverlab.slam.data.LaserLog``) in order, then
        optimise the graph once more and return one final pose per scan and the map.

        Args:
            log: the scans.
            max_extent_m: a scan whose predicted pose (the latest estimate moved by the
                odometry) lies farther than this from the first pose along x or y has run
                away: the run stops before it, :attr:`runaway` says where, and the map and
                poses hold the scans before it (default: never).
        """
        stamps: list[str] = []
        self.runaway = None
        watch = RunawayWatch(max_extent_m, "graph")
        for k, rec in enumerate(log):
            pred = self.map_to_odom() * rec.odom_pose
            self.runaway = watch.check(k, float(rec.timestamp), pred.x, pred.y)
            if self.runaway is not None:
                break
            ranges = np.asarray(rec.ranges)
            angles = rec.angle_min + rec.angle_increment * np.arange(ranges.size)
            self.process(
                ranges,
                angles,
                rec.odom_pose,
                float(rec.timestamp),
                range_min=float(rec.range_min),
                range_max=float(rec.range_max),
                laser_offset=rec.laser_offset,
            )
            stamps.append(rec.timestamp_text or f"{rec.timestamp:.6f}")
        self.optimise()
        poses = self.scan_poses()
        return GraphRun(
            poses=poses, map=self.occupancy(), trajectory=Trajectory.from_poses(stamps, poses)
        )


def run_log(
    log: Iterable[ScanLike],
    params: GraphParams | None = None,
    rng: np.random.Generator | None = None,
) -> GraphRun:
    """Run the graph SLAM over a whole laser log; see :meth:`GraphSLAM.run_log`."""
    return GraphSLAM(params, rng).run_log(log)


def run_graph(records: Iterable[ScanLike], params: Mapping[str, Any] | None = None) -> GraphRun:
    """One-call entry point for ``roverlab slam run --method graph``: ROS-named parameters
    (``GraphParams.from_ros``) in, :class:`GraphRun` out.

    Raises:
        GraphSlamParamsError: an unknown parameter or a bad value.
    """
    return GraphSLAM(GraphParams.from_ros(params or {})).run_log(records)
