"""2-D pose graphs: g2o ``VERTEX_SE2`` / ``EDGE_SE2`` files and chi2.

A :class:`PoseGraph` holds vertices (poses ``(x, y, theta)``) and relative-pose constraints.
Edge ``k`` from vertex ``i`` to vertex ``j`` measures ``z = (z_x, z_y, z_theta)``, the pose of
``j`` in the frame of ``i``, with information matrix ``Omega`` (3x3, g2o order x, y, theta).
Its error is the one g2o's ``EdgeSE2`` computes::

    e = [ R(z_th)^T (R(th_i)^T (t_j - t_i) - z_t) ;  wrap(th_j - th_i - z_th) ]

and :func:`chi2` is ``sum_k e_k^T Omega_k e_k`` (no 1/2), as g2o prints it. The optimiser
is :mod:`roverlab.slam.data.pose_solver`.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.slam.data._io import atomic_write_text, text_rows
from roverlab.slam.data.errors import PoseGraphError

__all__ = [
    "PoseGraph",
    "chi2",
    "edge_errors",
    "odometry_initialisation",
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
    vids: list[int] = []
    vposes: list[tuple[float, float, float]] = []
    efrom: list[int] = []
    eto: list[int] = []
    evals: list[list[float]] = []
    fix_ids: list[int] = []
    for lineno, parts in text_rows(p, PoseGraphError):
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
