"""TEB's solver: g2o's Levenberg-Marquardt on banded normal equations."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import TebParams, TebPlanner, Velocity2D
from roverlab.navigation.controllers.teb.solver import (
    _band_solve,
    _bandwidth,
    _normal_equations,
    band_order,
    levenberg_marquardt,
)
from tests.navigation.controllers.conftest import TEB
from tests.navigation.controllers.sim import costmaps, field_world


def _csr(dense: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows, cols = np.nonzero(dense)
    indptr = np.searchsorted(rows, np.arange(dense.shape[0] + 1)).astype(np.int64)
    return dense[rows, cols].astype(np.float64), cols.astype(np.int64), indptr


def test_band_order_interleaves_poses_and_time_differences() -> None:
    # 5 poses: free poses 1..3 (9 unknowns), dts 0..3 (4 unknowns)
    assert band_order(5).tolist() == [1, 2, 3, 5, 6, 7, 9, 10, 11, 0, 4, 8, 12]


def test_banded_normal_equations_and_cholesky_match_dense_algebra() -> None:
    rng = np.random.default_rng(4)
    n = 13
    # a chain-like Jacobian: each row touches a window of 4 consecutive unknowns
    jac = np.zeros((40, n))
    for row in range(40):
        start = rng.integers(0, n - 3)
        jac[row, start : start + 4] = rng.normal(size=4)
    r = rng.normal(size=40)
    data, indices, indptr = _csr(jac)
    perm = np.arange(n, dtype=np.int64)
    bw = _bandwidth(indices, indptr, perm)
    assert bw == 3
    hb, b, x = np.empty((bw + 1, n)), np.empty(n), np.empty(n)
    _normal_equations(data, indices, indptr, r, perm, hb, b)
    h = jac.T @ jac
    assert hb[0] == pytest.approx(np.diag(h))
    assert hb[2, :-2] == pytest.approx(np.diag(h, -2))
    assert b == pytest.approx(-jac.T @ r)
    assert _band_solve(hb, 0.5, b, x)
    assert x == pytest.approx(np.linalg.solve(h + 0.5 * np.eye(n), -jac.T @ r))
    # not positive definite: reported, not solved
    assert not _band_solve(-hb, 0.0, b, x)


def test_levenberg_marquardt_solves_a_nonlinear_least_squares_problem() -> None:
    # Rosenbrock as residuals (10 (y - x^2), 1 - x): minimum at (1, 1)
    def fun(v: np.ndarray, want: bool) -> tuple[np.ndarray, np.ndarray]:
        x, y = v
        r = np.array([10.0 * (y - x * x), 1.0 - x])
        jac = np.array([-20.0 * x, 10.0, -1.0])  # CSR data of [[-20x, 10], [-1, 0]]
        return r, jac

    indices = np.array([0, 1, 0], dtype=np.int64)
    indptr = np.array([0, 2, 3], dtype=np.int64)
    x = levenberg_marquardt(np.array([-1.2, 1.0]), fun, indices, indptr, np.arange(2), 100)
    assert x == pytest.approx([1.0, 1.0], abs=1e-6)
    # a few iterations only lower the cost (no step is kept that raises it)
    cost = [float(np.sum(fun(levenberg_marquardt(np.array([-1.2, 1.0]), fun, indices, indptr,
                                                 np.arange(2), k), False)[0] ** 2))
            for k in range(6)]  # fmt: skip
    assert all(b <= a for a, b in itertools.pairwise(cost))


def test_long_bands_cost_time_linear_in_their_length() -> None:
    """A band of hundreds of poses (a long local plan, small dt_ref) is solved in
    milliseconds: the banded factorisation, not a dense one."""
    glob, local = costmaps(field_world(2), local_m=12.0)
    from roverlab.navigation.planners import NavfnPlanner

    plan = NavfnPlanner().plan(SE2(1, 1, 0), SE2(5, 5, 0), glob.costmap)
    local.update_map(1.0, 1.0, 0.0)
    times = {}
    for dt_ref in (0.3, 0.05):
        p = TebParams.from_ros({**TEB, "dt_ref": dt_ref, "dt_hysteresis": dt_ref / 3,
                                "max_global_plan_lookahead_dist": 10.0})[0]  # fmt: skip
        teb = TebPlanner(p, footprint=np.array([[-0.15, -0.1], [-0.15, 0.1], [0.15, 0.1],
                                                 [0.15, -0.1]]))  # fmt: skip
        teb.compute_velocity(SE2(1, 1, 0), Velocity2D(), plan, local.costmap)  # compile
        t0 = time.thread_time()
        teb.compute_velocity(SE2(1, 1, 0), Velocity2D(), plan, local.costmap)
        times[dt_ref] = (time.thread_time() - t0, len(teb.band.poses))
    (_, n_short), (t_long, n_long) = times[0.3], times[0.05]
    assert n_long > 4 * n_short and n_long > 150
    assert t_long < 0.25
