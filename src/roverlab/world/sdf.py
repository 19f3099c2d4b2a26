"""Load Gazebo ``.world`` / ``.sdf`` files (SDF 1.4 to 1.7, as Gazebo 7 to 11 write them).

What is read:

* every ``<model>`` of the ``<world>`` (static or not, nested models too) and every
  ``<include><uri>model://NAME</uri>`` (its ``<name>`` and ``<pose>`` replace the included
  model's own), with ``<pose>`` of model, link and collision composed; ``<pose frame=...>``
  (SDF 1.5/1.6) and ``relative_to`` (1.7) may name the world, the parent model or a
  link of the same model;
* ``<collision>`` geometry: ``box``, ``cylinder``, ``sphere``, ``polyline`` (a closed,
  extruded outline), ``mesh`` (STL, Collada, OBJ from ``model://``, ``file://`` or a
  relative path, with ``<scale>``: each part's convex outline extruded over its z range,
  see :mod:`roverlab.geometry.mesh`; the mesh's colour when no visual material gives
  one); ``plane`` is the ground (its visual's colour becomes the floor);
* colours from the matching ``<visual>``'s ``<material>``: ``<diffuse>``, then a script
  material (Gazebo's own, e.g. ``Gazebo/Grey``, or one defined in a model's OGRE
  ``.material`` script, whose ``texture`` image is used as a texture), then
  ``<ambient>`` (the Building Editor writes ``Gazebo/Grey`` plus the chosen colour as
  ambient; a white ambient keeps the script's colour);
* the ``<state>`` section that Gazebo's "Save World As" writes: a model's state pose
  replaces its pose and a link's state pose (a world pose) replaces the link's pose,
  as Gazebo does when it loads the world;
* ``<gravity>`` (world or physics) and ``<scene><background>`` (the sky colour).

Building Editor models are plain models: each wall is a link ``Wall_N`` with a box
collision. Robots (models with sensors or plugins), actors, heightmaps, models not found
and other unknown elements are skipped and reported in :attr:`World.warnings` (a missing
``model://NAME`` as ``model NAME skipped: model://X not found``, which
:func:`roverlab.world.group_warnings` groups); lights, physics,
GUI and the like are ignored silently. Robots spawn at the origin, as in Gazebo.

Includes are looked up (first match wins) in: the caller's ``model_path``,
``$ROVERLAB_MODEL_PATH``, ``$GAZEBO_MODEL_PATH``, the world file's folder and its
``models/`` subfolder, ``~/.gazebo/models``, ``~/building_editor_models`` and the models
bundled with roverlab. A model folder holds ``model.config`` (naming its SDF file) and
``model.sdf``.
"""

from __future__ import annotations

import math
import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from roverlab.geometry import SE2, Transform3, quat_from_rpy, quat_normalize
from roverlab.geometry.mesh import MeshError, load_mesh, mesh_outlines
from roverlab.world._materials import GAZEBO_MATERIALS, ScriptMaterial, read_material_script
from roverlab.world._xml import XmlDoc, parse_xml_file
from roverlab.world.errors import WorldError
from roverlab.world.model import (
    DEFAULT_FLOOR_RGB,
    DEFAULT_RGB,
    DEFAULT_SKY_RGB,
    RGB,
    BoxShape,
    CylinderShape,
    PolylineShape,
    Shape,
    SphereShape,
    World,
)

__all__ = ["BUNDLED_MODELS_DIR", "load_sdf", "model_search_path"]

BUNDLED_MODELS_DIR = Path(__file__).resolve().parent / "bundled" / "models"

_IDENTITY = Transform3()

# World children that carry no static geometry: ignored without a warning.
_QUIET_WORLD_TAGS = frozenset(
    {
        "light",
        "state",
        "gui",
        "physics",
        "scene",
        "gravity",
        "magnetic_field",
        "atmosphere",
        "wind",
        "spherical_coordinates",
        "plugin",
        "audio",
        "frame",
        "joint",
        "enable_wind",
    }
)


