"""Collada files shaped like Gazebo model-database models, written into a test's tmp_path.

The database's meshes (dumpster, jersey_barrier, ...) are exports from modelling tools:
several ``<geometry>`` elements, nested ``<node>``\\ s with ``<matrix>`` transforms, quads in
``<polylist>`` beside ``<triangles>``, a unit other than the metre, ``Y_UP``, and open
surfaces (a bin without a top, an extruded profile without end caps) rather than closed
solids. :func:`write_model` writes a model folder (``model.config``, ``model.sdf``,
``meshes/NAME.dae``) from parts given in metres with +z up; the file stores them in its
own unit and up axis, so what a loader reads back can be compared in metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["ColladaPart", "boxes", "collada_text", "open_bin", "open_profile", "write_model"]


@dataclass(frozen=True)
class ColladaPart:
    """One ``<geometry>``: vertices (n, 3) in metres, +z up; polygons as vertex index
    lists (3 -> triangle, 4 -> quad); placed by the node translation ``at`` (metres);
    ``nested`` puts its node inside the previous part's node (the translation adds up)."""

    vertices: np.ndarray
    polygons: list[list[int]]
    rgb: tuple[float, float, float]
    at: tuple[float, float, float] = (0.0, 0.0, 0.0)
    nested: bool = False


def _box_quads(base: int) -> list[list[int]]:
    # vertices 0-3: bottom (z0) counter-clockwise, 4-7: top (z1)
    sides = [[base + i, base + (i + 1) % 4, base + 4 + (i + 1) % 4, base + 4 + i] for i in range(4)]
    return [[base + 3, base + 2, base + 1, base], *sides, [base + 4, base + 5, base + 6, base + 7]]


def _box_vertices(lo: tuple[float, float, float], hi: tuple[float, float, float]) -> np.ndarray:
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    ring = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return np.array([(x, y, z0) for x, y in ring] + [(x, y, z1) for x, y in ring])


def open_bin(size: tuple[float, float, float], rgb: tuple[float, float, float]) -> ColladaPart:
    """A box of ``size`` standing on z = 0, centred in x and y, with no top face (a hole)."""
    sx, sy, sz = size
    v = _box_vertices((-sx / 2, -sy / 2, 0.0), (sx / 2, sy / 2, sz))
    return ColladaPart(v, _box_quads(0)[:5], rgb)


def boxes(
    corners: list[tuple[tuple[float, float, float], tuple[float, float, float]]],
    rgb: tuple[float, float, float],
    *,
    at: tuple[float, float, float] = (0.0, 0.0, 0.0),
    nested: bool = False,
) -> ColladaPart:
    """Closed boxes (low, high corners), disjoint pieces of one geometry, as triangles."""
    verts = [_box_vertices(lo, hi) for lo, hi in corners]
    tris: list[list[int]] = []
    for k in range(len(corners)):
        for q in _box_quads(8 * k):
            tris += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    return ColladaPart(np.concatenate(verts), tris, rgb, at, nested)


def open_profile(
    profile: list[tuple[float, float]], length: float, rgb: tuple[float, float, float]
) -> ColladaPart:
    """The (y, z) outline ``profile`` swept along x over ``length`` (centred), with no
    end caps: a tube open at both ends, as a jersey barrier's exported surface."""
    n = len(profile)
    v = [(-length / 2, y, z) for y, z in profile] + [(length / 2, y, z) for y, z in profile]
    quads = [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return ColladaPart(np.array(v, dtype=np.float64), quads, rgb)


def _to_file(points: np.ndarray, unit_m: float, up: str) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64) / unit_m
    if up == "Y_UP":  # +z up -> +y up: (x, y, z) -> (x, z, -y)
        p = np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1)
    return p


def _floats(a: np.ndarray) -> str:
    return " ".join(f"{x:.6g}" for x in np.asarray(a).reshape(-1))


