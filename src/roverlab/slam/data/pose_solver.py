"""The pose-graph optimiser: Gauss-Newton / Levenberg-Marquardt on sparse normal equations,
and the chordal and odometry initialisations.

:func:`optimize` minimises :func:`~roverlab.slam.data.posegraph.chi2` on the sparse normal
equations: undamped Gauss-Newton steps under a watchdog (a step may raise chi2 for a while,
as after a big loop closure, but the best poses are kept) and Levenberg-Marquardt with
Nielsen's damping update when Gauss-Newton stops making progress. Jacobians are analytic,
computed for all edges at once with numpy and assembled into a ``scipy.sparse`` matrix,
factorised by QDLDL (sparse LDL^T) in an approximate-minimum-degree order analysed once
per run. The gauge is fixed by holding the first vertex (or the vertices of the file's
``FIX`` lines) at its initial value. From a poor start on a big loopy graph any local
method can stop in a local minimum: :func:`chordal_initialisation` gives a start near the
global optimum by solving first for the orientations (a linear least-squares problem on
``(cos, sin)`` pairs, normalised afterwards) and then, with the orientations fixed, for the
positions (linear again).

Reached on the benchmark graphs of ``shared/data/posegraphs`` from the files' own starts
(reference in brackets): INTEL 215.830 (215.83), M3500 137.913 (137.91), CSAIL 40.555
(40.56), city10000 511.985 (511.99), each in at most 8 iterations. Plain LM from the
INTEL odometry start crawls (chi2 238 after 300 iterations), hence the Gauss-Newton phase.

The graph-SLAM back end uses :func:`optimize`; the ``roverlab slam graph`` command runs it on
a g2o file.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Final, Literal

import numpy as np
import qdldl
import scipy.sparse as sp
from numpy.typing import ArrayLike
from scipy.sparse.csgraph import connected_components

from roverlab.slam.data.errors import PoseGraphError
from roverlab.slam.data.posegraph import (
    FloatArray,
    IndexArray,
    PoseGraph,
    _as_poses,
    _chi2,
    _with_poses,
    _wrap,
    odometry_initialisation,
)

__all__ = [
    "OptimizationReport",
    "chordal_initialisation",
    "optimize",
]


# --------------------------------------------------------------------------------- initialisation


# --------------------------------------------------------------------------------- linear algebra


def _free_index(graph: PoseGraph) -> tuple[IndexArray, int]:
    """Column block of each vertex among the free ones (-1 for fixed) and the free count."""
    free = np.ones(graph.num_vertices, dtype=bool)
    free[graph.fixed] = False
    col = np.full(graph.num_vertices, -1, dtype=np.intp)
    col[free] = np.arange(int(free.sum()), dtype=np.intp)
    return col, int(free.sum())


def _check_connected(graph: PoseGraph) -> None:
    """Raise unless every vertex is tied by edges to a fixed vertex (else H is singular)."""
    v = graph.num_vertices
    adj = sp.coo_matrix((np.ones(graph.num_edges), (graph.edge_from, graph.edge_to)), shape=(v, v))
    _, label = connected_components(adj, directed=False)
    anchored = np.isin(label, label[graph.fixed])
    if not np.all(anchored):
        loose = graph.ids[~anchored]
        shown = ", ".join(str(i) for i in loose[:5].tolist())
        more = f" and {loose.shape[0] - 5} more" if loose.shape[0] > 5 else ""
        raise PoseGraphError(
            f"vertices {shown}{more} are not connected by edges to a fixed vertex: "
            "their poses are undetermined"
        )


def _assemble(
    col: IndexArray,
    n: int,
    fr: IndexArray,
    to: IndexArray,
    a: FloatArray,
    b: FloatArray,
    w: FloatArray,
    e: FloatArray,
) -> tuple[sp.csc_matrix, FloatArray]:
    """Normal equations ``H = J^T W J`` and ``g = J^T W e`` over the free vertices.

    Edge ``k`` has error ``e[k]`` (``(E, m)``), Jacobians ``a[k]`` wrt vertex ``fr[k]`` and
    ``b[k]`` wrt ``to[k]`` (``(E, m, d)``) and weight ``w[k]`` (``(E, m, m)``); vertex ``v``
    owns unknowns ``d*col[v] .. d*col[v]+d-1`` (none if ``col[v] < 0``).
    """
    d = a.shape[2]
    wa = w @ a
    wb = w @ b
    at = np.swapaxes(a, 1, 2)
    bt = np.swapaxes(b, 1, 2)
    hab = at @ wb
    blocks = ((0, 0, at @ wa), (0, 1, hab), (1, 0, np.swapaxes(hab, 1, 2)), (1, 1, bt @ wb))
    ends = (col[fr], col[to])
    offs = np.arange(d)
    rr = np.repeat(offs, d)
    cc = np.tile(offs, d)
    rows, cols, vals = [], [], []
    for p, q, blk in blocks:
        ok = (ends[p] >= 0) & (ends[q] >= 0)
        rows.append((d * ends[p][ok])[:, None] + rr)
        cols.append((d * ends[q][ok])[:, None] + cc)
        vals.append(blk[ok].reshape(-1, d * d))
    h = sp.csc_matrix(
        (
            np.concatenate(vals).ravel(),
            (np.concatenate(rows).ravel(), np.concatenate(cols).ravel()),
        ),
        shape=(d * n, d * n),
    )
    we = (w @ e[:, :, None])[:, :, 0]
    g = np.zeros(d * n)
    for end, jt in ((ends[0], at), (ends[1], bt)):
        ok = end >= 0
        contrib = (jt[ok] @ we[ok][:, :, None])[:, :, 0]
        idx = (d * end[ok])[:, None] + offs
        g += np.bincount(idx.ravel(), weights=contrib.ravel(), minlength=d * n)
    return h, g


class _Factoriser:
    """Sparse LDL^T factorisations of symmetric positive definite systems that keep their
    sparsity pattern from one solve to the next (QDLDL, in an approximate-minimum-degree
    order).

    The ordering and the symbolic analysis are done on the first :meth:`solve`; later
    solves with the same pattern only refactorise numerically (a new pattern starts over).
    """

    def __init__(self) -> None:
        self._solver: Any = None
        self._indptr = np.zeros(0, dtype=np.int64)
        self._indices = np.zeros(0, dtype=np.int64)

    def solve(self, h: sp.spmatrix, rhs: FloatArray) -> FloatArray:
        """``h^-1 rhs``; raises RuntimeError when ``h`` is singular."""
        upper = sp.triu(h, format="csc")
        upper.sort_indices()
        same = (
            self._solver is not None
            and np.array_equal(upper.indptr, self._indptr)
            and np.array_equal(upper.indices, self._indices)
        )
        try:
            if same:
                self._solver.update(upper, upper=True)
            else:
                self._solver = qdldl.Solver(upper, upper=True)
                self._indptr, self._indices = upper.indptr.copy(), upper.indices.copy()
            out = np.asarray(self._solver.solve(rhs), dtype=np.float64)
        except ValueError as err:  # QDLDL: a zero pivot
            self._solver = None
            raise RuntimeError(f"the factorisation failed: {err}") from err
        if not np.all(np.isfinite(out)):
            raise RuntimeError("the factorisation is numerically singular")
        return out


# --------------------------------------------------------------------------------- chordal start


def chordal_initialisation(graph: PoseGraph, poses: ArrayLike | None = None) -> FloatArray:
    """A start for :func:`optimize` near the global optimum, for loopy graphs.

    1. Orientations: with ``r_k = (cos th_k, sin th_k)`` each edge says ``r_j = R(z_th) r_i``,
       which is linear in ``r``. The weighted least-squares solution (weights
       ``Omega_thth``, fixed vertices held) is normalised per vertex: ``th_k = atan2``.
    2. Positions: with those orientations, ``t_j - t_i = R(th_i) z_t`` is linear in the
       positions and solved in least squares, weighted by each edge's translational
       information rotated into the world frame.

    Args:
        graph: The graph.
        poses: Poses of the fixed vertices are taken from here (default ``graph.poses``);
            the other rows are ignored.

    Returns:
        ``(V, 3)`` poses.

    Raises:
        PoseGraphError: a vertex is not connected to a fixed one, or a system is singular.
    """
    x = np.array(_as_poses(graph, poses), dtype=np.float64)
    col, n = _free_index(graph)
    if n == 0:
        return x
    _check_connected(graph)
    fr, to = graph.edge_from, graph.edge_to
    z = graph.measurements
    count = graph.num_edges
    free_rows = np.flatnonzero(col >= 0)
    known = (col < 0)[:, None]
    eye = np.broadcast_to(np.eye(2), (count, 2, 2))
    factoriser = _Factoriser()
    # 1. orientations: residual r_j - M(z) r_i with M(z) = [[c, -s], [s, c]]
    cz, sz = np.cos(z[:, 2]), np.sin(z[:, 2])
    m = np.empty((count, 2, 2))
    m[:, 0, 0], m[:, 0, 1], m[:, 1, 0], m[:, 1, 1] = cz, -sz, sz, cz
    w = np.maximum(graph.information[:, 2, 2], 1e-12)[:, None, None] * eye
    r = np.where(known, np.stack([np.cos(x[:, 2]), np.sin(x[:, 2])], axis=1), 0.0)
    e0 = r[to] - (m @ r[fr][:, :, None])[:, :, 0]
    h, g = _assemble(col, n, fr, to, -m, np.ascontiguousarray(eye), w, e0)
    try:
        sol = factoriser.solve(h, -g).reshape(-1, 2)
    except RuntimeError as err:
        raise PoseGraphError(f"orientation initialisation failed: {err}") from err
    x[free_rows, 2] = np.arctan2(sol[:, 1], sol[:, 0])
    # 2. positions: residual t_j - t_i - R(th_i) z_t, weight R W_t R^T, R = R(th_i + z_th)
    ci, si = np.cos(x[fr, 2]), np.sin(x[fr, 2])
    cw, sw = np.cos(x[fr, 2] + z[:, 2]), np.sin(x[fr, 2] + z[:, 2])
    rw = np.empty((count, 2, 2))
    rw[:, 0, 0], rw[:, 0, 1], rw[:, 1, 0], rw[:, 1, 1] = cw, -sw, sw, cw
    wt = rw @ graph.information[:, :2, :2] @ np.swapaxes(rw, 1, 2)
    c = np.stack([ci * z[:, 0] - si * z[:, 1], si * z[:, 0] + ci * z[:, 1]], axis=1)
    t = np.where(known, x[:, :2], 0.0)
    e0 = t[to] - t[fr] - c
    h, g = _assemble(col, n, fr, to, np.ascontiguousarray(-eye), np.ascontiguousarray(eye), wt, e0)
    try:
        sol = factoriser.solve(h, -g).reshape(-1, 2)
    except RuntimeError as err:
        raise PoseGraphError(f"position initialisation failed: {err}") from err
    x[free_rows, :2] = sol
    return x


# --------------------------------------------------------------------------------- optimiser


@dataclass(frozen=True)
class OptimizationReport:
    """What :func:`optimize` did.

    Attributes:
        initial_chi2: chi2 at the start (after the initialisation, if one was asked for).
        final_chi2: chi2 of the returned poses.
        iterations: linear systems solved (Gauss-Newton and Levenberg-Marquardt steps,
            kept or not).
        gauss_newton_steps: how many of them were undamped Gauss-Newton steps.
        converged: whether a stopping test, not the iteration limit, ended the run.
        reason: why it stopped, in words.
        time_s: wall time of the whole call (initialisation included), s.
        history: chi2 after each step that was kept, starting with ``initial_chi2``.
    """

    initial_chi2: float
    final_chi2: float
    iterations: int
    gauss_newton_steps: int
    converged: bool
    reason: str
    time_s: float
    history: tuple[float, ...]


def _linearise(graph: PoseGraph, x: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Errors ``(E, 3)`` and their Jacobians wrt vertex ``i`` and ``j`` (``(E, 3, 3)``)."""
    xi = x[graph.edge_from]
    xj = x[graph.edge_to]
    z = graph.measurements
    count = z.shape[0]
    ci, si = np.cos(xi[:, 2]), np.sin(xi[:, 2])
    dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
    ux = ci * dx + si * dy  # R(th_i)^T (t_j - t_i)
    uy = -si * dx + ci * dy
    cz, sz = np.cos(z[:, 2]), np.sin(z[:, 2])
    px, py = ux - z[:, 0], uy - z[:, 1]
    e = np.empty((count, 3))
    e[:, 0] = cz * px + sz * py
    e[:, 1] = -sz * px + cz * py
    e[:, 2] = _wrap(xj[:, 2] - xi[:, 2] - z[:, 2])
    # de/dx_j: R(th_i + z_th)^T on the translation, 1 on the angle; de/dx_i = -that, plus
    # the lever arm: d/dth_i R(th_i)^T (t_j - t_i) = (uy, -ux), rotated by R(z_th)^T
    c, s = np.cos(xi[:, 2] + z[:, 2]), np.sin(xi[:, 2] + z[:, 2])
    b = np.zeros((count, 3, 3))
    b[:, 0, 0], b[:, 0, 1], b[:, 1, 0], b[:, 1, 1], b[:, 2, 2] = c, s, -s, c, 1.0
    a = -b
    a[:, 0, 2] = cz * uy - sz * ux
    a[:, 1, 2] = -sz * uy - cz * ux
    return e, a, b


