"""amcl's particle filter (``pf.c``): the sample set, its weights and averages, KLD
resampling with random-particle recovery, clustering and convergence.

The sensor weighting itself is a kernel of :mod:`.kernels` called by
:class:`~roverlab.localization.amcl.amcl.Amcl`; this class owns what happens before and
after it (normalisation, ``w_slow`` / ``w_fast``, the effective sample size).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.localization.amcl.clusters import cluster_stats, max_spread
from roverlab.localization.amcl.errors import AmclInputError, AmclParamsError
from roverlab.localization.amcl.field import AmclMap
from roverlab.localization.amcl.kernels import kld_resample

__all__ = ["Clusters", "ParticleFilter", "kld_limits"]

FloatArray = NDArray[np.float64]

#: A filter has converged when every particle lies within this distance (m, along x and
#: along y) of the particles' mean (amcl's ``dist_threshold``).
CONVERGED_DISTANCE_M = 0.5


def _average(current: float, sample: float, alpha: float, count: int) -> float:
    """One step of a bias-corrected exponential average (``alpha`` 0: frozen at the first
    sample, as amcl with a zero rate)."""
    if current == 0.0 or count <= 1:
        return sample
    if alpha <= 0.0:
        return current
    rate = max(alpha, 1.0 / count)
    return current + rate * (sample - current)


def kld_limits(
    max_particles: int, min_particles: int, kld_err: float, kld_z: float
) -> NDArray[np.int64]:
    """amcl's ``pf_resample_limit`` for ``k = 0 .. max_particles`` occupied bins.

    ``n = ceil((k - 1) / (2 err) * (1 - 2 / (9 (k - 1)) + sqrt(2 / (9 (k - 1))) z)^3)``
    (Fox 2003), clipped to ``[min_particles, max_particles]``; ``k <= 1`` gives
    ``max_particles``, as amcl.
    """
    k = np.arange(max_particles + 1, dtype=np.float64)
    out = np.full(max_particles + 1, max_particles, dtype=np.int64)
    km1 = k[2:] - 1.0
    b = 2.0 / (9.0 * km1)
    x = 1.0 - b + np.sqrt(b) * kld_z
    n = np.ceil(km1 / (2.0 * kld_err) * x * x * x)
    out[2:] = np.clip(n, min_particles, max_particles).astype(np.int64)
    return out


@dataclass(frozen=True, eq=False)
class Clusters:
    """The sample set's clusters (amcl's hypotheses) and overall statistics.

    Attributes:
        weights: ``(C,)`` each cluster's total weight.
        means: ``(C, 3)`` each cluster's mean pose.
        covariances: ``(C, 3, 3)`` each cluster's covariance (x, y block and yaw).
        counts: ``(C,)`` particles per cluster.
        labels: ``(N,)`` the cluster of each particle.
        mean: ``(3,)`` the whole set's mean.
        covariance: ``(3, 3)`` the whole set's covariance (what amcl publishes).
    """

    weights: FloatArray
    means: FloatArray
    covariances: FloatArray
    counts: NDArray[np.int64]
    labels: NDArray[np.int64]
    mean: FloatArray
    covariance: FloatArray

    def best(self) -> int:
        """Index of the heaviest cluster (the first of equals)."""
        return int(np.argmax(self.weights))


class ParticleFilter:
    """amcl's sample set with KLD-adaptive resampling and alpha_slow/alpha_fast recovery.

    Args:
        free_space: the map whose free cells random particles are drawn from.
        min_particles: KLD sampling's floor.
        max_particles: its ceiling, and the count after (re)initialisation.
        kld_err: ``kld_err``.
        kld_z: ``kld_z``.
        alpha_slow: ``recovery_alpha_slow``.
        alpha_fast: ``recovery_alpha_fast``.
        selective_resampling: resample only when the effective sample size is below half
            the particles.
        rng: every random draw.

    Attributes:
        w_slow: the slow running average of the measurement likelihood.
        w_fast: the fast one.
        n_effective: the effective sample size after the last measurement update.
        converged: every particle is within 0.5 m of the mean (updated at resampling).
        injected: random particles added by the last resampling.

    Raises:
        AmclParamsError: bad particle counts or KLD values.
    """

    def __init__(
        self,
        *,
        free_space: AmclMap,
        min_particles: int,
        max_particles: int,
        kld_err: float,
        kld_z: float,
        alpha_slow: float,
        alpha_fast: float,
        selective_resampling: bool,
        rng: np.random.Generator,
    ) -> None:
        if not 1 <= min_particles <= max_particles:
            raise AmclParamsError(
                f"need 1 <= min_particles <= max_particles, got {min_particles}, {max_particles}"
            )
        if not (0.0 < kld_err < 1.0 and kld_z > 0.0):
            raise AmclParamsError(f"bad KLD parameters: kld_err {kld_err}, kld_z {kld_z}")
        self.map = free_space
        self.min_particles = int(min_particles)
        self.max_particles = int(max_particles)
        self.alpha_slow = float(alpha_slow)
        self.alpha_fast = float(alpha_fast)
        self.selective_resampling = bool(selective_resampling)
        self.rng = rng
        self._limits = kld_limits(self.max_particles, self.min_particles, kld_err, kld_z)
        size = 1 << max(4, int(2 * self.max_particles).bit_length())
        self._hash = np.empty(size, dtype=np.int64)
        self._out = np.empty((self.max_particles, 3))
        self.poses: FloatArray = np.zeros((1, 3))
        self.weights: FloatArray = np.ones(1)
        self.w_slow = 0.0
        self.w_fast = 0.0
        self.n_effective = 1.0
        self.converged = False
        self.injected = 0
        self._samples = 0
        self._clusters: Clusters | None = None
        self.init_uniform()

    # ------------------------------------------------------------------ initialisation
    def _reset(self, poses: FloatArray) -> None:
        self.poses = np.ascontiguousarray(poses, dtype=np.float64)
        n = self.poses.shape[0]
        self.weights = np.full(n, 1.0 / n)
        self.w_slow = self.w_fast = 0.0
        self._samples = 0
        self.n_effective = float(n)
        self.converged = False
        self.injected = 0
        self._clusters = None

    def init_gaussian(self, mean: ArrayLike, covariance: ArrayLike) -> None:
        """``max_particles`` particles drawn from a Gaussian (amcl's ``pf_init``).

        Args:
            mean: ``(x, y, yaw)``.
            covariance: ``(3, 3)`` (x, y, yaw), symmetric positive semi-definite.

        Raises:
            AmclInputError: a non-finite mean or a covariance that is not a finite
                symmetric positive semi-definite 3 x 3 matrix.
        """
        mu = np.asarray(mean, dtype=np.float64).reshape(-1)
        cov = np.asarray(covariance, dtype=np.float64)
        if mu.shape != (3,) or not np.isfinite(mu).all():
            raise AmclInputError(f"initial pose must be three finite numbers, got {mu.tolist()}")
        if cov.shape != (3, 3) or not np.isfinite(cov).all():
            raise AmclInputError("initial covariance must be a finite 3 x 3 matrix")
        if not np.allclose(cov, cov.T, atol=1e-12):
            raise AmclInputError("initial covariance must be symmetric")
        values, vectors = np.linalg.eigh(cov)
        if values.min() < -1e-9 * max(1.0, float(np.abs(values).max())):
            raise AmclInputError(
                f"initial covariance must be positive semi-definite (eigenvalues "
                f"{np.round(values, 6).tolist()})"
            )
        scale = np.sqrt(np.clip(values, 0.0, None))
        z = self.rng.standard_normal((self.max_particles, 3))
        poses = mu + (z * scale) @ vectors.T
        poses[:, 2] = (poses[:, 2] + np.pi) % (2.0 * np.pi) - np.pi
        self._reset(poses)

    def init_uniform(self) -> None:
        """``max_particles`` particles uniform over the map's free cells, headings uniform
        (amcl's ``pf_init_model`` with its uniform pose generator: global localization)."""
        self._reset(self.random_poses(self.max_particles))

    def random_poses(self, count: int) -> FloatArray:
        """``(count, 3)`` poses uniform over the free cells' area, headings uniform."""
        free = self.map.free_cells
        res = self.map.resolution_m
        ox, oy = self.map.origin_xy
        pick = free[self.rng.integers(0, free.shape[0], size=count)]
        jitter = self.rng.random((count, 3))
        out = np.empty((count, 3))
        out[:, 0] = ox + (pick[:, 1] + jitter[:, 0]) * res
        out[:, 1] = oy + (pick[:, 0] + jitter[:, 1]) * res
        out[:, 2] = jitter[:, 2] * 2.0 * math.pi - math.pi
        return out

    @property
    def count(self) -> int:
        """Particles in the set."""
        return int(self.poses.shape[0])

    # ------------------------------------------------------------------ measurement
    def normalise(self, total: float, *, log_scale: float = 0.0, beams: int = 0) -> None:
        """After a sensor kernel multiplied the weights (their sum is ``total``):
        normalise, update the effective sample size and the likelihood averages.

        The averages follow Probabilistic Robotics' Augmented MCL over the mean measurement
        likelihood ``sum(w_before * p) = total * exp(log_scale)`` (``w_before`` summing to
        one; amcl divides it by the particle count as well, which makes it jump whenever
        KLD sampling changes the count). With ``beams`` > 0 (a model whose ``p`` is a
        product over the beams) they average its ``beams``-th root, the geometric mean
        ``pz`` per beam: a product swings by orders of magnitude from scan to scan with
        what the laser happens to see, so that a short average of it falls below a long
        one (and random particles are injected) while the filter is right. They are
        bias-corrected exponential averages: the plain mean of the samples so far until
        there are ``1 / alpha`` of them (amcl starts them at the first sample, so with
        ``alpha_slow`` 0.001 ``w_slow`` remembers the start-up for many minutes). A zero or
        non-finite total makes the weights uniform and leaves the averages alone.
        """
        self._clusters = None
        n = self.count
        if not (total > 0.0 and math.isfinite(total)):
            self.weights[:] = 1.0 / n
            self.n_effective = float(n)
            return
        if beams > 0:
            w_avg = math.exp((math.log(total) + log_scale) / beams)
        else:
            w_avg = total * math.exp(log_scale)
        self.weights /= total
        self.n_effective = 1.0 / float(np.dot(self.weights, self.weights))
        self._samples += 1
        self.w_slow = _average(self.w_slow, w_avg, self.alpha_slow, self._samples)
        self.w_fast = _average(self.w_fast, w_avg, self.alpha_fast, self._samples)

    # ------------------------------------------------------------------ resampling
    def resample(self) -> None:
        """amcl's ``pf_update_resample``: KLD-adaptive resampling, each draw replaced by a
        random particle with probability ``max(0, 1 - w_fast / w_slow)``; with
        ``selective_resampling`` nothing is drawn while the effective sample size is at
        least half the particles.

        amcl resets both averages after injecting, so that while the robot stays lost
        they restart at the lost level and injection stops after one burst; here they
        keep running, and injection goes on (at most ``1 - p_random / w_slow`` of the
        draws) until the particles explain the scans as well as ``w_slow`` remembers.
        """
        if self.selective_resampling and self.n_effective > 0.5 * self.count:
            self._clusters = None
            self._update_converged()
            return
        w_diff = 0.0
        if self.w_slow > 0.0:
            w_diff = max(0.0, 1.0 - self.w_fast / self.w_slow)
        ox, oy = self.map.origin_xy
        n, self.injected = kld_resample(
            self.poses,
            self.weights,
            self.rng,
            w_diff,
            self.map.free_cells,
            self.map.resolution_m,
            ox,
            oy,
            self._limits,
            self._out,
            self._hash,
        )
        self.poses = self._out[:n].copy()
        self.weights = np.full(n, 1.0 / n)
        self._clusters = None
        self._update_converged()

    def _update_converged(self) -> None:
        self.converged = bool(max_spread(self.poses) <= CONVERGED_DISTANCE_M)

    # ------------------------------------------------------------------ statistics
    def clusters(self) -> Clusters:
        """The clusters of the current set (computed once per set of weights)."""
        if self._clusters is None:
            labels, cw, means, covs, counts, mean, cov = cluster_stats(self.poses, self.weights)
            self._clusters = Clusters(cw, means, covs, counts, labels, mean, cov)
        return self._clusters
