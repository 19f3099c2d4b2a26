"""The compiled sensor models against a direct computation of amcl's formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.localization.amcl.kernels import (
    beam_weights,
    likelihood_field_prob_weights,
    likelihood_field_weights,
)
from roverlab.raycast import cast_grid
from tests.localization.amcl.helpers import BEARINGS, ORIGIN, RES, room_grid, room_map, scan_at

Z_HIT, Z_RAND, SIGMA, RMAX = 0.95, 0.05, 0.2, 10.0


def _endpoints(pose: SE2, ex: np.ndarray, ey: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    return pose.x + c * ex - s * ey, pose.y + s * ex + c * ey


def _pz(m: object, hx: np.ndarray, hy: np.ndarray) -> np.ndarray:
    amap = room_map()
    col = np.floor((hx - ORIGIN[0]) / RES).astype(int)
    row = np.floor((hy - ORIGIN[1]) / RES).astype(int)
    inside = (col >= 0) & (row >= 0) & (col < amap.width) & (row < amap.height)
    d = np.full(hx.shape, amap.max_dist_m)
    d[inside] = amap.distance[row[inside], col[inside]]
    return Z_HIT * np.exp(-(d**2) / (2 * SIGMA**2)) + Z_RAND / RMAX


def _beams(pose: SE2, every: int = 12) -> tuple[np.ndarray, np.ndarray]:
    # a little noise keeps end points off cell boundaries, where rounding picks either cell
    r = scan_at(pose, rng=np.random.default_rng(3), noise=0.004)[::every]
    a = BEARINGS[::every]
    ok = np.isfinite(r)
    return r[ok] * np.cos(a[ok]) + 0.1, r[ok] * np.sin(a[ok])  # laser 0.1 m ahead


def test_likelihood_field_is_one_plus_the_sum_of_cubes() -> None:
    m = room_map()
    table, off = m.likelihood_table(z_hit=Z_HIT, z_rand=Z_RAND, sigma_hit=SIGMA, range_max=RMAX)
    truth = SE2(2.5, 2.0, 0.3)
    ex, ey = _beams(SE2(2.5 + 0.1 * math.cos(0.3), 2.0 + 0.1 * math.sin(0.3), 0.3))
    poses = np.array([[2.5, 2.0, 0.3], [2.6, 2.0, 0.3], [2.5, 2.0, 0.4], [-5.0, 9.0, 0.0]])
    w = np.full(4, 0.25)
    total = likelihood_field_weights(poses, w, ex, ey, table, off, 1 / RES, *ORIGIN)
    for k, (x, y, a) in enumerate(poses):
        hx, hy = _endpoints(SE2(x, y, a), ex, ey)
        assert w[k] == pytest.approx(0.25 * (1.0 + (_pz(m, hx, hy) ** 3).sum()))
    assert total == pytest.approx(w.sum())
    assert w[0] == w.max()  # the true pose explains the scan best
    assert w[3] == pytest.approx(0.25 * (1 + len(ex) * off))  # off the map: capped distance
    assert truth.x == 2.5


def test_likelihood_field_prob_is_the_product_and_beamskip_drops_disagreeing_beams() -> None:
    m = room_map()
    log_t, log_off = m.log_likelihood_table(z_hit=Z_HIT, z_rand=Z_RAND, sigma_hit=SIGMA,
                                            range_max=RMAX)  # fmt: skip
    ex, ey = _beams(SE2(2.6, 2.0, 0.3))
    # a person 0.5 m in front of the laser: the first beam reads short for every particle
    ex = np.concatenate([[0.6], ex])
    ey = np.concatenate([[0.0], ey])
    rng = np.random.default_rng(0)
    poses = np.column_stack([2.5 + rng.normal(0, 0.02, 50), 2.0 + rng.normal(0, 0.02, 50),
                             0.3 + rng.normal(0, 0.01, 50)])  # fmt: skip
    w = np.ones(50)
    args = (log_t, log_off, m.distance, 1 / RES, *ORIGIN)
    _, scale, _, _ = likelihood_field_prob_weights(poses, w, ex, ey, *args, False, 0.5, 0.3,
                                                   0.9, np.empty((0, 0)))  # fmt: skip
    hx, hy = _endpoints(SE2(*poses[0]), ex, ey)
    # the weights come scaled by exp(-max log p): the heaviest particle gets exactly 1
    assert w[0] * math.exp(scale) == pytest.approx(np.prod(_pz(m, hx, hy)))
    assert w.max() == 1.0
    w2 = np.ones(50)
    total, scale2, skipped, too_many = likelihood_field_prob_weights(
        poses, w2, ex, ey, *args, True, 0.2, 0.3, 0.9, np.empty((50, len(ex)))
    )
    assert skipped == 1 and not too_many  # only the person's beam disagrees with the map
    assert w2[0] * math.exp(scale2) == pytest.approx(np.prod(_pz(m, hx[1:], hy[1:])))
    assert total == pytest.approx(w2.sum())
    # most beams disagreeing: the filter may be wrong; amcl then uses them all
    w3 = np.ones(50)
    _, _, skipped3, too_many3 = likelihood_field_prob_weights(
        poses + np.array([1.0, 0.7, 1.0]), w3, ex, ey, *args, True, 0.05, 0.3, 0.2,
        np.empty((50, len(ex))),
    )  # fmt: skip
    assert too_many3 and skipped3 == 0


def test_likelihood_field_prob_does_not_underflow_with_many_beams() -> None:
    """360 beams of a pose 1 m off: each pz is tiny and their product underflows to zero
    (amcl's weights all become 0); in the log domain the better pose still wins."""
    m = room_map()
    log_t, log_off = m.log_likelihood_table(z_hit=Z_HIT, z_rand=Z_RAND, sigma_hit=0.05,
                                            range_max=RMAX)  # fmt: skip
    ex, ey = _beams(SE2(2.6, 2.0, 0.3), every=1)
    ex, ey = np.tile(ex, 4), np.tile(ey, 4)
    poses = np.array([[3.5, 2.8, 0.3], [3.4, 2.8, 0.3]])
    hx, hy = _endpoints(SE2(*poses[0]), ex, ey)
    assert np.prod(_pz(m, hx, hy)) == 0.0  # what a direct product gives
    w = np.full(2, 0.5)
    total, scale, _, _ = likelihood_field_prob_weights(
        poses, w, ex, ey, log_t, log_off, m.distance, 1 / RES, *ORIGIN, False, 0.5, 0.3, 0.9,
        np.empty((0, 0)),
    )  # fmt: skip
    assert total > 0.0 and np.isfinite(scale) and scale < -745.0
    assert w.max() == 0.5 and total == pytest.approx(w.sum())


def test_beam_model_mixture() -> None:
    grid = room_grid()
    amap = room_map()
    pose = SE2(2.513, 2.017, 0.31)  # rays away from cell corners
    a = BEARINGS[::24]
    # noisy readings: z = obs - expected is never a rounding error away from 0, where
    # the short-reading term switches on
    obs = np.minimum(scan_at(pose, rng=np.random.default_rng(5), noise=0.01)[::24], RMAX)
    obs[0] = 0.5  # short reading
    obs[1] = RMAX  # max reading
    poses = np.array([[2.513, 2.017, 0.31], [2.711, 2.133, 0.31]])
    w = np.ones(2)
    z_short, z_max, lam = 0.1, 0.05, 0.1
    beam_weights(poses, w, 0.0, 0.0, np.cos(a), np.sin(a), obs, RMAX, amap.blocked, RES,
                 *ORIGIN, Z_HIT, z_short, z_max, Z_RAND, SIGMA, lam)  # fmt: skip
    for k in range(2):
        x, y, t = poses[k]
        expected = np.minimum(cast_grid(grid != 0, RES, ORIGIN, x, y, a + t, RMAX), RMAX)
        z = obs - expected
        pz = Z_HIT * np.exp(-(z**2) / (2 * SIGMA**2))
        pz += np.where(z < 0, z_short * lam * np.exp(-lam * obs), 0.0)
        pz += np.where(obs == RMAX, z_max, Z_RAND / RMAX)
        assert w[k] == pytest.approx(1.0 + (pz**3).sum())
    assert w[0] > w[1]
