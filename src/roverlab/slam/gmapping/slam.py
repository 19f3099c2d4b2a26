"""slam_gmapping's filter: a Rao-Blackwellised particle filter with the improved proposal.

Grisetti, Stachniss and Burgard, "Improved Techniques for Grid Mapping with
Rao-Blackwellized Particle Filters", IEEE T-RO 2007. Each particle carries a pose, a weight,
a trajectory (a node in a shared tree) and its own count map. Per scan:

1. every particle moves by the odometry delta plus sampled noise
   (:mod:`roverlab.slam.gmapping.motion`);
2. only once the robot has travelled ``linearUpdate``, turned ``angularUpdate`` or (if
   ``temporalUpdate >= 0``) waited ``temporalUpdate`` since the last update, the scan is
   used (the first scan is always used: it seeds every map at the first odometry pose, so
   the map frame is the odometry frame at the start):

   a. each particle's pose is refined by hill climbing on its own map (steps ``lstep`` /
      ``astep`` halved ``iterations`` times, score with ``sigma`` and ``kernelSize``);
      a score at or below ``minimumScore`` keeps the odometry sample instead;
   b. the improved proposal: the poses on a grid of ``+-llsamplerange`` (step
      ``llsamplestep``) and ``+-lasamplerange`` (step ``lasamplestep``) around that pose are
      weighted by scan likelihood (``lsigma``) times odometry density; their weighted mean
      and covariance give a Gaussian from which the particle's new pose is drawn, and their
      sum (the normaliser eta) multiplies the particle's weight;
   c. adaptive resampling: with the weights normalised as
      ``exp((log w - max) / (ogain * particles))``, the particles are resampled
      (systematic resampling) only when ``Neff = 1 / sum w^2`` falls below
      ``resampleThreshold * particles``;
   d. the scan is integrated into every particle's map at its new pose; beams are cropped
      to ``maxUrange`` and readings beyond ``maxRange`` are dropped.

One addition to gmapping (on by default, ``recover_odometry_failures=False`` turns it off):
when even the best particle's hill climbing matches poorly (score below 70 % of the beams),
the odometry is taken to have failed -- a push, wheel slip, or a log whose odometry counts
reversing as driving forward (Freiburg 079) -- and a coarse exhaustive search around the
odometry sample restarts the hill climbing (:meth:`GMapping._recover`). gmapping itself
cannot recover from such a jump: its hill climbing only finds the nearest optimum.

Poses are of the robot (odometry ``base_frame``) in the map frame; the laser's pose on the
robot is ``laser_offset``. All randomness comes from the ``numpy.random.Generator`` given
to the constructor, so a seeded run is reproducible.

The hill climbing and the recovery are in :class:`~roverlab.slam.gmapping.matching.ScanMatching`
(a base class of :class:`GMapping`); the per-scan poses of :meth:`GMapping.run_log` in
:mod:`roverlab.slam.gmapping.scan_poses`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.maps.grid import scan_arrays
from roverlab.slam.common import Runaway, RunawayWatch, ScanLike
from roverlab.slam.degeneracy import odometry_along, scan_constraint
from roverlab.slam.gmapping import kernels
from roverlab.slam.gmapping.errors import GMappingInputError
from roverlab.slam.gmapping.grid import GMappingMap, ParticleMaps
from roverlab.slam.gmapping.matching import _RECOVER_BELOW, ScanMatching, _Beams, scan_beams
from roverlab.slam.gmapping.motion import (
    compose,
    motion_sigmas,
    relative,
    sample_motion,
    wrap,
)
from roverlab.slam.gmapping.params import GMappingParams
from roverlab.slam.gmapping.scan_poses import _scan_poses

__all__ = ["GMapping", "GMappingRun", "Particle", "ScanLike", "UpdateInfo", "run_log"]

_NO_OFFSET = SE2()
# Log-likelihood of a beam without a correspondence is this over lsigma (gmapping's
# "null likelihood").
_NULL_LIKELIHOOD = -0.5
# Floors of the odometry density's standard deviations in the proposal (m, rad): a robot
# that reports no motion (a temporal update) still lets the scan matcher move it a little.
_MIN_SIGMA_XY = 0.01
_MIN_SIGMA_TH = 0.005


@dataclass(frozen=True, slots=True)
class Particle:
    """A snapshot of one particle.

    Attributes:
        index: its slot in the filter.
        pose: its current robot pose in the map frame.
        log_weight: its log weight since the last resampling.
        weight_sum: its log weight accumulated over the whole run (gmapping ranks the
            particles by this to pick the best).
        trajectory: (K, 3) its robot pose at each of the K filter updates so far.
    """

    index: int
    pose: SE2
    log_weight: float
    weight_sum: float
    trajectory: NDArray[np.float64]


class UpdateInfo(NamedTuple):
    """What one filter update did.

    Attributes:
        timestamp: the scan's timestamp (s).
        neff: the effective sample size after weighting (``particles`` on the first scan).
        resampled: whether the particles were resampled.
    """

    timestamp: float
    neff: float
    resampled: bool


class GMappingRun(NamedTuple):
    """Result of :meth:`GMapping.run_log`.

    Attributes:
        poses: (N, 3) robot pose per scan of the log, in the map frame, from the best
            particle's trajectory; scans between two updates get the pose of the last
            update moved by the odometry since.
        map: the best particle's map as published (:class:`GMappingMap`).
        timestamps: (N,) the scans' timestamps (s).
    """

    poses: NDArray[np.float64]
    map: GMappingMap
    timestamps: NDArray[np.float64]


class GMapping(ScanMatching):
    """slam_gmapping's particle filter on plain arrays (no node, no clock, no TF).

    Args:
        params: the ROS parameters (defaults: gmapping's).
        rng: the only source of randomness (a seed is turned into ``default_rng(seed)``;
            ``None`` draws fresh entropy).
        laser_offset: pose of the laser in the robot frame (``base_frame -> laser``); each
            call of :meth:`process` may override it.
        recover_odometry_failures: search widely when every particle's scan match fails
            (see the module docstring); ``False`` is plain gmapping.
        degenerate_eigen_ratio: (roverlab) a scan whose surface normals' eigenvalue ratio
            is below this (a bare corridor: :func:`roverlab.slam.degeneracy.scan_constraint`)
            cannot fix the robot along its weak direction: there each particle's match keeps
            the particle's own (odometry-sampled) position; 0 (the default) is plain
            gmapping, whose matcher slips back along a corridor. Off by default: 0.01 gives
            0.0394 m on intel (seed 0, plain 0.0379), fr079 unchanged.

    Attributes:
        history: one :class:`UpdateInfo` per filter update (Neff, resampled or not).
        resamples: how many updates resampled.
        recoveries: how many updates needed (and accepted) the odometry-failure search.
        maps: the particles' maps (:class:`ParticleMaps`).
    """

    def __init__(
        self,
        params: GMappingParams | None = None,
        rng: np.random.Generator | int | None = None,
        *,
        laser_offset: SE2 = _NO_OFFSET,
        recover_odometry_failures: bool = True,
        degenerate_eigen_ratio: float = 0.0,
    ) -> None:
        self.params = params if params is not None else GMappingParams()
        self.recover_odometry_failures = bool(recover_odometry_failures)
        self.degenerate_eigen_ratio = float(degenerate_eigen_ratio)
        self.degenerate_updates = 0
        if isinstance(rng, np.random.Generator):
            self._rng = rng
        else:
            self._rng = np.random.default_rng(rng)
        self.laser_offset = laser_offset
        p = self.params
        nl = int(math.floor(p.llsamplerange / p.llsamplestep + 1e-9))
        na = int(math.floor(p.lasamplerange / p.lasamplestep + 1e-9))
        lin = np.arange(-nl, nl + 1) * p.llsamplestep
        ang = np.arange(-na, na + 1) * p.lasamplestep
        gx, gy, gt = np.meshgrid(lin, lin, ang, indexing="ij")
        self._offsets = np.ascontiguousarray(np.stack([gx.ravel(), gy.ravel(), gt.ravel()], 1))
        self.reset()

    # ------------------------------------------------------------------------ state
    def reset(self) -> None:
        """Forget everything: no map, no trajectory (the generator is not reseeded)."""
        p = self.params
        n = p.particles
        self.maps = ParticleMaps(n, p.delta, (p.xmin, p.ymin))
        self._poses = np.zeros((n, 3))
        self._log_w = np.zeros(n)
        self._w_sum = np.zeros(n)
        self._node = np.full(n, -1, dtype=np.int64)
        self._tree_pose = np.zeros((1024, 3))
        self._tree_parent = np.full(1024, -1, dtype=np.int64)
        self._tree_size = 0
        self._initialized = False
        self._scans_seen = 0
        self._last_odom = np.zeros(3)
        self._update_odom = np.zeros(3)
        self._update_poses = np.zeros((n, 3))
        self._update_time = 0.0
        self._linear = 0.0
        self._angular = 0.0
        self._motion_var = np.zeros(3)
        self.history: list[UpdateInfo] = []
        self.resamples = 0
        self.recoveries = 0
        self.runaway: Runaway | None = None

    @property
    def updates(self) -> int:
        """How many scans were integrated (the first one included)."""
        return len(self.history)

    @property
    def poses(self) -> NDArray[np.float64]:
        """(P, 3) current robot poses of all particles (a copy)."""
        return self._poses.copy()

    @property
    def update_odom(self) -> SE2:
        """The odometry pose at the last update."""
        u = self._update_odom
        return SE2(float(u[0]), float(u[1]), float(u[2]))

    def weights(self) -> NDArray[np.float64]:
        """(P,) normalised weights, smoothed as gmapping does (``ogain``)."""
        gain = 1.0 / (self.params.ogain * self.params.particles)
        w = np.exp(gain * (self._log_w - self._log_w.max()))
        return np.asarray(w / w.sum(), dtype=np.float64)

    def neff(self) -> float:
        """The effective sample size ``1 / sum w^2`` of :meth:`weights`."""
        w = self.weights()
        return float(1.0 / np.sum(w * w))

    def best_index(self) -> int:
        """The particle with the largest accumulated log weight (gmapping's choice)."""
        return int(np.argmax(self._w_sum))

    def trajectory(self, index: int) -> NDArray[np.float64]:
        """(K, 3) robot poses of particle ``index`` at each of the K updates so far."""
        if not 0 <= index < self.params.particles:
            raise GMappingInputError(f"no particle {index}")
        if self._node[index] < 0:
            return np.zeros((0, 3))
        chain = kernels.backtrack(self._tree_parent[: self._tree_size], int(self._node[index]))
        return self._tree_pose[chain].copy()

    def particle(self, index: int) -> Particle:
        """A snapshot of particle ``index``."""
        traj = self.trajectory(index)
        x, y, t = (float(v) for v in self._poses[index])
        return Particle(
            index=index,
            pose=SE2(x, y, t),
            log_weight=float(self._log_w[index]),
            weight_sum=float(self._w_sum[index]),
            trajectory=traj,
        )

    def best_particle(self) -> Particle:
        """A snapshot of the best particle (:meth:`best_index`)."""
        return self.particle(self.best_index())

    def map_to_odom(self) -> SE2:
        """``map -> odom`` at the last update: the best particle's pose there times the
        inverse of the odometry pose there (what slam_gmapping broadcasts)."""
        best = self.best_index()
        node = int(self._node[best])
        pose = self._tree_pose[node] if node >= 0 else np.zeros(3)
        m = SE2(float(pose[0]), float(pose[1]), float(pose[2]))
        return m * ~self.update_odom

    def occupancy(self, index: int | None = None) -> GMappingMap:
        """A particle's map (default: the best one) as slam_gmapping publishes it.

        It covers the configured ``xmin .. ymax`` box and everything explored beyond it;
        cells never seen are -1, cells whose hit ratio exceeds ``occ_thresh`` 100, others 0.
        """
        i = self.best_index() if index is None else index
        if not 0 <= i < self.params.particles:
            raise GMappingInputError(f"no particle {i}")
        p = self.params
        return self.maps.occupancy(i, p.occ_thresh, (p.xmin, p.ymin, p.xmax, p.ymax))

    # ------------------------------------------------------------------------ scans
    def process(
        self,
        ranges: ArrayLike,
        angles: ArrayLike,
        odom_pose: ArrayLike | SE2,
        timestamp: float,
        *,
        range_min: float = 0.0,
        range_max: float = math.inf,
        laser_offset: SE2 | None = None,
    ) -> bool:
        """Feed one scan with the odometry pose at its time.

        Args:
            ranges: (N,) ranges (m); NaN, non-positive and beyond-``maxRange`` readings are
                dropped; readings below ``range_min`` count as ``range_max``, as
                slam_gmapping does.
            angles: (N,) beam angles in the laser frame (rad).
            odom_pose: the robot's odometry pose ``(x, y, theta)`` at the scan.
            timestamp: the scan's time (s), for ``temporalUpdate``.
            range_min: the sensor's minimum range (m).
            range_max: the sensor's maximum range (m); ``maxRange`` defaults to it minus
                1 cm.
            laser_offset: this scan's laser pose in the robot frame (default: the
                constructor's).

        Returns:
            Whether the filter was updated (the scan was integrated into the maps).

        Raises:
            GMappingInputError: mismatched shapes, non-finite angles, odometry or time.
        """
        r, a = scan_arrays(ranges, angles, GMappingInputError)
        odom = _odom_array(odom_pose)
        t = float(timestamp)
        if not math.isfinite(t):
            raise GMappingInputError(f"timestamp must be finite, got {timestamp!r}")
        off = self.laser_offset if laser_offset is None else laser_offset
        self._scans_seen += 1
        if self._scans_seen % self.params.throttle_scans != 0:
            return False
        beams = scan_beams(r, a, float(range_min), float(range_max), off, self.params)
        if not self._initialized:
            self._initialize(beams, odom, t)
            return True
        p = self.params
        u = relative(self._last_odom, odom)
        sig = motion_sigmas(u, p)
        self._poses = sample_motion(self._poses, u, sig, self._rng)
        self._motion_var += sig * sig
        self._last_odom = odom
        self._linear += math.hypot(float(u[0]), float(u[1]))
        self._angular += abs(float(u[2]))
        due = (
            self._linear >= p.linearUpdate
            or self._angular >= p.angularUpdate
            or (p.temporalUpdate >= 0.0 and t - self._update_time > p.temporalUpdate)
        )
        if not due:
            return False
        self._update(beams, odom, t)
        return True

    def run_log(
        self,
        log: Iterable[ScanLike],
        *,
        interpolate: bool = False,
        max_extent_m: float = math.inf,
    ) -> GMappingRun:
        """Process every scan of a laser log (``roverlab.slam.data.logs.LaserLog``) in order.

        Each record's ``laser_offset`` places the laser on the robot. Returns one robot pose
        per scan from the best particle's trajectory (see :class:`GMappingRun`) and its map.

        Args:
            log: the scans, in time order.
            interpolate: how scans between two updates get their pose. ``False`` (what a
                running slam_gmapping reports): the pose of the last update moved by the
                odometry since. ``True`` (offline smoothing): a blend of that and the pose
                of the next update moved back by the odometry, weighted by how far the robot
                had come between the two updates (travel over ``linearUpdate`` plus turn
                over ``angularUpdate``); so the correction the next update makes is spread
                over the scans before it instead of appearing as a jump.
            max_extent_m: a scan whose predicted pose (the best particle's at the last
                update moved by the odometry since) lies farther than this from the first
                one along x or y has run away: the run stops before it, :attr:`runaway` says
                where, and the map and poses hold the scans before it (default: never).
        """
        stamps: list[float] = []
        odoms: list[NDArray[np.float64]] = []
        after: list[int] = []  # index of the last update at or before each scan
        update_scans: list[int] = []  # scan index of each update
        first = self.updates
        self.runaway = None
        watch = RunawayWatch(max_extent_m, "gmapping")
        for k, rec in enumerate(log):
            pred = self.map_to_odom() * rec.odom_pose
            self.runaway = watch.check(k, float(rec.timestamp), pred.x, pred.y)
            if self.runaway is not None:
                break
            ranges = np.asarray(rec.ranges)
            angles = rec.angle_min + rec.angle_increment * np.arange(ranges.size)
            odom = _odom_array(rec.odom_pose)
            if self.process(
                ranges,
                angles,
                odom,
                float(rec.timestamp),
                range_min=float(rec.range_min),
                range_max=float(rec.range_max),
                laser_offset=rec.laser_offset,
            ):
                update_scans.append(len(stamps))
            stamps.append(float(rec.timestamp))
            odoms.append(odom)
            after.append(self.updates - 1 - first)
        odo = np.array(odoms, dtype=np.float64).reshape(-1, 3)
        traj = self.best_particle().trajectory[first:]
        poses = _scan_poses(
            traj,
            odo,
            np.array(after, dtype=np.int64),
            np.array(update_scans, dtype=np.int64),
            self.params if interpolate else None,
        )
        return GMappingRun(poses=poses, map=self.occupancy(), timestamps=np.array(stamps))

    # ------------------------------------------------------------------------ internals
    def _initialize(self, beams: _Beams, odom: NDArray[np.float64], t: float) -> None:
        self._poses[:] = odom
        self._register(beams)
        self._add_nodes(root=True)
        self._initialized = True
        self._finish_update(odom, t)
        self.history.append(UpdateInfo(t, float(self.params.particles), False))

    def _update(self, beams: _Beams, odom: NDArray[np.float64], t: float) -> None:
        p = self.params
        cells = self.maps.cells
        ox, oy = self.maps.origin_xy
        inv_sigma = 1.0 / p.sigma
        n_beams = beams.hit.shape[0]
        if n_beams and cells.shape[1]:
            matched, scores = self._match(self._poses, np.arange(p.particles), beams)
            best = int(np.argmax(scores))
            if self.recover_odometry_failures and scores[best] < _RECOVER_BELOW * n_beams:
                self._recover(beams, best, matched, scores)
            if self.degenerate_eigen_ratio > 0.0:
                ratio, weak = scan_constraint(beams.hit)
                if ratio < self.degenerate_eigen_ratio:
                    self.degenerate_updates += 1
                    pairs = zip(matched, self._poses, strict=True)
                    matched = np.array([odometry_along(m, q, weak) for m, q in pairs])
            centers = np.where((scores > p.minimumScore)[:, None], matched, self._poses)
        else:
            centers = self._poses
        motion_mean = compose(self._update_poses, relative(self._update_odom, odom)[None, :])
        var = np.maximum(
            self._motion_var, np.array([_MIN_SIGMA_XY, _MIN_SIGMA_XY, _MIN_SIGMA_TH]) ** 2
        )
        inv_lsigma = 1.0 / p.lsigma
        mean, cov, log_eta = kernels.proposal_all(
            cells,
            ox,
            oy,
            p.delta,
            np.ascontiguousarray(centers),
            beams.hit,
            beams.free,
            p.kernelSize,
            inv_sigma,
            inv_lsigma,
            _NULL_LIKELIHOOD * inv_lsigma,
            self._offsets,
            np.ascontiguousarray(motion_mean),
            1.0 / var,
        )
        self._poses = _draw_gaussian(mean, cov, self._rng)
        self._log_w += log_eta
        self._w_sum += log_eta
        neff = self.neff()
        resample = neff < p.resampleThreshold * p.particles
        if resample:
            self._resample()
        self._register(beams)
        self._add_nodes(root=False)
        self._finish_update(odom, t)
        self.history.append(UpdateInfo(t, neff, bool(resample)))

    def _resample(self) -> None:
        n = self.params.particles
        w = self.weights()
        cdf = np.cumsum(w)
        cdf[-1] = 1.0
        positions = (self._rng.random() + np.arange(n)) / n
        drawn = np.minimum(np.searchsorted(cdf, positions, side="right"), n - 1)
        counts = np.bincount(drawn, minlength=n).astype(np.int64)
        source = self.maps.resample(counts)
        self._poses = self._poses[source]
        self._w_sum = self._w_sum[source]
        self._node = self._node[source]
        self._log_w = np.zeros(n)
        self.resamples += 1

    def _register(self, beams: _Beams) -> None:
        if beams.ends.shape[0] == 0:
            return
        poses = self._poses
        pts = np.concatenate([beams.origin[None, :], beams.ends], axis=0)
        c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
        wx = poses[:, 0:1] + c[:, None] * pts[None, :, 0] - s[:, None] * pts[None, :, 1]
        wy = poses[:, 1:2] + s[:, None] * pts[None, :, 0] + c[:, None] * pts[None, :, 1]
        pad = 2.0 * self.params.delta
        self.maps.ensure(
            float(wx.min()) - pad,
            float(wy.min()) - pad,
            float(wx.max()) + pad,
            float(wy.max()) + pad,
        )
        ox, oy = self.maps.origin_xy
        kernels.register_all(
            self.maps.cells,
            ox,
            oy,
            self.params.delta,
            self._poses,
            beams.origin,
            beams.ends,
            beams.is_hit,
        )

    def _add_nodes(self, *, root: bool) -> None:
        n = self.params.particles
        need = self._tree_size + (1 if root else n)
        if need > self._tree_pose.shape[0]:
            cap = max(need, 2 * self._tree_pose.shape[0])
            pose = np.zeros((cap, 3))
            parent = np.full(cap, -1, dtype=np.int64)
            pose[: self._tree_size] = self._tree_pose[: self._tree_size]
            parent[: self._tree_size] = self._tree_parent[: self._tree_size]
            self._tree_pose, self._tree_parent = pose, parent
        k = self._tree_size
        if root:
            self._tree_pose[k] = self._poses[0]
            self._tree_parent[k] = -1
            self._node[:] = k
        else:
            self._tree_pose[k : k + n] = self._poses
            self._tree_parent[k : k + n] = self._node
            self._node = np.arange(k, k + n, dtype=np.int64)
        self._tree_size = need

    def _finish_update(self, odom: NDArray[np.float64], t: float) -> None:
        self._last_odom = odom
        self._update_odom = odom
        self._update_poses = self._poses.copy()
        self._update_time = t
        self._linear = 0.0
        self._angular = 0.0
        self._motion_var = np.zeros(3)


def run_log(
    log: Iterable[ScanLike],
    params: GMappingParams | None = None,
    rng: np.random.Generator | int | None = None,
    *,
    interpolate: bool = False,
) -> GMappingRun:
    """Run slam_gmapping over a whole laser log; see :meth:`GMapping.run_log`."""
    return GMapping(params, rng).run_log(log, interpolate=interpolate)


def _draw_gaussian(
    mean: NDArray[np.float64], cov: NDArray[np.float64], rng: np.random.Generator
) -> NDArray[np.float64]:
    """One draw per row from ``N(mean[i], cov[i])`` (covariances may be singular)."""
    vals, vecs = np.linalg.eigh(cov)
    root = vecs * np.sqrt(np.clip(vals, 0.0, None))[:, None, :]
    z = rng.standard_normal(mean.shape)
    out = mean + np.einsum("pij,pj->pi", root, z)
    out[:, 2] = wrap(out[:, 2])
    return out


def _odom_array(odom_pose: ArrayLike | SE2) -> NDArray[np.float64]:
    if isinstance(odom_pose, SE2):
        arr = odom_pose.as_array()
    else:
        arr = np.asarray(odom_pose, dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise GMappingInputError(f"odom_pose must be 3 finite numbers (x, y, theta), got {arr}")
    return arr