def _geometry(i: int, part: ColladaPart, unit_m: float, up: str) -> str:
    v = _to_file(part.vertices, unit_m, up)
    gid = f"geom{i}"
    if all(len(p) == 3 for p in part.polygons):
        prims = (
            f'<triangles material="mat{i}" count="{len(part.polygons)}">'
            f'<input semantic="VERTEX" source="#{gid}-vtx" offset="0"/>'
            f"<p>{' '.join(str(k) for p in part.polygons for k in p)}</p></triangles>"
        )
    else:
        prims = (
            f'<polylist material="mat{i}" count="{len(part.polygons)}">'
            f'<input semantic="VERTEX" source="#{gid}-vtx" offset="0"/>'
            f"<vcount>{' '.join(str(len(p)) for p in part.polygons)}</vcount>"
            f"<p>{' '.join(str(k) for p in part.polygons for k in p)}</p></polylist>"
        )
    return (
        f'<geometry id="{gid}" name="{gid}"><mesh>'
        f'<source id="{gid}-pos"><float_array id="{gid}-pos-array" count="{v.size}">'
        f"{_floats(v)}</float_array><technique_common>"
        f'<accessor source="#{gid}-pos-array" count="{len(v)}" stride="3">'
        '<param name="X" type="float"/><param name="Y" type="float"/>'
        '<param name="Z" type="float"/></accessor></technique_common></source>'
        f'<vertices id="{gid}-vtx"><input semantic="POSITION" source="#{gid}-pos"/></vertices>'
        f"{prims}</mesh></geometry>"
    )


def _node(i: int, part: ColladaPart, unit_m: float, up: str, inner: str) -> str:
    m = np.eye(4)
    m[:3, 3] = _to_file(np.array([part.at]), unit_m, up)[0]
    return (
        f'<node id="node{i}" name="node{i}"><matrix>{_floats(m)}</matrix>'
        f'<instance_geometry url="#geom{i}"><bind_material><technique_common>'
        f'<instance_material symbol="mat{i}" target="#mat{i}"/>'
        f"</technique_common></bind_material></instance_geometry>{inner}</node>"
    )


def collada_text(parts: list[ColladaPart], *, unit_m: float = 1.0, up: str = "Z_UP") -> str:
    """The Collada document of ``parts`` (see :class:`ColladaPart`)."""
    effects = "".join(
        f'<effect id="fx{i}"><profile_COMMON><technique sid="common"><phong><diffuse>'
        f"<color>{p.rgb[0]} {p.rgb[1]} {p.rgb[2]} 1</color></diffuse></phong></technique>"
        f"</profile_COMMON></effect>"
        for i, p in enumerate(parts)
    )
    materials = "".join(
        f'<material id="mat{i}" name="mat{i}"><instance_effect url="#fx{i}"/></material>'
        for i in range(len(parts))
    )
    geometries = "".join(_geometry(i, p, unit_m, up) for i, p in enumerate(parts))
    # nodes, innermost first: a nested part goes inside the node of the part before it
    nodes: list[str] = []
    inner = ""
    for i in range(len(parts) - 1, -1, -1):
        inner = _node(i, parts[i], unit_m, up, inner)
        if not parts[i].nested:
            nodes.insert(0, inner)
            inner = ""
    return (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        f'<asset><unit meter="{unit_m}" name="unit"/><up_axis>{up}</up_axis></asset>'
        f"<library_effects>{effects}</library_effects>"
        f"<library_materials>{materials}</library_materials>"
        f"<library_geometries>{geometries}</library_geometries>"
        '<library_visual_scenes><visual_scene id="scene" name="scene">'
        f"{''.join(nodes)}</visual_scene></library_visual_scenes>"
        '<scene><instance_visual_scene url="#scene"/></scene></COLLADA>\n'
    )


def write_model(
    models: Path, name: str, parts: list[ColladaPart], *, unit_m: float = 1.0, up: str = "Z_UP"
) -> Path:
    """``models/NAME/{model.config, model.sdf, meshes/NAME.dae}`` as in Gazebo's model
    database (the mesh both collision and visual); returns the .dae's path."""
    folder = models / name
    (folder / "meshes").mkdir(parents=True, exist_ok=True)
    dae = folder / "meshes" / f"{name}.dae"
    dae.write_text(collada_text(parts, unit_m=unit_m, up=up))
    (folder / "model.config").write_text(
        f'<?xml version="1.0"?>\n<model><name>{name}</name><version>1.0</version>'
        "<sdf version='1.5'>model.sdf</sdf></model>\n"
    )
    uri = f"model://{name}/meshes/{name}.dae"
    geometry = f"<geometry><mesh><uri>{uri}</uri></mesh></geometry>"
    (folder / "model.sdf").write_text(
        f'<?xml version="1.0" ?>\n<sdf version="1.5"><model name="{name}"><static>true</static>'
        f'<link name="link"><collision name="collision">{geometry}</collision>'
        f'<visual name="visual">{geometry}</visual></link></model></sdf>\n'
    )
    return dae
