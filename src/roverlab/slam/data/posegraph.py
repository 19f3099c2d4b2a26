"""2-D pose graphs: g2o ``VERTEX_SE2`` / ``EDGE_SE2`` files, chi2, and a sparse optimiser.

A :class:`PoseGraph` holds vertices (poses ``(x, y, theta)``) and relative-pose constraints.
Edge ``k`` from vertex ``i`` to vertex ``j`` measures ``z = (z_x, z_y, z_theta)``, the pose of
``j`` in the frame of ``i``, with information matrix ``Omega`` (3x3, g2o order x, y, theta).
Its error is the one g2o's ``EdgeSE2`` computes::

    e = [ R(z_th)^T (R(th_i)^T (t_j - t_i) - z_t) ;  wrap(th_j - th_i - z_th) ]

and :func:`chi2` is ``sum_k e_k^T Omega_k e_k`` (no 1/2), as g2o prints it.

:func:`optimize` minimises chi2 on the sparse normal equations: undamped Gauss-Newton steps
under a watchdog (a step may raise chi2 for a while, as after a big loop closure, but the
best poses are kept) and Levenberg-Marquardt with Nielsen's damping update when Gauss-Newton
stops making progress. Jacobians are analytic, computed for all edges at once with numpy
and assembled into a ``scipy.sparse`` matrix, factorised by QDLDL (sparse LDL^T) in an
approximate-minimum-degree order analysed once per run. The gauge is fixed by holding the
first vertex (or the vertices of the file's ``FIX`` lines) at its initial value. From a
poor start on a big loopy graph any local method can stop in a local minimum:
:func:`chordal_initialisation` gives a start near the global optimum by solving first for
the orientations (a linear least-squares problem on ``(cos, sin)`` pairs, normalised
afterwards) and then, with the orientations fixed, for the positions (linear again).

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
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
import qdldl
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse.csgraph import connected_components

from roverlab.slam.data._io import atomic_write_text
from roverlab.slam.data.errors import PoseGraphError

__all__ = [
    "OptimizationReport",
    "PoseGraph",
    "chi2",
    "chordal_initialisation",
    "edge_errors",
    "odometry_initialisation",
    "optimize",
    "read_g2o",
    "write_g2o",
]

FloatArray = NDArray[np.float64]
IndexArray = NDArray[np.intp]

_TWO_PI: Final = 2.0 * math.pi
#: Upper-triangular order of the 6 information entries on an EDGE_SE2 line.
_TRIU: Final = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def _wrap(a: FloatArray) -> FloatArray:
    """Angles wrapped to [-pi, pi)."""
    return np.asarray((a + np.pi) % _TWO_PI - np.pi, dtype=np.float64)


# --------------------------------------------------------------------------------- graph


@dataclass(frozen=True, eq=False, kw_only=True)
class PoseGraph:
    """A 2-D pose graph; arrays are validated (shapes, finiteness, indices) at construction.

    Attributes:
        ids: ``(V,)`` vertex ids as in the file; row ``k`` of every per-vertex array is
            vertex ``ids[k]``.
        poses: ``(V, 3)`` initial estimates ``(x, y, theta)``, m and rad.
        edge_from: ``(E,)`` index (row, not id) of each edge's first vertex ``i``.
        edge_to: ``(E,)`` index of each edge's second vertex ``j``.
        measurements: ``(E, 3)`` measured pose of ``j`` in the frame of ``i``.
        information: ``(E, 3, 3)`` symmetric information matrices.
        fixed: indices of the vertices held fixed (the gauge): the ``FIX`` vertices of the
            file if it has any, else the first vertex.
        vertices_given: whether the initial estimates came from VERTEX lines (False: they
            were chained from the odometry edges).
    """

    ids: NDArray[np.int64]
    poses: FloatArray
    edge_from: IndexArray
    edge_to: IndexArray
    measurements: FloatArray
    information: FloatArray
    fixed: IndexArray = field(default_factory=lambda: np.zeros(1, dtype=np.intp))
    vertices_given: bool = True

    def __post_init__(self) -> None:
        ids = np.asarray(self.ids, dtype=np.int64).reshape(-1)
        poses = np.asarray(self.poses, dtype=np.float64)
        fr = np.asarray(self.edge_from, dtype=np.intp).reshape(-1)
        to = np.asarray(self.edge_to, dtype=np.intp).reshape(-1)
        meas = np.asarray(self.measurements, dtype=np.float64)
        info = np.asarray(self.information, dtype=np.float64)
        fixed = np.unique(np.asarray(self.fixed, dtype=np.intp).reshape(-1))
        v, e = ids.shape[0], fr.shape[0]
        if v == 0:
            raise PoseGraphError("a pose graph needs at least one vertex")
        if poses.shape != (v, 3):
            raise PoseGraphError(f"poses must have shape ({v}, 3), not {poses.shape}")
        if np.unique(ids).shape[0] != v:
            raise PoseGraphError("vertex ids must be unique")
        if to.shape != (e,) or meas.shape != (e, 3) or info.shape != (e, 3, 3):
            raise PoseGraphError(
                f"edge arrays disagree: {e} edge_from, {to.shape[0]} edge_to, "
                f"measurements {meas.shape}, information {info.shape}"
            )
        for name, idx in (("edge_from", fr), ("edge_to", to), ("fixed", fixed)):
            if idx.size and (idx.min() < 0 or idx.max() >= v):
                raise PoseGraphError(f"{name} holds a vertex index outside [0, {v})")
        if e and np.any(fr == to):
            raise PoseGraphError("an edge connects a vertex to itself")
        if fixed.size == 0:
            raise PoseGraphError("at least one vertex must be fixed (the gauge)")
        for name, arr in (("poses", poses), ("measurements", meas), ("information", info)):
            if not np.all(np.isfinite(arr)):
                raise PoseGraphError(f"{name} hold non-finite values")
        if not np.allclose(info, np.swapaxes(info, 1, 2), rtol=1e-9, atol=1e-9):
            raise PoseGraphError("information matrices must be symmetric")
        frozen: tuple[tuple[str, NDArray[Any]], ...] = (
            ("ids", ids),
            ("poses", poses),
            ("edge_from", fr),
            ("edge_to", to),
            ("measurements", meas),
            ("information", info),
            ("fixed", fixed),
        )
        for name, arr in frozen:
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    @property
    def num_vertices(self) -> int:
        return int(self.ids.shape[0])

    @property
    def num_edges(self) -> int:
        return int(self.edge_from.shape[0])

    def index_of(self, vertex_id: int) -> int:
        """Row of vertex ``vertex_id``; raises PoseGraphError if there is none."""
        hits = np.flatnonzero(self.ids == vertex_id)
        if hits.size == 0:
            raise PoseGraphError(f"no vertex with id {vertex_id}")
        return int(hits[0])


# --------------------------------------------------------------------------------- g2o io


def read_g2o(path: str | Path) -> PoseGraph:
    """Read a g2o file of ``VERTEX_SE2``, ``EDGE_SE2`` (and ``FIX``) lines.

    ``EDGE_SE2 i j x y theta I11 I12 I13 I22 I23 I33`` gives the measurement and the upper
    triangle of the information matrix. Without VERTEX lines, the initial poses are chained
    from the odometry edges (consecutive ids), see :func:`odometry_initialisation`. Blank
    lines and ``#`` comments are skipped.

    Raises:
        PoseGraphError: the file cannot be read, a line is malformed (the message names the
            file and line), an edge names an unknown vertex, or a line type is not a 2-D
            pose-graph one (landmarks, 3-D).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise PoseGraphError(f"{p}: cannot read: {err}") from err
    vids: list[int] = []
    vposes: list[tuple[float, float, float]] = []
    efrom: list[int] = []
    eto: list[int] = []
    evals: list[list[float]] = []
    fix_ids: list[int] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        parts = line.split()
        if not parts or parts[0].startswith("#"):
            continue
        tag = parts[0]
        try:
            if tag == "VERTEX_SE2":
                if len(parts) != 5:
                    raise ValueError(f"VERTEX_SE2 needs 4 values, got {len(parts) - 1}")
                vids.append(int(parts[1]))
                vposes.append((float(parts[2]), float(parts[3]), float(parts[4])))
            elif tag == "EDGE_SE2":
                if len(parts) != 12:
                    raise ValueError(f"EDGE_SE2 needs 11 values, got {len(parts) - 1}")
                efrom.append(int(parts[1]))
                eto.append(int(parts[2]))
                evals.append([float(s) for s in parts[3:12]])
            elif tag == "FIX":
                if len(parts) < 2:
                    raise ValueError("FIX needs a vertex id")
                fix_ids.extend(int(s) for s in parts[1:])
            else:
                raise PoseGraphError(
                    f"{p}:{lineno}: unsupported g2o element {tag!r} "
                    "(only VERTEX_SE2, EDGE_SE2 and FIX)"
                )
        except ValueError as err:
            raise PoseGraphError(f"{p}:{lineno}: malformed {tag} line: {err}") from err
    if not vids and not efrom:
        raise PoseGraphError(f"{p}: no VERTEX_SE2 or EDGE_SE2 line")
    vals = np.asarray(evals, dtype=np.float64).reshape(-1, 9)
    info = np.zeros((vals.shape[0], 3, 3))
    for k, (r, c) in enumerate(_TRIU):
        info[:, r, c] = vals[:, 3 + k]
        info[:, c, r] = vals[:, 3 + k]
    vertices_given = bool(vids)
    ids = np.asarray(vids if vids else sorted({*efrom, *eto}), dtype=np.int64)
    if np.unique(ids).shape[0] != ids.shape[0]:
        raise PoseGraphError(f"{p}: a VERTEX_SE2 id appears twice")
    order = np.argsort(ids, kind="stable")
    sorted_ids = ids[order]

    def rows(id_list: list[int], what: str) -> IndexArray:
        a = np.asarray(id_list, dtype=np.int64)
        pos = np.searchsorted(sorted_ids, a)
        pos = np.minimum(pos, sorted_ids.shape[0] - 1)
        bad = sorted_ids[pos] != a
        if np.any(bad):
            raise PoseGraphError(
                f"{p}: {what} names vertex {int(a[bad][0])}, which has no VERTEX_SE2"
            )
        return np.asarray(order[pos], dtype=np.intp)

    fr, to = rows(efrom, "an edge"), rows(eto, "an edge")
    fixed = rows(fix_ids, "FIX") if fix_ids else np.zeros(1, dtype=np.intp)
    poses = np.asarray(vposes, dtype=np.float64).reshape(-1, 3)
    try:
        graph = PoseGraph(
            ids=ids,
            poses=poses if vertices_given else np.zeros((ids.shape[0], 3)),
            edge_from=fr,
            edge_to=to,
            measurements=vals[:, :3],
            information=info,
            fixed=fixed,
            vertices_given=vertices_given,
        )
    except PoseGraphError as err:
        raise PoseGraphError(f"{p}: {err}") from err
    if not vertices_given:
        graph = _with_poses(graph, odometry_initialisation(graph))
    return graph


