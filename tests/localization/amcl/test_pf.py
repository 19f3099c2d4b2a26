"""amcl's particle filter: KLD sample counts, low-variance resampling, recovery injection,
clusters and convergence, seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.localization.amcl import (
    AmclInputError,
    AmclParamsError,
    ParticleFilter,
    kld_limits,
)
from tests.localization.amcl.helpers import room_map


def _pf(seed: int = 0, **kw: float) -> ParticleFilter:
    args: dict[str, object] = {
        "min_particles": 100, "max_particles": 5000, "kld_err": 0.01, "kld_z": 0.99,
        "alpha_slow": 0.0, "alpha_fast": 0.0, "selective_resampling": False,
    }  # fmt: skip
    args.update(kw)
    return ParticleFilter(free_space=room_map(), rng=np.random.default_rng(seed), **args)  # type: ignore[arg-type]


def test_kld_limits_follow_fox_and_amcls_rules() -> None:
    lim = kld_limits(5000, 100, 0.01, 0.99)
    assert lim[0] == lim[1] == 5000  # amcl: one bin or none -> max_particles
    for k in (2, 3, 10, 50, 200):
        b = 2.0 / (9.0 * (k - 1))
        n = math.ceil((k - 1) / 0.02 * (1.0 - b + math.sqrt(b) * 0.99) ** 3)
        assert lim[k] == min(max(n, 100), 5000), k
    assert lim[2] == 100 and lim[3] == 182
    assert lim[5000] == 5000


def test_a_tight_cloud_keeps_few_particles_a_wide_one_many() -> None:
    pf = _pf()
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([1e-4, 1e-4, 1e-4]))  # well inside one bin
    assert pf.count == 5000
    pf.resample()
    assert pf.count == 5000  # amcl: a single occupied bin keeps max_particles
    # astride a bin edge (x = 2.5 m, bins 0.5 m): two bins, KLD's 100 for k = 2, and amcl
    # draws until the count exceeds the limit: 101
    two = _pf()
    two.init_gaussian((2.5, 2.1, 0.3), np.diag([1e-4, 1e-8, 1e-8]))
    two.resample()
    assert two.count == 101
    wide = _pf()
    wide.resample()  # uniform over the room: thousands of bins
    assert wide.count == 5000
    mid = _pf()
    mid.init_gaussian((2.6, 2.1, 0.3), np.diag([0.01, 0.01, 0.005]))
    mid.resample()
    assert 300 < mid.count < 5000


def test_resampling_follows_the_weights_with_low_variance() -> None:
    pf = _pf(min_particles=5000)
    poses = np.zeros((4, 3))
    poses[:, 0] = [1.0, 2.0, 3.0, 4.0]  # four bins
    pf.poses = poses
    pf.weights = np.array([0.1, 0.2, 0.3, 0.4])
    pf.resample()
    assert pf.count == 5000
    counts = [int((np.abs(pf.poses[:, 0] - x) < 1e-9).sum()) for x in (1, 2, 3, 4)]
    # systematic: every count within one of weight * M (multinomial would spread by ~30)
    assert all(abs(c - w * 5000) <= 1 for c, w in zip(counts, (0.1, 0.2, 0.3, 0.4), strict=True))
    assert pf.weights == pytest.approx(np.full(5000, 1 / 5000))


def test_recovery_injects_random_particles_when_the_fast_average_drops() -> None:
    pf = _pf(alpha_slow=0.001, alpha_fast=0.1)
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([1e-4, 1e-4, 1e-4]))
    for _ in range(100):  # the scans fit: likelihood 20
        pf.weights *= 20.0
        pf.normalise(float(pf.weights.sum()))
    assert pf.w_slow == pytest.approx(20.0) and pf.w_fast == pytest.approx(20.0)
    pf.resample()
    assert pf.injected == 0
    for _ in range(10):  # kidnapped: likelihood 5
        pf.weights *= 5.0
        pf.normalise(float(pf.weights.sum()))
    w_diff = 1.0 - pf.w_fast / pf.w_slow
    assert w_diff > 0.3
    pf.resample()
    assert pf.injected > 0
    far = np.hypot(pf.poses[:, 0] - 2.6, pf.poses[:, 1] - 2.1) > 0.5
    assert far.sum() == pytest.approx(pf.injected, abs=pf.injected * 0.05 + 3)
    assert far.mean() == pytest.approx(w_diff, abs=0.05)
    # the averages keep running (amcl resets them): injection goes on while the fit is poor
    assert pf.w_slow > 0 and pf.w_fast < pf.w_slow


def test_product_likelihoods_are_averaged_per_beam() -> None:
    """A product over 30 beams swings by orders of magnitude with what the laser sees; the
    averages take its 30th root (the geometric mean pz per beam), given in log form."""
    pf = _pf(alpha_slow=0.001, alpha_fast=0.1)
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([1e-4, 1e-4, 1e-4]))
    rng = np.random.default_rng(1)
    for _ in range(200):  # well localised: log p per beam about log 0.8, +-20% per scan
        log_p = 30 * math.log(0.8 * (1.0 + 0.2 * rng.uniform(-1, 1)))
        pf.normalise(float(pf.weights.sum()), log_scale=log_p, beams=30)
    assert pf.w_slow == pytest.approx(0.8, rel=0.05)
    assert 1.0 - pf.w_fast / pf.w_slow < 0.15  # little injection while tracking
    for _ in range(10):  # kidnapped: pz per beam 0.1
        pf.normalise(float(pf.weights.sum()), log_scale=30 * math.log(0.1), beams=30)
    assert 1.0 - pf.w_fast / pf.w_slow > 0.5


def test_zero_rates_never_inject() -> None:
    pf = _pf()
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([1e-3, 1e-3, 1e-3]))
    for like in (20.0, 1.0, 1.0, 1.0):
        pf.weights *= like
        pf.normalise(float(pf.weights.sum()))
    pf.resample()
    assert pf.injected == 0


def test_selective_resampling_waits_for_a_low_effective_sample_size() -> None:
    pf = _pf(selective_resampling=True)
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([0.01, 0.01, 0.01]))
    before = pf.poses.copy()
    pf.normalise(1.0)  # uniform weights: n_effective = N
    pf.resample()
    assert np.array_equal(pf.poses, before)
    pf.weights[:10] = 1.0
    pf.weights[10:] = 1e-9
    pf.normalise(float(pf.weights.sum()))
    assert pf.n_effective < 20
    pf.resample()
    assert not np.array_equal(pf.poses[: len(before)], before[: pf.count])


def test_clusters_and_convergence() -> None:
    pf = _pf()
    rng = np.random.default_rng(4)
    a = np.column_stack([1.0 + rng.normal(0, 0.05, 300), 1.0 + rng.normal(0, 0.05, 300),
                         np.full(300, 3.1)])  # fmt: skip
    a[:150, 2] = -3.12  # across the +-pi seam: still one cluster
    b = np.column_stack([4.0 + rng.normal(0, 0.05, 100), 3.0 + rng.normal(0, 0.05, 100),
                         np.full(100, 0.5)])  # fmt: skip
    pf.poses = np.vstack([a, b])
    pf.weights = np.full(400, 1 / 400)
    c = pf.clusters()
    assert len(c.weights) == 2
    k = c.best()
    assert c.weights[k] == pytest.approx(0.75) and c.counts[k] == 300
    assert c.means[k][:2] == pytest.approx(a[:, :2].mean(axis=0))
    assert abs(math.remainder(c.means[k][2] - math.pi, 2 * math.pi)) < 0.03
    assert c.covariances[k][0, 0] == pytest.approx(a[:, 0].var(), rel=1e-6)
    # the whole set's covariance (what amcl publishes)
    allx = pf.poses[:, 0]
    assert c.covariance[0, 0] == pytest.approx(allx.var(), rel=1e-6)
    pf.resample()
    assert not pf.converged  # two groups 3 m apart
    pf.init_gaussian((2.6, 2.1, 0.3), np.diag([1e-3, 1e-3, 1e-3]))
    pf.resample()
    assert pf.converged


def _root(parent: list[int], i: int) -> int:
    while parent[i] != i:
        i = parent[i]
    return i


def test_clusters_join_touching_bins_as_a_brute_force_reference() -> None:
    rng = np.random.default_rng(7)
    for n, side in ((80, 12.0), (2000, 30.0)):
        poses = np.column_stack([rng.uniform(0, side, n), rng.uniform(0, side, n),
                                 rng.uniform(-math.pi, math.pi, n)])  # fmt: skip
        pf = _pf()
        pf.poses = poses
        pf.weights = np.full(n, 1 / n)
        labels = pf.clusters().labels
        ix = np.floor(poses[:, 0] / 0.5).astype(int)
        iy = np.floor(poses[:, 1] / 0.5).astype(int)
        ia = np.floor((poses[:, 2] + math.pi) / math.radians(10.0)).astype(int) % 36
        parent = list(range(n))

        da = np.abs(ia[:, None] - ia[None, :])
        touch = ((np.abs(ix[:, None] - ix[None, :]) <= 1) & (np.abs(iy[:, None] - iy[None, :]) <= 1)
                 & (np.minimum(da, 36 - da) <= 1))  # fmt: skip
        for i, j in zip(*np.nonzero(touch), strict=True):
            parent[_root(parent, int(i))] = _root(parent, int(j))
        ref = np.array([_root(parent, i) for i in range(n)])
        same = ref[:, None] == ref[None, :]
        assert np.array_equal(same, labels[:, None] == labels[None, :])
        assert len(set(labels.tolist())) == len(set(ref.tolist())) > 5


def test_seeded_filters_repeat_and_different_seeds_differ() -> None:
    def run(seed: int) -> np.ndarray:
        pf = _pf(seed, alpha_slow=0.001, alpha_fast=0.1)
        pf.init_gaussian((2.6, 2.1, 0.3), np.diag([0.1, 0.1, 0.1]))
        for like in (3.0, 1.0):
            pf.weights *= like + pf.poses[:, 0]
            pf.normalise(float(pf.weights.sum()))
            pf.resample()
        return pf.poses

    assert np.array_equal(run(1), run(1))
    assert not np.array_equal(run(1), run(2))


def test_bad_initial_covariance_and_counts() -> None:
    pf = _pf()
    with pytest.raises(AmclInputError, match="positive semi-definite"):
        pf.init_gaussian((0, 0, 0), np.diag([1.0, -1.0, 1.0]))
    with pytest.raises(AmclInputError, match="symmetric"):
        pf.init_gaussian((0, 0, 0), [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]])
    with pytest.raises(AmclInputError, match="three finite numbers"):
        pf.init_gaussian((0, math.nan, 0), np.eye(3))
    with pytest.raises(AmclParamsError):
        _pf(min_particles=10, max_particles=5)


def test_uniform_particles_lie_on_free_cells() -> None:
    pf = _pf()
    m = room_map()
    cells = m.cell_of(pf.poses[:, :2])
    assert (m.data[cells[:, 0], cells[:, 1]] == 0).all()
    assert pf.poses[:, 2].min() >= -math.pi and pf.poses[:, 2].max() < math.pi
