"""Mesh files (STL, Collada, OBJ) -> convex parts for the 2.5D world, cached on disk.

A world or robot mesh becomes, for each of its parts (each connected piece of each
geometry in the file), the vertices of that part's 3-D convex hull, in metres with +z up:

* loaded with ``trimesh`` (Collada through ``pycollada``), the file's scene graph applied;
* Collada's ``<asset><unit meter="...">`` scales it and ``<up_axis>`` (``Y_UP``,
  ``X_UP``) turns it to +z up, as Gazebo's loader does; STL and OBJ have no unit: metres;
* the part's colour is its material's diffuse colour (or its face/vertex colour) if the
  file gives one.

A rigid transform and a scale are affine, so the hull of the transformed part is the
transformed hull: :func:`mesh_outlines` places the cached hulls with a link's pose and the
``<scale>`` and returns, per part, its outline on the ground (the 2-D convex hull) and its
z range, which the world turns into extruded polygons seen by collision, lidar and cameras.

Processed meshes are cached in ``$ROVERLAB_CACHE_DIR/meshes`` (default
``~/.cache/roverlab/meshes``), one ``.npz`` per file keyed by the SHA-256 of its bytes, so
a changed file is re-read and a copy elsewhere is not.
"""

from __future__ import annotations

import hashlib
import os
import threading
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from roverlab.errors import RoverlabError
from roverlab.fileio import atomic_write
from roverlab.geometry import Transform3

__all__ = [
    "MESH_SUFFIXES",
    "MeshError",
    "MeshOutline",
    "MeshPart",
    "load_mesh",
    "mesh_cache_dir",
    "mesh_outlines",
]

MESH_SUFFIXES: Final = (".stl", ".dae", ".obj")
_CACHE_VERSION: Final = 1
_MAX_PARTS: Final = 64  # more pieces than this: one hull per geometry instead
RGB = tuple[int, int, int]


class MeshError(RoverlabError):
    """A mesh file that cannot be read (missing, unsupported format, no triangles)."""


@dataclass(frozen=True)
class MeshPart:
    """One convex part: its hull vertices (n, 3) in metres, +z up, and its colour."""

    hull: NDArray[np.float64]
    rgb: RGB | None = None


@dataclass(frozen=True)
class MeshOutline:
    """A placed part: its outline on the ground (k, 2) (counter-clockwise), z range, colour."""

    points: NDArray[np.float64]
    z_min: float
    z_max: float
    rgb: RGB | None = None


def mesh_cache_dir() -> Path:
    """Where processed meshes are kept (``$ROVERLAB_CACHE_DIR/meshes``)."""
    root = os.environ.get("ROVERLAB_CACHE_DIR")
    base = Path(root) if root else Path.home() / ".cache" / "roverlab"
    return base / "meshes"


_MEMO: dict[tuple[str, int, int], tuple[MeshPart, ...]] = {}
_LOCK = threading.Lock()


def load_mesh(path: str | os.PathLike[str]) -> tuple[MeshPart, ...]:
    """The convex parts of a mesh file (see the module docstring).

    Raises:
        MeshError: one line naming the file: missing, not STL/DAE/OBJ, unreadable, empty.
    """
    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise MeshError(f"{p}: mesh format {p.suffix or '(none)'} is not supported (STL, DAE, OBJ)")
    try:
        st = p.stat()
    except OSError as err:
        raise MeshError(f"{p}: cannot read mesh: {err.strerror or err}") from err
    memo_key = (str(p.resolve()), st.st_mtime_ns, st.st_size)
    with _LOCK:
        hit = _MEMO.get(memo_key)
    if hit is not None:
        return hit
    data = p.read_bytes()
    digest = hashlib.sha256(data).hexdigest()
    cache = mesh_cache_dir() / f"{digest}-v{_CACHE_VERSION}.npz"
    parts = _read_cache(cache)
    if parts is None:
        parts = _process(p, data)
        _write_cache(cache, parts)
    with _LOCK:
        _MEMO[memo_key] = parts
    return parts


def _read_cache(cache: Path) -> tuple[MeshPart, ...] | None:
    try:
        with np.load(cache) as z:
            counts = z["counts"]
            verts = z["vertices"]
            rgbs = z["rgb"]
    except (OSError, KeyError, ValueError):
        return None
    out: list[MeshPart] = []
    start = 0
    for n, rgb in zip(counts.tolist(), rgbs.tolist(), strict=True):
        colour = None if rgb[0] < 0 else (int(rgb[0]), int(rgb[1]), int(rgb[2]))
        out.append(MeshPart(verts[start : start + n].copy(), colour))
        start += n
    return tuple(out)


def _write_cache(cache: Path, parts: tuple[MeshPart, ...]) -> None:
    """Atomic write (temp + rename); a cache that cannot be written is only slower."""
    try:
        cache.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(
            cache,
            lambda f: np.savez(
                f,
                counts=np.array([len(q.hull) for q in parts], dtype=np.int64),
                vertices=np.concatenate([q.hull for q in parts]) if parts else np.zeros((0, 3)),
                rgb=np.array(
                    [q.rgb if q.rgb else (-1, -1, -1) for q in parts], dtype=np.int64
                ).reshape(-1, 3),
            ),
        )
    except OSError:
        return