def _fmt(v: float) -> str:
    """Shortest text that reads back as exactly ``v``."""
    return repr(float(v))


def _g2o_lines(graph: PoseGraph, poses: FloatArray) -> Iterator[str]:
    for vid, (x, y, th) in zip(graph.ids.tolist(), poses.tolist(), strict=True):
        yield f"VERTEX_SE2 {vid} {_fmt(x)} {_fmt(y)} {_fmt(th)}\n"
    ids = graph.ids
    for k in range(graph.num_edges):
        z = graph.measurements[k]
        om = graph.information[k]
        nums = " ".join(_fmt(v) for v in (*z, *(om[r, c] for r, c in _TRIU)))
        yield f"EDGE_SE2 {ids[graph.edge_from[k]]} {ids[graph.edge_to[k]]} {nums}\n"
    default_gauge = graph.fixed.shape[0] == 1 and graph.fixed[0] == 0
    if not default_gauge:
        yield "FIX " + " ".join(str(ids[k]) for k in graph.fixed) + "\n"


def write_g2o(path: str | Path, graph: PoseGraph, poses: ArrayLike | None = None) -> None:
    """Write ``graph`` as g2o text, atomically (a temporary file renamed into place).

    Numbers are written with the fewest digits that read back exactly, so
    ``read_g2o(write_g2o(g))`` gives the same arrays.

    Args:
        path: Output file.
        graph: The graph (edges, ids, gauge).
        poses: ``(V, 3)`` vertex poses to write (default: ``graph.poses``), e.g. the
            optimised ones.

    Raises:
        PoseGraphError: bad ``poses`` shape, or the file cannot be written.
    """
    est = graph.poses if poses is None else np.asarray(poses, dtype=np.float64)
    if est.shape != graph.poses.shape:
        raise PoseGraphError(f"poses must have shape {graph.poses.shape}, not {est.shape}")
    atomic_write_text(path, "".join(_g2o_lines(graph, est)), PoseGraphError)