Method = Literal["auto", "levenberg-marquardt"]
Init = Literal["none", "chordal", "odometry"]

#: Undamped steps in a row that may fail to beat the best chi2 before falling back to LM.
_WATCHDOG_STEPS: Final = 4
#: Starting Levenberg-Marquardt damping, relative to the diagonal of H.
_LAMBDA0: Final = 1e-5
_LAMBDA_MAX: Final = 1e16
#: chi2 changes below this (absolute) count as no change.
_CHI2_ATOL: Final = 1e-15


def optimize(
    graph: PoseGraph,
    initial: ArrayLike | None = None,
    *,
    max_iterations: int = 100,
    tolerance: float = 1e-9,
    init: Init = "none",
    method: Method = "auto",
) -> tuple[FloatArray, OptimizationReport]:
    """Minimise chi2 over the free vertices (the fixed ones keep their initial pose).

    Every iteration linearises all edges at once (analytic Jacobians, vectorised over
    edges), assembles the sparse normal equations ``(H + lambda D) dx = -g`` over the free
    vertices, ``D = diag(H)``, and solves them by a sparse LDL^T factorisation in a
    fill-reducing order analysed once. Poses are updated additively (angles wrapped), as
    g2o's ``VertexSE2`` does.

    ``method="auto"`` starts with undamped Gauss-Newton steps (``lambda = 0``) under a
    watchdog: a step may raise chi2 (after a big loop closure the first steps often do, then
    land next to the optimum), but the best poses seen are kept, and if
    ``4`` steps in a row fail to beat the best chi2 the run returns to the best poses and
    continues with Levenberg-Marquardt. ``method="levenberg-marquardt"`` uses LM from the
    start. LM keeps only steps that lower chi2 and updates ``lambda`` by Nielsen's rule
    (times ``max(1/3, 1 - (2 rho - 1)^3)`` after a kept step, ``rho`` = actual / predicted
    decrease; times 2, 4, 8, ... after rejected ones).

    Args:
        graph: The pose graph.
        initial: ``(V, 3)`` starting poses (default: ``graph.poses``).
        max_iterations: Most linear solves.
        tolerance: Converged when a step changes chi2 by at most ``tolerance`` times chi2.
        init: Replace the start first: ``"chordal"`` (:func:`chordal_initialisation`, for
            big loopy graphs from a poor start), ``"odometry"``
            (:func:`odometry_initialisation`) or ``"none"`` (``initial`` as given).
        method: ``"auto"`` or ``"levenberg-marquardt"``, see above.

    Returns:
        The optimised ``(V, 3)`` poses (angles in [-pi, pi)) and an
        :class:`OptimizationReport`.

    Raises:
        PoseGraphError: bad arguments, or a vertex is not connected to a fixed one (its
            pose would be undetermined).
    """
    t0 = time.perf_counter()
    if max_iterations < 0:
        raise PoseGraphError(f"max_iterations must be >= 0, not {max_iterations}")
    if not (math.isfinite(tolerance) and tolerance >= 0.0):
        raise PoseGraphError(f"tolerance must be a finite number >= 0, not {tolerance}")
    if method not in ("auto", "levenberg-marquardt"):
        raise PoseGraphError(f"unknown method {method!r} (auto or levenberg-marquardt)")
    x = np.array(_as_poses(graph, initial), dtype=np.float64)
    if init == "chordal":
        x = chordal_initialisation(graph, x)
    elif init == "odometry":
        x = odometry_initialisation(_with_poses(graph, x))
    elif init != "none":
        raise PoseGraphError(f"unknown initialisation {init!r} (none, chordal or odometry)")
    x[:, 2] = _wrap(x[:, 2])
    col, n = _free_index(graph)
    f = _chi2(graph, x)
    history = [f]

    def report(reason: str, converged: bool, iterations: int, gn_steps: int) -> OptimizationReport:
        return OptimizationReport(
            initial_chi2=history[0],
            final_chi2=f,
            iterations=iterations,
            gauss_newton_steps=gn_steps,
            converged=converged,
            reason=reason,
            time_s=time.perf_counter() - t0,
            history=tuple(history),
        )

    if n == 0 or graph.num_edges == 0:
        return x, report("nothing to optimise", True, 0, 0)
    _check_connected(graph)
    free_rows = np.flatnonzero(col >= 0)
    factoriser = _Factoriser()
    gauss_newton = method == "auto"
    best_x, best_f = x, f  # Gauss-Newton phase: the best poses so far
    misses = 0
    lam, nu = _LAMBDA0, 2.0
    iterations = gn_steps = 0
    h: sp.csc_matrix | None = None
    g = diag = np.zeros(0)
    stale = True
    while iterations < max_iterations:
        if stale:
            e, a, b = _linearise(graph, x)
            h, g = _assemble(col, n, graph.edge_from, graph.edge_to, a, b, graph.information, e)
            diag = np.maximum(h.diagonal(), 1e-12)
            stale = False
            if not np.any(g):
                return x, report("gradient is zero", True, iterations, gn_steps)
        assert h is not None
        iterations += 1
        damping = 0.0 if gauss_newton else lam
        try:
            step = factoriser.solve(h + sp.diags(damping * diag), -g)
        except RuntimeError:
            step = np.full_like(g, np.nan)
        x_new = x.copy()
        x_new[free_rows] += step.reshape(-1, 3)
        x_new[:, 2] = _wrap(x_new[:, 2])
        f_new = _chi2(graph, x_new) if np.all(np.isfinite(step)) else math.inf
        if gauss_newton:
            gn_steps += 1
            if f_new < best_f:
                done = best_f - f_new <= tolerance * best_f + _CHI2_ATOL
                best_x, best_f, misses = x_new, f_new, 0
            else:
                done = misses == 0 and f_new - best_f <= tolerance * best_f + _CHI2_ATOL
                misses += 1
            x, f, stale = x_new, f_new, True
            history.append(f)
            if done or misses >= _WATCHDOG_STEPS or not math.isfinite(f_new):
                x, f = best_x, best_f
                if f != history[-1]:
                    history.append(f)
                if done:
                    return x, report("chi2 stopped changing", True, iterations, gn_steps)
                gauss_newton = False  # fall back to Levenberg-Marquardt from the best poses
            continue
        # Levenberg-Marquardt: predicted decrease of the linear model, -(2 g.dx + dx.H.dx)
        predicted = -(2.0 * float(g @ step) + float(step @ (h @ step)))
        rho = (f - f_new) / predicted if predicted > 0.0 else -1.0
        if f_new < f and rho > 0.0:
            done = f - f_new <= tolerance * f + _CHI2_ATOL
            x, f, stale = x_new, f_new, True
            history.append(f)
            lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
            nu = 2.0
            if done:
                return x, report("chi2 stopped changing", True, iterations, gn_steps)
        else:
            lam *= nu
            nu *= 2.0
            if lam > _LAMBDA_MAX:
                return x, report("no step lowers chi2 any more", True, iterations, gn_steps)
    if gauss_newton and best_f < f:
        x, f = best_x, best_f
        history.append(f)
    return x, report("iteration limit reached", False, iterations, gn_steps)