def _collada_frame(data: bytes) -> NDArray[np.float64]:
    """4x4 transform applying Collada's unit and up axis (identity when absent)."""
    m = np.eye(4)
    try:
        root = ET.fromstring(data)
    except ET.ParseError:
        return m
    ns = root.tag[: root.tag.index("}") + 1] if root.tag.startswith("{") else ""
    asset = root.find(f"{ns}asset")
    if asset is None:
        return m
    unit = asset.find(f"{ns}unit")
    scale = 1.0
    if unit is not None:
        try:
            scale = float(unit.get("meter", "1"))
        except ValueError:
            scale = 1.0
    up = (asset.findtext(f"{ns}up_axis") or "Z_UP").strip().upper()
    if up == "Y_UP":  # +y up -> +z up: rotate +90 deg about x
        m[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
    elif up == "X_UP":  # +x up -> +z up: rotate -90 deg about y
        m[:3, :3] = [[0, 0, -1], [0, 1, 0], [1, 0, 0]]
    m[:3, :3] *= scale
    return m


def _colour(geom: Any) -> RGB | None:
    visual = getattr(geom, "visual", None)
    if visual is None:
        return None
    try:
        kind = visual.kind
        if kind == "texture":
            material = visual.material
            c = getattr(material, "main_color", None)
            if c is None:
                c = getattr(material, "diffuse", None)
        elif kind in ("face", "vertex"):
            c = visual.main_color
        else:
            return None
    except (AttributeError, ValueError, IndexError):
        return None
    if c is None:
        return None
    arr = np.asarray(c, dtype=np.float64).reshape(-1)
    if arr.size < 3:
        return None
    if (
        arr.max() <= 1.0
        and arr.dtype.kind == "f"
        and not np.issubdtype(np.asarray(c).dtype, np.integer)
    ):
        arr = arr * 255.0
    return (int(arr[0]), int(arr[1]), int(arr[2]))


def _hull3(points: NDArray[np.float64]) -> NDArray[np.float64]:
    """The 3-D convex hull's vertices (all points if flat or tiny)."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 5:
        return pts
    try:
        return pts[ConvexHull(pts).vertices]
    except (QhullError, ValueError):
        return pts  # flat: keep every vertex (its 2-D hull is taken later)


def _pieces(geom: Any) -> list[NDArray[np.float64]]:
    """The vertices of each connected piece of one geometry (the whole geometry when it
    has more than ``_MAX_PARTS`` pieces).

    Only trimesh's own code and scipy run here: ``repair=False`` skips the hole filling
    that ``split`` does by default (``fill_holes`` needs networkx, an optional package of
    trimesh, and a hull does not care about holes), and ``engine="scipy"`` finds the
    pieces with scipy's connected components, never networkx."""
    geom.merge_vertices()  # STL repeats each vertex per triangle: join them first
    if len(geom.faces) <= 1:
        return [np.asarray(geom.vertices, dtype=np.float64)]
    pieces = geom.split(only_watertight=False, repair=False, engine="scipy")
    if not 1 <= len(pieces) <= _MAX_PARTS:
        pieces = [geom]
    return [np.asarray(p.vertices, dtype=np.float64) for p in pieces]


def _process(path: Path, data: bytes) -> tuple[MeshPart, ...]:
    import trimesh

    try:
        loaded: Any = trimesh.load(path, force="scene", process=False)
    except Exception as err:  # trimesh and pycollada raise many kinds
        raise MeshError(f"{path}: cannot read mesh: {' '.join(str(err).split()) or err}") from err
    frame = _collada_frame(data) if path.suffix.lower() == ".dae" else np.eye(4)
    parts: list[MeshPart] = []
    geoms: list[tuple[Any, NDArray[np.float64]]] = []
    for node in loaded.graph.nodes_geometry:
        transform, name = loaded.graph[node]
        geom = loaded.geometry.get(name)
        if geom is None or not hasattr(geom, "faces") or len(geom.faces) == 0:
            continue
        geoms.append((geom, frame @ np.asarray(transform, dtype=np.float64)))
    try:
        for geom, transform in geoms:
            rgb = _colour(geom)
            for v in _pieces(geom):
                v = v @ transform[:3, :3].T + transform[:3, 3]
                if len(v):
                    parts.append(MeshPart(_hull3(v), rgb))
    except Exception as err:  # a library failure on this file: one line naming it
        raise MeshError(f"{path}: cannot process mesh: {type(err).__name__}: {err}") from err
    if not parts:
        raise MeshError(f"{path}: the mesh has no triangles")
    return tuple(parts)


def _hull2(points: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Counter-clockwise 2-D convex hull; None if the points span no area."""
    from scipy.spatial import ConvexHull, QhullError

    pts = np.unique(np.round(points, 9), axis=0)
    if len(pts) < 3:
        return None
    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError):
        return None
    return np.asarray(pts[hull.vertices], dtype=np.float64)


def mesh_outlines(
    parts: tuple[MeshPart, ...],
    pose: Transform3,
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0),
) -> list[MeshOutline]:
    """Place parts (``scale`` in the mesh frame, then ``pose``); one outline per part with
    an area on the ground (a part seen edge-on from above, e.g. a vertical sheet, is
    skipped)."""
    out: list[MeshOutline] = []
    s = np.asarray(scale, dtype=np.float64)
    for part in parts:
        v = pose.apply(part.hull * s)
        hull = _hull2(v[:, :2])
        if hull is None:
            continue
        z0, z1 = float(v[:, 2].min()), float(v[:, 2].max())
        out.append(MeshOutline(hull, z0, z1, part.rgb))
    return out
