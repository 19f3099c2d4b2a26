"""TEB's solver: g2o's Levenberg-Marquardt (``OptimizationAlgorithmLevenberg``) on the
band's sparse normal equations, solved by a banded Cholesky factorisation.

teb_local_planner hands its hyper-graph to g2o: per iteration the edges are linearised,
``H = J^T W J`` and ``b = -J^T W e`` are assembled, ``(H + lambda I) dx = b`` is solved by a
sparse Cholesky factorisation (CSparse / CHOLMOD) and the step is kept when the cost
drops, with g2o's lambda schedule (start ``1e-5 * max(diag H)``; after a good step times
``max(1/3, min(2/3, 1 - (2 rho - 1)^3))``, after a bad one times ``ni``, ``ni`` doubling;
at most 10 tries per iteration). The band is a chain: with the unknowns ordered along it
(``dt_0, pose_1, dt_1, pose_2, ...``) every edge touches a window of at most 11 of them,
so ``H`` is banded and its factorisation costs ``O(n * 11^2)`` — linear in the band's
length, as g2o's sparse solver, where a dense solver grows with the cube of it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["band_order", "levenberg_marquardt"]

_jit = numba.njit(cache=True, nogil=True)
F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: ``evaluate(x, want_jacobian) -> (residuals, jacobian_csr_data)``
Evaluate = Callable[[F64, bool], tuple[F64, F64]]
_TAU = 1e-5  # g2o's _tau
_GOOD_LOWER, _GOOD_UPPER = 1.0 / 3.0, 2.0 / 3.0
_MAX_TRIALS = 10  # g2o's maxTrialsAfterFailure


def band_order(n_poses: int) -> NDArray[np.int64]:
    """Position in the banded order of each unknown (free poses 1..n-2 as x, y, theta,
    then time differences 0..n-2): ``dt_j -> 4 j``, ``pose_i[k] -> 4 (i - 1) + 1 + k``."""
    free = n_poses - 2
    pose = (4 * np.arange(free)[:, None] + 1 + np.arange(3)[None, :]).ravel()
    return np.concatenate([pose, 4 * np.arange(n_poses - 1)]).astype(np.int64)


@_jit
def _bandwidth(indices: I64, indptr: I64, perm: I64) -> int:
    bw = 0
    for row in range(indptr.shape[0] - 1):
        lo = 1 << 60
        hi = -1
        for k in range(indptr[row], indptr[row + 1]):
            p = perm[indices[k]]
            lo = min(lo, p)
            hi = max(hi, p)
        if hi >= 0:
            bw = max(bw, hi - lo)
    return bw


@_jit
def _normal_equations(
    jdata: NDArray[np.float64],
    indices: NDArray[np.int64],
    indptr: NDArray[np.int64],
    r: NDArray[np.float64],
    perm: NDArray[np.int64],
    hb: NDArray[np.float64],
    b: NDArray[np.float64],
) -> None:
    """``H = J^T J`` into lower band storage ``hb[i - j, j] = H[i, j]`` (banded order) and
    ``b = -J^T r`` (the residuals carry the square roots of the weights)."""
    hb[:] = 0.0
    b[:] = 0.0
    for row in range(indptr.shape[0] - 1):
        k0 = indptr[row]
        k1 = indptr[row + 1]
        for k in range(k0, k1):
            a = perm[indices[k]]
            va = jdata[k]
            b[a] -= va * r[row]
            for m in range(k0, k1):
                c = perm[indices[m]]
                if c >= a:
                    hb[c - a, a] += va * jdata[m]


@_jit
def _band_solve(hb: F64, lam: float, b: F64, x: F64) -> bool:
    """Solve ``(H + lam I) x = b`` by Cholesky on the band; False if not positive
    definite."""
    bw = hb.shape[0] - 1
    n = hb.shape[1]
    lo = hb.copy()
    for j in range(n):
        lo[0, j] += lam
    for j in range(n):
        s = lo[0, j]
        for k in range(max(0, j - bw), j):
            v = lo[j - k, k]
            s -= v * v
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        lo[0, j] = d
        for i in range(j + 1, min(n, j + bw + 1)):
            s = lo[i - j, j]
            for k in range(max(0, i - bw), j):
                s -= lo[i - k, k] * lo[j - k, k]
            lo[i - j, j] = s / d
    # L y = b, then L^T x = y
    for i in range(n):
        s = b[i]
        for k in range(max(0, i - bw), i):
            s -= lo[i - k, k] * x[k]
        x[i] = s / lo[0, i]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for k in range(i + 1, min(n, i + bw + 1)):
            s -= lo[k - i, i] * x[k]
        x[i] = s / lo[0, i]
    return True


def levenberg_marquardt(
    x0: NDArray[np.float64],
    evaluate: Evaluate,
    indices: NDArray[np.int64],
    indptr: NDArray[np.int64],
    perm: NDArray[np.int64],
    iterations: int,
) -> NDArray[np.float64]:
    """g2o's ``optimize(iterations)`` with ``OptimizationAlgorithmLevenberg`` from ``x0``.

    Args:
        x0: the unknowns (original order).
        evaluate: ``evaluate(x, want_jacobian) -> (r, jdata)``: weighted residuals and, when
            asked, the Jacobian's CSR data (structure ``indices``, ``indptr``).
        perm: each unknown's position in the banded order (:func:`band_order`).
        iterations: g2o iterations (a linearisation each).

    Returns:
        The unknowns after the last accepted step.
    """
    n = x0.shape[0]
    bw = _bandwidth(indices, indptr, perm)
    hb = np.empty((bw + 1, n))
    b = np.empty(n)
    dxp = np.empty(n)
    x = x0.copy()
    r, jdata = evaluate(x, True)
    chi = float(r @ r)
    lam = 0.0
    ni = 2.0
    for it in range(iterations):
        if it > 0:
            r, jdata = evaluate(x, True)
        _normal_equations(jdata, indices, indptr, r, perm, hb, b)
        if it == 0:
            lam = _TAU * float(np.max(np.abs(hb[0]))) if n else 0.0
            ni = 2.0
        rho = 0.0
        trials = 0
        while True:
            ok = _band_solve(hb, lam, b, dxp)
            trial_chi = math.inf
            if ok:
                trial = x + dxp[perm]
                rt, _ = evaluate(trial, False)
                trial_chi = float(rt @ rt)
                if not math.isfinite(trial_chi):
                    trial_chi = math.inf
            scale = float(dxp @ (lam * dxp + b)) + 1e-3 if ok else 1.0
            rho = (chi - trial_chi) / scale
            if ok and rho > 0 and math.isfinite(trial_chi):
                alpha = min(1.0 - (2.0 * rho - 1.0) ** 3, _GOOD_UPPER)
                lam *= max(_GOOD_LOWER, alpha)
                ni = 2.0
                chi = trial_chi
                x = trial
            else:
                lam *= ni
                ni *= 2.0
                if not math.isfinite(lam):
                    break
            trials += 1
            if not (rho < 0 and trials < _MAX_TRIALS):
                break
        if trials == _MAX_TRIALS or rho == 0 or not math.isfinite(lam):
            break
    return x