def _package_model_paths(world_dir: Path) -> list[Path]:
    """``<export><gazebo_ros gazebo_model_path="${prefix}/models"/>`` of the ROS package
    holding the world (the nearest ``package.xml`` up to 3 folders up), which gazebo_ros
    adds to GAZEBO_MODEL_PATH."""
    for folder in [world_dir, *list(world_dir.parents)[:3]]:
        manifest = folder / "package.xml"
        if not manifest.is_file():
            continue
        try:
            root = ET.parse(manifest).getroot()
        except (ET.ParseError, OSError):
            return []
        out: list[Path] = []
        for exp in root.iter("gazebo_ros"):
            for attr in ("gazebo_model_path", "gazebo_media_path"):
                raw = exp.get(attr)
                if raw and attr == "gazebo_model_path":
                    for part in raw.split(os.pathsep):
                        path = part.replace("${prefix}", str(folder)).strip()
                        if path:
                            out.append(Path(path))
        return out
    return []


def model_search_path(
    model_path: Sequence[str | os.PathLike[str]] = (), world_dir: Path | None = None
) -> list[Path]:
    """The folders searched for ``model://NAME``, in order (see the module docstring)."""
    paths: list[Path] = [Path(p) for p in model_path]
    for var in ("ROVERLAB_MODEL_PATH", "GAZEBO_MODEL_PATH"):
        paths += [Path(p) for p in os.environ.get(var, "").split(os.pathsep) if p]
    if world_dir is not None:
        paths += [world_dir, world_dir / "models", *_package_model_paths(world_dir)]
    home = Path.home()
    paths += [home / ".gazebo" / "models", home / "building_editor_models", BUNDLED_MODELS_DIR]
    unique: list[Path] = []
    for p in paths:
        if p not in unique:
            unique.append(p)
    return unique


def load_sdf(
    path: str | os.PathLike[str], *, model_path: Sequence[str | os.PathLike[str]] = ()
) -> World:
    """Load a Gazebo world (``.world``) or SDF model file (``.sdf``) as a :class:`World`.

    A file with models but no ``<world>`` (a ``model.sdf``, e.g. one saved by the
    Building Editor) is loaded as a world holding those models.

    Args:
        path: the ``.world`` / ``.sdf`` file.
        model_path: extra folders searched first for ``model://`` includes.

    Raises:
        WorldError: malformed XML, a missing include, a non-positive or NaN size, a bad
            pose; one line naming the file, line and element.
    """
    p = Path(path)
    loader = _SdfLoader(model_search_path(model_path, p.resolve().parent))
    return loader.load(p)


@dataclass(eq=False)
class _State:
    """Poses from a ``<state>`` section (world frame)."""

    pose: Transform3 | None = None
    links: dict[str, Transform3] = field(default_factory=dict)
    models: dict[str, _State] = field(default_factory=dict)


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


