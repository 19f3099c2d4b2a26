"""amcl's per-scan logic (``amcl_node.cpp``'s ``laserReceived``) as a pure class.

:class:`Amcl` owns the particle filter and decides, scan by scan, what ROS 1 amcl does:

* the first scan after (re)initialisation takes the odometry pose as reference, weights
  the particles and publishes a pose;
* later scans update the filter only when the odometry moved more than ``update_min_d``
  along x or y or turned more than ``update_min_a`` since the last update (or a
  no-motion update was requested): motion model, then sensor model;
* every ``resample_interval``-th update resamples; a pose is published after
  resampling: the mean of the heaviest cluster, with the whole set's covariance, and
  ``map -> odom = pose * odom^-1``.

Scans come as ranges and bearings in the robot's base frame (an upside-down or yawed
laser is already folded into the bearings), with the laser's position on the robot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.localization.amcl.errors import AmclInputError
from roverlab.localization.amcl.field import AmclMap
from roverlab.localization.amcl.kernels import (
    beam_weights,
    likelihood_field_prob_weights,
    likelihood_field_weights,
)
from roverlab.localization.amcl.motion import sample_motion
from roverlab.localization.amcl.params import AmclParams
from roverlab.localization.amcl.pf import Clusters, ParticleFilter

__all__ = ["Amcl", "PoseEstimate", "ScanResult", "select_beams"]

FloatArray = NDArray[np.float64]

#: Laser tables kept per map (one per distinct range limit).
_TABLE_CACHE: Final = 4


@dataclass(frozen=True, slots=True)
class PoseEstimate:
    """amcl's published pose.

    Attributes:
        pose: the robot's pose in the map frame: the heaviest cluster's mean.
        covariance: ``(3, 3)`` covariance of ``(x, y, yaw)``: the whole particle set's, as
            amcl publishes it (the yaw-x/y terms are zero).
        cluster_weight: the heaviest cluster's share of the weight.
        clusters: how many clusters the particles form.
    """

    pose: SE2
    covariance: FloatArray
    cluster_weight: float
    clusters: int


@dataclass(frozen=True, slots=True)
class ScanResult:
    """What one scan did.

    Attributes:
        updated: the filter was updated (motion and sensor model).
        resampled: the particles were resampled.
        estimate: the pose published after this scan, or None (amcl publishes after
            resampling and after the first scan following (re)initialisation).
        map_to_odom: the ``map -> odom`` transform of that pose, or None.
        beams: beams the sensor model used (0 when it was skipped).
        note: why the sensor model was skipped or degraded ("" if it was not).
    """

    updated: bool
    resampled: bool
    estimate: PoseEstimate | None
    map_to_odom: SE2 | None
    beams: int
    note: str = ""


def select_beams(count: int, max_beams: int, model: str) -> NDArray[np.intp]:
    """The beam indices amcl uses out of ``count``: every ``step``-th from the first, with
    ``step = (count - 1) // (max_beams - 1)`` (``likelihood_field``, ``beam``) or
    ``ceil(count / max_beams)`` (``likelihood_field_prob``), at least 1."""
    if count <= 0:
        return np.zeros(0, dtype=np.intp)
    if model == "likelihood_field_prob":
        step = max(1, math.ceil(count / max_beams))
    else:
        step = max(1, (count - 1) // (max_beams - 1))
    return np.arange(0, count, step, dtype=np.intp)


class Amcl:
    """ROS 1 amcl on one map, minus the ROS plumbing.

    Args:
        params: the parameters (:class:`AmclParams`).
        amcl_map: the map (its ``max_dist_m`` should be ``laser_likelihood_max_dist``).
        rng: every random draw of the filter.
        initial_pose: start from this pose with ``initial_covariance`` instead of
            ``initial_pose_x/y/a`` and ``initial_cov_xx/yy/aa``.
        initial_covariance: ``(3, 3)`` covariance of ``initial_pose``.
        global_start: start from particles spread uniformly over the free cells instead.

    Attributes:
        params: the parameters.
        map: the map.
        pf: the particle filter.
        updates: filter updates so far.
        last_estimate: the last published pose, or None.
        map_to_odom: the last ``map -> odom``, or None before the first pose.

    Raises:
        AmclInputError: the initial pose is non-finite or off the map.
    """

    def __init__(
        self,
        params: AmclParams,
        amcl_map: AmclMap,
        *,
        rng: np.random.Generator,
        initial_pose: SE2 | None = None,
        initial_covariance: ArrayLike | None = None,
        global_start: bool = False,
    ) -> None:
        self.params = params
        self.map = amcl_map
        self.pf = ParticleFilter(
            free_space=amcl_map,
            min_particles=params.min_particles,
            max_particles=params.max_particles,
            kld_err=params.kld_err,
            kld_z=params.kld_z,
            alpha_slow=params.recovery_alpha_slow,
            alpha_fast=params.recovery_alpha_fast,
            selective_resampling=params.selective_resampling,
            rng=rng,
        )
        self.updates = 0
        self.last_estimate: PoseEstimate | None = None
        self.map_to_odom: SE2 | None = None
        self._odom_ref: SE2 | None = None
        self._force_update = False
        self._resample_count = 0
        self._tables: dict[tuple[str, float], tuple[FloatArray, float]] = {}
        self._scratch = np.empty(0)
        if global_start:
            self.global_localization()
            return
        if initial_pose is None:
            initial_pose = SE2(params.initial_pose_x, params.initial_pose_y, params.initial_pose_a)
        if initial_covariance is None:
            initial_covariance = np.diag(
                [params.initial_cov_xx, params.initial_cov_yy, params.initial_cov_aa]
            )
        self.set_initial_pose(initial_pose, initial_covariance)

    # ------------------------------------------------------------------ (re)initialisation
    def set_initial_pose(self, pose: SE2, covariance: ArrayLike) -> None:
        """Re-initialise the particles around ``pose`` (``/initialpose``, amcl's
        ``pf_init``); the next scan then updates the filter and publishes a pose.

        Raises:
            AmclInputError: a non-finite pose, a pose off the map, or a bad covariance.
        """
        x, y, a = float(pose.x), float(pose.y), float(pose.theta)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(a)):
            raise AmclInputError(f"initial pose must be finite, got ({x}, {y}, {a})")
        if not self.map.contains(x, y):
            xmin, ymin, xmax, ymax = self.map.bounds
            raise AmclInputError(
                f"initial pose ({x:.3f}, {y:.3f}) is outside the map "
                f"(x {xmin:.2f} .. {xmax:.2f}, y {ymin:.2f} .. {ymax:.2f})"
            )
        self.pf.init_gaussian((x, y, float(wrap_angle(a))), covariance)
        self._odom_ref = None

    def global_localization(self) -> None:
        """Spread ``max_particles`` uniformly over the free cells (the
        ``global_localization`` service)."""
        self.pf.init_uniform()
        self._odom_ref = None

    def request_nomotion_update(self) -> None:
        """Update the filter on the next scan even if the robot has not moved (the
        ``request_nomotion_update`` service)."""
        self._force_update = True

    # ------------------------------------------------------------------ scans
    def process_scan(
        self,
        *,
        odom_pose: SE2,
        ranges: ArrayLike,
        bearings: ArrayLike,
        laser_xy: tuple[float, float] = (0.0, 0.0),
        range_min: float = 0.0,
        range_max: float = math.inf,
    ) -> ScanResult:
        """One laser scan with the robot's odometry pose at its time.

        Args:
            odom_pose: the base frame's pose in the odometry frame at the scan.
            ranges: ``(N,)`` ranges (m); NaN, inf and out-of-limit readings are allowed.
            bearings: ``(N,)`` each beam's direction in the base frame (rad).
            laser_xy: the laser's position in the base frame (m).
            range_min: the scan's ``range_min`` (m).
            range_max: the scan's ``range_max`` (m).

        Raises:
            AmclInputError: mismatched shapes or a non-finite odometry pose, bearing or
                laser position.
        """
        r = np.asarray(ranges, dtype=np.float64).reshape(-1)
        b = np.asarray(bearings, dtype=np.float64).reshape(-1)
        if r.shape != b.shape:
            raise AmclInputError(f"{r.shape[0]} ranges but {b.shape[0]} bearings")
        if not np.isfinite(b).all():
            raise AmclInputError("beam bearings must be finite")
        pose = (float(odom_pose.x), float(odom_pose.y), float(odom_pose.theta))
        if not all(math.isfinite(v) for v in (*pose, *laser_xy)):
            raise AmclInputError(f"odometry pose must be finite, got {pose}")
        p = self.params
        force_publication = False
        if self._odom_ref is None:
            self._odom_ref = odom_pose
            self._resample_count = 0
            update = True
            force_publication = True
        else:
            ref = self._odom_ref
            delta = (pose[0] - ref.x, pose[1] - ref.y, float(wrap_angle(pose[2] - ref.theta)))
            update = (
                abs(delta[0]) > p.update_min_d
                or abs(delta[1]) > p.update_min_d
                or abs(delta[2]) > p.update_min_a
                or self._force_update
            )
            self._force_update = False
            if update:
                sample_motion(
                    self.pf.poses,
                    model=p.odom_model_type,
                    delta=delta,
                    old_theta=ref.theta,
                    alphas=p.odom_alphas,
                    rng=self.pf.rng,
                )
        resampled = False
        beams = 0
        note = ""
        if update:
            self.updates += 1
            beams, note = self._sensor_update(r, b, laser_xy, range_min, range_max)
            self._odom_ref = odom_pose
            self._resample_count += 1
            if self._resample_count % p.resample_interval == 0:
                self.pf.resample()
                resampled = True
        estimate: PoseEstimate | None = None
        if resampled or force_publication:
            estimate = self._estimate(self.pf.clusters())
            self.last_estimate = estimate
            self.map_to_odom = estimate.pose * ~odom_pose
        return ScanResult(update, resampled, estimate, self.map_to_odom if estimate else None,
                          beams, note)  # fmt: skip

    def pose_at(self, odom_pose: SE2) -> SE2 | None:
        """The robot's map pose for an odometry pose: ``map_to_odom * odom_pose``."""
        if self.map_to_odom is None:
            return None
        return self.map_to_odom * odom_pose

    def _estimate(self, clusters: Clusters) -> PoseEstimate:
        k = clusters.best()
        x, y, a = (float(v) for v in clusters.means[k])
        cov = np.zeros((3, 3))
        cov[:2, :2] = clusters.covariance[:2, :2]
        cov[2, 2] = clusters.covariance[2, 2]
        total = float(clusters.weights.sum())
        share = float(clusters.weights[k]) / total if total > 0.0 else 0.0
        return PoseEstimate(SE2(x, y, a), cov, share, int(clusters.weights.shape[0]))

    # ------------------------------------------------------------------ sensor model
    def _limits(self, range_min: float, range_max: float) -> tuple[float, float]:
        p = self.params
        rmax = min(range_max, p.laser_max_range) if p.laser_max_range > 0.0 else range_max
        rmin = max(range_min, p.laser_min_range) if p.laser_min_range > 0.0 else range_min
        return rmin, rmax

    def _table(self, kind: str, range_max: float) -> tuple[FloatArray, float]:
        key = (kind, range_max)
        hit = self._tables.get(key)
        if hit is not None:
            return hit
        p = self.params
        make = self.map.log_likelihood_table if kind == "log" else self.map.likelihood_table
        table = make(
            z_hit=p.laser_z_hit, z_rand=p.laser_z_rand, sigma_hit=p.laser_sigma_hit,
            range_max=range_max,
        )  # fmt: skip
        if len(self._tables) >= _TABLE_CACHE:
            self._tables.pop(next(iter(self._tables)))
        self._tables[key] = table
        return table

    def _sensor_update(
        self,
        ranges: FloatArray,
        bearings: FloatArray,
        laser_xy: tuple[float, float],
        range_min: float,
        range_max: float,
    ) -> tuple[int, str]:
        """Weight the particles with the laser model; returns (beams used, note)."""
        p = self.params
        rmin, rmax = self._limits(float(range_min), float(range_max))
        if not (math.isfinite(rmax) and rmax > 0.0):
            return 0, f"the scan's range limit {rmax} is not a positive finite number"
        idx = select_beams(ranges.shape[0], p.laser_max_beams, p.laser_model_type)
        r = ranges[idx].copy()
        a = bearings[idx]
        r[r <= rmin] = rmax  # amcl has no minimum range: short readings become max range
        m = self.map
        ox, oy = m.origin_xy
        pf = self.pf
        if p.laser_model_type == "beam":
            ok = ~np.isnan(r)
            if not ok.any():
                return 0, "the scan has no reading that is not NaN: sensor update skipped"
            obs = np.minimum(r[ok], rmax)
            total = beam_weights(
                pf.poses, pf.weights, float(laser_xy[0]), float(laser_xy[1]),
                np.cos(a[ok]), np.sin(a[ok]), obs, rmax, m.blocked, m.resolution_m, ox, oy,
                p.laser_z_hit, p.laser_z_short, p.laser_z_max, p.laser_z_rand,
                p.laser_sigma_hit, p.laser_lambda_short,
            )  # fmt: skip
            pf.normalise(total)
            return int(obs.shape[0]), ""
        ok = np.isfinite(r) & (r < rmax)
        if not ok.any():
            return 0, (
                f"the scan has no finite reading within ({rmin:g}, {rmax:g}) m: "
                "sensor update skipped"
            )
        ex = laser_xy[0] + r[ok] * np.cos(a[ok])
        ey = laser_xy[1] + r[ok] * np.sin(a[ok])
        inv = 1.0 / m.resolution_m
        if p.laser_model_type == "likelihood_field":
            table, off = self._table("cube", rmax)
            total = likelihood_field_weights(pf.poses, pf.weights, ex, ey, table, off, inv, ox, oy)
            pf.normalise(total)
            return int(ex.shape[0]), ""
        log_table, log_off = self._table("log", rmax)
        skip = p.do_beamskip and pf.converged
        scratch = np.empty((0, 0))
        if skip:
            size = pf.count * ex.shape[0]
            if self._scratch.size < size:
                self._scratch = np.empty(size)
            scratch = self._scratch[:size].reshape(pf.count, ex.shape[0])
        total, log_scale, skipped, too_many = likelihood_field_prob_weights(
            pf.poses, pf.weights, ex, ey, log_table, log_off, m.distance, inv, ox, oy, skip,
            p.beam_skip_distance, p.beam_skip_threshold, p.beam_skip_error_threshold, scratch,
        )  # fmt: skip
        used = int(ex.shape[0]) - int(skipped)
        pf.normalise(total, log_scale=log_scale, beams=used)
        if too_many:
            return used, (
                f"over {100.0 * p.beam_skip_error_threshold:.0f}% of the beams disagree with "
                "the map: the filter may have converged to a wrong pose; all beams used"
            )
        return used, ""