# --------------------------------------------------------------------------------- errors


def _as_poses(graph: PoseGraph, poses: ArrayLike | None) -> FloatArray:
    x = graph.poses if poses is None else np.asarray(poses, dtype=np.float64)
    if x.shape != graph.poses.shape:
        raise PoseGraphError(f"poses must have shape {graph.poses.shape}, not {x.shape}")
    return x


def _errors(graph: PoseGraph, x: FloatArray) -> FloatArray:
    xi = x[graph.edge_from]
    xj = x[graph.edge_to]
    z = graph.measurements
    ci, si = np.cos(xi[:, 2]), np.sin(xi[:, 2])
    dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
    px = ci * dx + si * dy - z[:, 0]
    py = -si * dx + ci * dy - z[:, 1]
    cz, sz = np.cos(z[:, 2]), np.sin(z[:, 2])
    e = np.empty_like(z)
    e[:, 0] = cz * px + sz * py
    e[:, 1] = -sz * px + cz * py
    e[:, 2] = _wrap(xj[:, 2] - xi[:, 2] - z[:, 2])
    return e


def edge_errors(graph: PoseGraph, poses: ArrayLike | None = None) -> FloatArray:
    """``(E, 3)`` error vectors ``e`` of every edge (see the module docstring)."""
    return _errors(graph, _as_poses(graph, poses))