class _SdfLoader:
    def __init__(self, search: list[Path]) -> None:
        self.search = search
        self.warnings: list[str] = []
        self.shapes: list[Shape] = []
        self.floor_rgb: RGB | None = None
        self.include_stack: list[Path] = []
        self.scripts: dict[Path, list[ScriptMaterial]] = {}

    # ------------------------------------------------------------------ entry

    def load(self, path: Path) -> World:
        doc = parse_xml_file(path)
        root = doc.root
        if root.tag != "sdf":
            raise WorldError(f"{doc.where(root)}: root element is <{root.tag}>, expected <sdf>")
        worlds = root.findall("world")
        gravity = (0.0, 0.0, -9.8)
        sky = DEFAULT_SKY_RGB
        if not worlds:
            if root.find("model") is None and root.find("include") is None:
                raise WorldError(f"{doc.where(root)}: <sdf> holds no <world> and no <model>")
            name = path.stem
            self._children(doc, root, _IDENTITY, {}, "")
        else:
            world = worlds[0]
            if len(worlds) > 1:
                self._warn(doc, worlds[1], "more than one <world>: only the first is loaded")
            name = world.get("name") or path.stem
            if name == "default":
                name = path.stem
            states = self._states(doc, world)
            physics_gravity = world.find("physics/gravity")
            if world.find("gravity") is not None:
                gravity = self._vec3(doc, world.find("gravity"), "world / <gravity>")
            elif physics_gravity is not None:
                gravity = self._vec3(doc, physics_gravity, "world / <physics><gravity>")
            background = world.find("scene/background")
            if world.find("scene/sky") is None and background is not None:
                sky = self._colour(doc, background, "world / <scene><background>") or sky
            self._children(doc, world, _IDENTITY, states, "")
        return World(
            name=name,
            shapes=tuple(self.shapes),
            spawn_poses=(SE2(),),
            gravity=gravity,
            floor_rgb=self.floor_rgb or DEFAULT_FLOOR_RGB,
            sky_rgb=sky,
            source=path,
            warnings=tuple(self.warnings),
        )

    def _warn(self, doc: XmlDoc, el: ET.Element, msg: str) -> None:
        self.warnings.append(f"{doc.where(el)}: {msg}")

    def _children(
        self,
        doc: XmlDoc,
        parent: ET.Element,
        parent_tf: Transform3,
        states: dict[str, _State],
        label: str,
    ) -> None:
        for child in parent:
            tag = child.tag
            if tag == "model":
                name = child.get("name", "")
                self._model(doc, child, parent_tf, states.get(name), label, name=name)
            elif tag == "include":
                self._include(doc, child, parent_tf, states, label)
            elif tag == "actor":
                self._warn(doc, child, f"actor {child.get('name', '')!r} skipped (actors move)")
            elif tag in ("population", "road", "road_network"):
                self._warn(doc, child, f"<{tag}> is not supported: skipped")
            elif parent.tag in ("world", "sdf") and tag not in _QUIET_WORLD_TAGS:
                self._warn(doc, child, f"unknown element <{tag}> skipped")

    # ------------------------------------------------------------------ state

    def _states(self, doc: XmlDoc, world: ET.Element) -> dict[str, _State]:
        states: dict[str, _State] = {}
        for state in world.findall("state"):  # the last section wins, as in a log
            for m in state.findall("model"):
                states[m.get("name", "")] = self._model_state(doc, m, "state")
        return states

    def _model_state(self, doc: XmlDoc, el: ET.Element, label: str) -> _State:
        label = _join(label, f"model {el.get('name', '')!r}")
        st = _State()
        if el.find("pose") is not None:
            st.pose = self._pose(doc, el, label)[0]
        scale = el.find("scale")
        if scale is not None:
            values = self._floats(doc, scale, 3, _join(label, "<scale>"))
            if any(abs(v - 1.0) > 1e-9 for v in values):
                self._warn(doc, scale, f"{label}: <scale> {_text(scale)} ignored (scale 1 used)")
        for link in el.findall("link"):
            if link.find("pose") is not None:
                llabel = _join(label, f"link {link.get('name', '')!r}")
                st.links[link.get("name", "")] = self._pose(doc, link, llabel)[0]
        for nested in el.findall("model"):
            st.models[nested.get("name", "")] = self._model_state(doc, nested, label)
        return st

    # ---------------------------------------------------------------- include

    def _include(
        self,
        doc: XmlDoc,
        el: ET.Element,
        parent_tf: Transform3,
        states: dict[str, _State],
        label: str,
    ) -> None:
        uri_el = el.find("uri")
        uri = _text(uri_el)
        ilabel = _join(label, "<include>")
        if uri_el is None or not uri:
            raise WorldError(f"{doc.where(el)}: {ilabel}: needs a <uri>")
        model_dir = self._resolve_uri(uri, doc)
        if model_dir is None or not model_dir.is_dir():
            if uri.startswith("model://"):
                name = _text(el.find("name")) or uri[len("model://") :].split("/")[0]
                self._warn(doc, uri_el, f"model {name} skipped: {uri} not found")
                return
            if "://" in uri and not uri.startswith("file://"):
                raise WorldError(
                    f"{doc.where(uri_el)}: {ilabel}: {uri}: online models are not fetched; "
                    "download the model and add its parent folder to ROVERLAB_MODEL_PATH"
                )
            raise WorldError(f"{doc.where(uri_el)}: {ilabel}: model folder {uri} not found")
        sdf_file = self._model_file(model_dir, doc, uri_el, ilabel)
        key = sdf_file.resolve()
        if key in self.include_stack:
            raise WorldError(f"{doc.where(uri_el)}: {ilabel}: {uri} includes itself")
        inc = parse_xml_file(sdf_file)
        model_el = inc.root.find("model")
        if model_el is None:
            if inc.root.find("actor") is not None:
                self._warn(doc, el, f"{ilabel}: {uri} is an actor: skipped")
            elif inc.root.find("light") is None:
                self._warn(doc, el, f"{ilabel}: {uri} holds no <model>: skipped")
            return
        name = _text(el.find("name")) or model_el.get("name", "")
        override = None
        if el.find("pose") is not None:
            pose, frame = self._pose(doc, el, ilabel)
            override = self._frame_base(doc, el, frame, parent_tf, {}, ilabel) * pose
        self.include_stack.append(key)
        try:
            self._model(
                inc, model_el, parent_tf, states.get(name), label, name=name, world_pose=override
            )
        finally:
            self.include_stack.pop()

    def _find_model(self, name: str) -> Path | None:
        for base in self.search:
            d = base / name
            if (d / "model.config").is_file() or (d / "model.sdf").is_file():
                return d
        return None

    def _resolve_uri(self, uri: str, doc: XmlDoc) -> Path | None:
        """A model:// or file:// URI (or a plain path) as a local path; None if unknown."""
        if uri.startswith("model://"):
            name, _, rest = uri[len("model://") :].partition("/")
            d = self._find_model(name)
            return None if d is None else (d / rest if rest else d)
        if uri.startswith("file://"):
            rest = uri[len("file://") :]
            if rest.startswith("media/"):  # Gazebo's own media folder: not available
                return None
            p = Path(rest)
        elif "://" in uri:
            return None
        else:
            p = Path(uri)
        return p if p.is_absolute() else doc.path.resolve().parent / p

    def _model_file(self, model_dir: Path, doc: XmlDoc, el: ET.Element, label: str) -> Path:
        config = model_dir / "model.config"
        if config.is_file():
            cfg = parse_xml_file(config)
            best: tuple[tuple[int, ...], str] | None = None
            for sdf in cfg.root.iter("sdf"):
                try:
                    version = tuple(int(v) for v in sdf.get("version", "0").split("."))
                except ValueError:
                    version = (0,)
                if _text(sdf) and (best is None or version > best[0]):
                    best = (version, _text(sdf))
            if best is None:
                raise WorldError(f"{cfg.where(cfg.root)}: model.config names no <sdf> file")
            f = model_dir / best[1]
            if not f.is_file():
                raise WorldError(
                    f"{cfg.where(cfg.root)}: <sdf> file {best[1]} not found in {model_dir}"
                )
            return f
        f = model_dir / "model.sdf"
        if f.is_file():
            return f
        raise WorldError(
            f"{doc.where(el)}: {label}: {model_dir} holds no model.config or model.sdf"
        )

    # ------------------------------------------------------------------ model

    def _model(
        self,
        doc: XmlDoc,
        el: ET.Element,
        parent_tf: Transform3,
        state: _State | None,
        label: str,
        *,
        name: str,
        world_pose: Transform3 | None = None,
    ) -> None:
        mlabel = _join(label, f"model {name!r}")
        robot_signs = [t for t in ("sensor", "plugin") if next(el.iter(t), None) is not None]
        if robot_signs:
            self._warn(
                doc,
                el,
                f"{mlabel} has <{robot_signs[0]}> elements, so it is taken for a robot: skipped",
            )
            return
        if state is not None and state.pose is not None:
            model_tf = state.pose
        elif world_pose is not None:
            model_tf = world_pose
        else:
            pose, frame = self._pose(doc, el, mlabel)
            model_tf = self._frame_base(doc, el, frame, parent_tf, {}, mlabel) * pose

        links = {lk.get("name", ""): lk for lk in el.findall("link")}
        link_tfs: dict[str, Transform3] = {}
        visiting: set[str] = set()

        def link_tf(lname: str) -> Transform3:
            if lname in link_tfs:
                return link_tfs[lname]
            if state is not None and lname in state.links:
                link_tfs[lname] = state.links[lname]
                return link_tfs[lname]
            lk = links[lname]
            llabel = _join(mlabel, f"link {lname!r}")
            if lname in visiting:
                raise WorldError(f"{doc.where(lk)}: {llabel}: pose frames form a cycle")
            visiting.add(lname)
            pose, frame = self._pose(doc, lk, llabel)
            frames = {name: model_tf, "__model__": model_tf}
            base = self._frame_base(doc, lk, frame, model_tf, frames, llabel, link_tf, links)
            link_tfs[lname] = base * pose
            visiting.discard(lname)
            return link_tfs[lname]

        for lname, lk in links.items():
            self._link(
                doc,
                lk,
                link_tf(lname),
                model_tf,
                name,
                link_tf,
                links,
                _join(mlabel, f"link {lname!r}"),
            )
        nested_states = state.models if state is not None else {}
        for child in el:
            if child.tag == "model":
                cname = child.get("name", "")
                self._model(doc, child, model_tf, nested_states.get(cname), mlabel, name=cname)
            elif child.tag == "include":
                self._include(doc, child, model_tf, nested_states, mlabel)

    def _frame_base(
        self,
        doc: XmlDoc,
        el: ET.Element,
        frame: str | None,
        default: Transform3,
        frames: dict[str, Transform3],
        label: str,
        link_tf: Callable[[str], Transform3] | None = None,
        links: dict[str, ET.Element] | None = None,
    ) -> Transform3:
        """The world transform of the frame a pose is expressed in."""
        if not frame:
            return default
        if frame == "world":
            return _IDENTITY
        if frame in frames:
            return frames[frame]
        if link_tf is not None and links is not None and frame in links:
            return link_tf(frame)
        self._warn(doc, el, f"{label}: pose frame {frame!r} not understood: parent frame used")
        return default

    def _link(
        self,
        doc: XmlDoc,
        link: ET.Element,
        ltf: Transform3,
        model_tf: Transform3,
        model_name: str,
        link_tf: Callable[[str], Transform3],
        links: dict[str, ET.Element],
        label: str,
    ) -> None:
        frames = {model_name: model_tf, "__model__": model_tf, link.get("name", ""): ltf}
        visuals: list[tuple[ET.Element, Transform3, list[_Geom]]] = []
        for vis in link.findall("visual"):
            vlabel = _join(label, f"visual {vis.get('name', '')!r}")
            pose, frame = self._pose(doc, vis, vlabel)
            vtf = self._frame_base(doc, vis, frame, ltf, frames, vlabel, link_tf, links) * pose
            visuals.append((vis, vtf, self._geometry(doc, vis, vlabel, quiet=True)))
        collisions = link.findall("collision")
        for col in collisions:
            clabel = _join(label, f"collision {col.get('name', '')!r}")
            pose, frame = self._pose(doc, col, clabel)
            ctf = self._frame_base(doc, col, frame, ltf, frames, clabel, link_tf, links) * pose
            for geom in self._geometry(doc, col, clabel, quiet=False):
                rgb, texture = self._visual_colour(doc, geom, ctf, visuals, label)
                if geom.kind == "plane":
                    if self.floor_rgb is None and rgb is not None:
                        self.floor_rgb = rgb
                    continue
                if geom.parts is not None:
                    self.shapes.extend(geom.parts(ctf, rgb, col.get("name", "")))
                    continue
                assert geom.shape is not None
                self.shapes.append(
                    geom.shape(ctf, rgb or DEFAULT_RGB, texture, col.get("name", ""))
                )
        if not collisions and any(g.kind != "plane" for _, _, gs in visuals for g in gs):
            self._warn(doc, link, f"{label} has visuals but no <collision>: not in the scene")
        if not collisions:
            for vis, vtf, geoms in visuals:
                for g in geoms:
                    if g.kind == "plane" and self.floor_rgb is None:
                        rgb, _ = self._visual_colour(doc, g, vtf, [(vis, vtf, [g])], label)
                        self.floor_rgb = rgb

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
