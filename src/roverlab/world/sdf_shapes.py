"""SDF element readers for shapes: geometries (box, cylinder, sphere, plane, polyline,
mesh), visual colours and materials (``<ambient>``/``<diffuse>``, Gazebo material scripts),
poses and checked numbers. :class:`SdfShapeReader` is the part of the SDF loader
(:mod:`roverlab.world.sdf`) that turns one element into shapes; the loader walks the
world, its models, links and includes.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from roverlab.geometry import Transform3, quat_from_rpy, quat_normalize
from roverlab.geometry.mesh import MeshError, load_mesh, mesh_outlines
from roverlab.world._materials import GAZEBO_MATERIALS, ScriptMaterial, read_material_script
from roverlab.world._xml import XmlDoc
from roverlab.world.errors import WorldError
from roverlab.world.model import (
    DEFAULT_RGB,
    RGB,
    BoxShape,
    CylinderShape,
    PolylineShape,
    Shape,
    SphereShape,
)

__all__ = ["SdfShapeReader"]

_IDENTITY = Transform3()


@dataclass(frozen=True, eq=False)
class _Geom:
    kind: str
    shape: Callable[[Transform3, RGB, Path | None, str], Shape] | None
    signature: tuple[object, ...]
    # a mesh: (world pose, visual colour or None, name) -> its parts' shapes
    parts: Callable[[Transform3, RGB | None, str], list[Shape]] | None = None


def _join(label: str, part: str) -> str:
    return f"{label} / {part}" if label else part


def _text(el: ET.Element | None) -> str:
    return " ".join((el.text or "").split()) if el is not None else ""


class SdfShapeReader:
    """Element readers shared by the SDF loader; it provides ``_warn`` and ``_resolve_uri``."""

    scripts: dict[Path, list[ScriptMaterial]]

    def _warn(self, doc: XmlDoc, el: ET.Element, msg: str) -> None:
        raise NotImplementedError

    def _resolve_uri(self, uri: str, doc: XmlDoc) -> Path | None:
        raise NotImplementedError

    def _visual_colour(
        self,
        doc: XmlDoc,
        geom: _Geom,
        ctf: Transform3,
        visuals: list[tuple[ET.Element, Transform3, list[_Geom]]],
        label: str,
    ) -> tuple[RGB | None, Path | None]:
        """Colour (and texture) of the visual that best matches a collision geometry."""
        if not visuals:
            return None, None

        def same_pose(a: Transform3, b: Transform3) -> bool:
            return all(
                abs(x - y) < 1e-6 for x, y in zip(a.translation, b.translation, strict=True)
            ) and (
                abs(abs(sum(x * y for x, y in zip(a.rotation, b.rotation, strict=True))) - 1.0)
                < 1e-9
            )

        ranked = sorted(
            visuals,
            key=lambda v: (
                not any(g.signature == geom.signature for g in v[2]),
                not same_pose(v[1], ctf),
                not any(g.kind == geom.kind for g in v[2]),
            ),
        )
        vis = ranked[0][0]
        mat = vis.find("material")
        if mat is None:
            return None, None
        return self._material(doc, mat, _join(label, f"visual {vis.get('name', '')!r}"))

    # --------------------------------------------------------------- material

    def _material(self, doc: XmlDoc, mat: ET.Element, label: str) -> tuple[RGB | None, Path | None]:
        diffuse = self._colour(doc, mat.find("diffuse"), _join(label, "<diffuse>"))
        ambient = self._colour(doc, mat.find("ambient"), _join(label, "<ambient>"))
        script = mat.find("script")
        script_rgb: RGB | None = None
        texture: Path | None = None
        sname = _text(script.find("name")) if script is not None else ""
        if script is not None and sname and sname != "__default__":
            found = self._script_material(doc, script, sname)
            if found is not None:
                script_rgb, texture = found
            else:
                script_rgb = GAZEBO_MATERIALS.get(sname.lower())
                if script_rgb is None and diffuse is None and ambient is None:
                    self._warn(
                        doc, script, f"{label}: unknown material {sname!r}: default colour used"
                    )
        if diffuse is not None:
            return diffuse, texture
        if script_rgb is not None and (ambient is None or ambient == (255, 255, 255) or texture):
            return script_rgb, texture
        return ambient or script_rgb, texture

    def _script_material(
        self, doc: XmlDoc, script: ET.Element, sname: str
    ) -> tuple[RGB | None, Path | None] | None:
        """A material defined in the script files of ``<uri>``s: (rgb, texture path)."""
        dirs: list[Path] = []
        files: list[Path] = []
        for u in script.findall("uri"):
            p = self._resolve_uri(_text(u), doc)
            if p is None:
                continue
            if p.is_dir():
                dirs.append(p)
                files += sorted(p.glob("*.material"))
            elif p.is_file():
                files.append(p)
        table: dict[str, tuple[ScriptMaterial, Path]] = {}
        for f in files:
            if f not in self.scripts:
                self.scripts[f] = read_material_script(f)
            for m in self.scripts[f]:
                table.setdefault(m.name, (m, f))
        if sname not in table:
            return None
        rgb: RGB | None = None
        tex_name: Path | None = None
        script_file: Path | None = None
        current: str | None = sname
        seen: set[str] = set()
        while current and current in table and current not in seen:
            seen.add(current)
            m, f = table[current]
            rgb = rgb or m.rgb
            if tex_name is None and m.texture is not None:
                tex_name, script_file = m.texture, f
            current = m.parent
        if rgb is None and current:
            rgb = GAZEBO_MATERIALS.get(current.lower())
        texture: Path | None = None
        if tex_name is not None and script_file is not None:
            candidates = [d / tex_name for d in dirs]
            candidates += [
                script_file.parent / tex_name,
                script_file.parent.parent / "textures" / tex_name,
            ]
            texture = next((c for c in candidates if c.is_file()), None)
            if texture is None:
                self._warn(doc, script, f"texture {tex_name} of material {sname!r} not found")
        return rgb, texture

    # --------------------------------------------------------------- geometry

    def _geometry(self, doc: XmlDoc, el: ET.Element, label: str, *, quiet: bool) -> list[_Geom]:
        g = el.find("geometry")
        if g is None or len(g) == 0:
            if not quiet:
                self._warn(doc, el, f"{label} has no <geometry>: skipped")
            return []
        shape_el = g[0]
        kind = shape_el.tag
        glabel = _join(label, f"<{kind}>")
        if kind == "box":
            size = self._positive(doc, shape_el, "size", 3, (1.0, 1.0, 1.0), glabel)
            return [
                _Geom(
                    kind,
                    lambda tf, rgb, tex, nm: BoxShape(
                        pose=tf, size=(size[0], size[1], size[2]), rgb=rgb, texture=tex, name=nm
                    ),
                    (kind, *size),
                )
            ]
        if kind == "cylinder":
            (r,) = self._positive(doc, shape_el, "radius", 1, (1.0,), glabel)
            (length,) = self._positive(doc, shape_el, "length", 1, (1.0,), glabel)
            return [
                _Geom(
                    kind,
                    lambda tf, rgb, tex, nm: CylinderShape(
                        pose=tf, radius=r, length=length, rgb=rgb, name=nm
                    ),
                    (kind, r, length),
                )
            ]
        if kind == "sphere":
            (sr,) = self._positive(doc, shape_el, "radius", 1, (1.0,), glabel)
            return [
                _Geom(
                    kind,
                    lambda tf, rgb, tex, nm: SphereShape(pose=tf, radius=sr, rgb=rgb, name=nm),
                    (kind, sr),
                )
            ]
        if kind == "polyline":
            out: list[_Geom] = []
            for pl in g.findall("polyline"):
                out.append(self._polyline(doc, pl, glabel))
            return out
        if kind == "plane":
            return [_Geom(kind, None, (kind,))]
        if kind == "mesh":
            return self._mesh(doc, shape_el, glabel, quiet=quiet)
        if not quiet:
            self._warn(doc, shape_el, f"{label}: <{kind}> geometry is not supported: skipped")
        return []

    def _mesh(self, doc: XmlDoc, el: ET.Element, label: str, *, quiet: bool) -> list[_Geom]:
        uri = _text(el.find("uri"))
        if not uri:
            raise WorldError(f"{doc.where(el)}: {label}: <mesh> needs a <uri>")
        scale_el = el.find("scale")
        scale = (1.0, 1.0, 1.0)
        if scale_el is not None:
            sx, sy, sz = self._floats(doc, scale_el, 3, _join(label, "<scale>"))
            scale = (sx, sy, sz)
        signature = ("mesh", uri, *scale)
        if quiet:  # a visual: only its signature matters (which collision it colours)
            return [_Geom("mesh", None, signature)]
        if el.find("submesh") is not None:
            self._warn(doc, el, f"{label}: <submesh> ignored: the whole mesh {uri} is used")
        path = self._resolve_uri(uri, doc)
        if path is None or not path.is_file():
            self._warn(doc, el, f"{label}: mesh {uri} not found: skipped")
            return []
        try:
            parts = load_mesh(path)
        except MeshError as err:
            self._warn(doc, el, f"{label}: {err}: skipped")
            return []

        def shapes(tf: Transform3, rgb: RGB | None, name: str) -> list[Shape]:
            out: list[Shape] = []
            for o in mesh_outlines(parts, tf, scale):
                height = o.z_max - o.z_min
                if height < 1e-3:
                    continue  # a flat sheet: nothing stands up from the floor
                out.append(
                    PolylineShape(
                        pose=Transform3((0.0, 0.0, o.z_min)),
                        points=tuple((float(x), float(y)) for x, y in o.points),
                        height=height,
                        rgb=rgb or o.rgb or DEFAULT_RGB,
                        name=name,
                    )
                )
            return out

        return [_Geom("mesh", None, signature, shapes)]

    def _polyline(self, doc: XmlDoc, pl: ET.Element, label: str) -> _Geom:
        (height,) = self._positive(doc, pl, "height", 1, (1.0,), label)
        pts: list[tuple[float, float]] = []
        for pt in pl.findall("point"):
            x, y = self._floats(doc, pt, 2, _join(label, "<point>"))
            pts.append((x, y))
        if len({p for p in pts}) < 3:
            raise WorldError(
                f"{doc.where(pl)}: {label}: needs at least 3 distinct <point>s, got {len(pts)}"
            )
        points = tuple(pts)
        return _Geom(
            "polyline",
            lambda tf, rgb, tex, nm: PolylineShape(
                pose=tf, points=points, height=height, rgb=rgb, name=nm
            ),
            ("polyline", height, *points),
        )

    # ---------------------------------------------------------------- numbers

    def _floats(self, doc: XmlDoc, el: ET.Element, n: int, label: str) -> tuple[float, ...]:
        raw = _text(el)
        try:
            vals = tuple(float(v) for v in raw.split())
        except ValueError:
            vals = ()
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise WorldError(f"{doc.where(el)}: {label}: needs {n} finite numbers, got {raw!r}")
        return vals

    def _positive(
        self,
        doc: XmlDoc,
        parent: ET.Element,
        tag: str,
        n: int,
        default: tuple[float, ...],
        label: str,
    ) -> tuple[float, ...]:
        el = parent.find(tag)
        if el is None:
            return default
        raw = _text(el)
        try:
            vals = tuple(float(v) for v in raw.split())
        except ValueError:
            vals = ()
        if len(vals) != n or not all(math.isfinite(v) and v > 0.0 for v in vals):
            what = "a positive number" if n == 1 else f"{n} positive numbers"
            raise WorldError(
                f"{doc.where(el)}: {_join(label, f'<{tag}>')}: needs {what}, got {raw!r}"
            )
        return vals

    def _vec3(self, doc: XmlDoc, el: ET.Element | None, label: str) -> tuple[float, float, float]:
        assert el is not None
        x, y, z = self._floats(doc, el, 3, label)
        return (x, y, z)

    def _colour(self, doc: XmlDoc, el: ET.Element | None, label: str) -> RGB | None:
        if el is None:
            return None
        raw = _text(el)
        try:
            vals = [float(v) for v in raw.split()]
        except ValueError:
            vals = []
        if len(vals) not in (3, 4) or not all(math.isfinite(v) for v in vals):
            raise WorldError(
                f"{doc.where(el)}: {label}: needs 3 or 4 numbers r g b [a], got {raw!r}"
            )
        r, g, b = (round(min(1.0, max(0.0, v)) * 255) for v in vals[:3])
        return (r, g, b)

    def _pose(self, doc: XmlDoc, parent: ET.Element, label: str) -> tuple[Transform3, str | None]:
        """The ``<pose>`` child of ``parent`` and the frame it is expressed in."""
        el = parent.find("pose")
        if el is None:
            return _IDENTITY, None
        frame = el.get("relative_to", el.get("frame"))
        raw = _text(el)
        if not raw:
            return _IDENTITY, frame
        try:
            vals = [float(v) for v in raw.split()]
        except ValueError:
            vals = []
        quat = el.get("rotation_format", "euler_rpy") == "quat_xyzw"
        n = 7 if quat else 6
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise WorldError(
                f"{doc.where(el)}: {_join(label, '<pose>')}: needs {n} finite numbers, got {raw!r}"
            )
        if quat:
            try:
                q = quat_normalize(vals[3:7])
            except ValueError as err:
                raise WorldError(f"{doc.where(el)}: {_join(label, '<pose>')}: {err}") from err
        else:
            rpy = vals[3:6]
            if el.get("degrees", "false").strip().lower() in ("true", "1"):
                rpy = [math.radians(v) for v in rpy]
            q = quat_from_rpy(*rpy)
        return Transform3.from_arrays(vals[:3], q), frame