def _chi2(graph: PoseGraph, x: FloatArray) -> float:
    e = _errors(graph, x)
    return float(np.einsum("ei,eij,ej->", e, graph.information, e))


def chi2(graph: PoseGraph, poses: ArrayLike | None = None) -> float:
    """``sum_k e_k^T Omega_k e_k`` over the edges, at ``poses`` (default: the graph's)."""
    return _chi2(graph, _as_poses(graph, poses))


# --------------------------------------------------------------------------------- initialisation


def odometry_initialisation(graph: PoseGraph) -> FloatArray:
    """Poses chained from the odometry edges (consecutive vertex ids), first vertex kept.

    Vertices are visited in id order; vertex ``k+1`` is placed by the edge between ``k``
    and ``k+1`` (either direction). Vertices the chain cannot reach are placed
    breadth-first over the remaining edges; vertices no edge reaches keep their pose.
    """
    v = graph.num_vertices
    x = np.array(graph.poses, dtype=np.float64)
    placed = np.zeros(v, dtype=bool)
    order = np.argsort(graph.ids, kind="stable")
    placed[order[0]] = True
    placed[graph.fixed] = True
    adj: dict[int, list[tuple[int, int, bool]]] = {}
    for k, (i, j) in enumerate(zip(graph.edge_from.tolist(), graph.edge_to.tolist(), strict=True)):
        adj.setdefault(i, []).append((j, k, True))
        adj.setdefault(j, []).append((i, k, False))
    z = graph.measurements

    def place(src: int, dst: int, k: int, forward: bool) -> None:
        zx, zy, zt = z[k]
        if not forward:  # dst -> src measured: invert it
            c, s = math.cos(zt), math.sin(zt)
            zx, zy, zt = -c * zx - s * zy, s * zx - c * zy, -zt
        px, py, pt = x[src]
        c, s = math.cos(pt), math.sin(pt)
        x[dst] = (px + c * zx - s * zy, py + s * zx + c * zy, math.remainder(pt + zt, _TWO_PI))
        placed[dst] = True

    ids = graph.ids
    for a, b in zip(order[:-1].tolist(), order[1:].tolist(), strict=True):
        if placed[b] or not placed[a] or ids[b] != ids[a] + 1:
            continue
        for nb, k, fwd in adj.get(a, ()):
            if nb == b:
                place(a, b, k, fwd)
                break
    queue = deque(np.flatnonzero(placed).tolist())
    while queue:
        a = queue.popleft()
        for nb, k, fwd in adj.get(a, ()):
            if not placed[nb]:
                place(a, nb, k, fwd)
                queue.append(nb)
    return x


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


def _with_poses(graph: PoseGraph, poses: FloatArray) -> PoseGraph:
    return PoseGraph(
        ids=graph.ids,
        poses=poses,
        edge_from=graph.edge_from,
        edge_to=graph.edge_to,
        measurements=graph.measurements,
        information=graph.information,
        fixed=graph.fixed,
        vertices_given=graph.vertices_given,
    )
