"""Load Gazebo ``.world`` / ``.sdf`` files (SDF 1.4 to 1.7, as Gazebo 7 to 11 write them).

What is read:

* every ``<model>`` of the ``<world>`` (static or not, nested models too) and every
  ``<include><uri>model://NAME</uri>`` (its ``<name>`` and ``<pose>`` replace the included
  model's own), with ``<pose>`` of model, link and collision composed; ``<pose frame=...>``
  (SDF 1.5/1.6) and ``relative_to`` (1.7) may name the world, the parent model, a link
  of the same model or an SDF 1.7 ``<frame>`` (of the world, or of the model:
  ``attached_to`` a link, a frame or the model); a nested model's or include's pose may
  name its parent model's links and frames;
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
GUI and the like are ignored silently, except that Gazebo's ``<physics>`` timing and
world plugins are named in :attr:`World.notes`. Robots spawn at the origin, as in Gazebo.

Includes are looked up (first match wins) in: the caller's ``model_path``,
``$ROVERLAB_MODEL_PATH``, ``$GAZEBO_MODEL_PATH``, the world file's folder and its
``models/`` subfolder, ``~/.gazebo/models``, ``~/building_editor_models`` and the models
bundled with roverlab. A model folder holds ``model.config`` (naming its SDF file) and
``model.sdf``.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from roverlab.geometry import SE2, Transform3
from roverlab.world._materials import ScriptMaterial
from roverlab.world._notes import movable_note, world_notes
from roverlab.world._xml import XmlDoc, parse_xml_file
from roverlab.world.errors import WorldError
from roverlab.world.model import (
    DEFAULT_FLOOR_RGB,
    DEFAULT_RGB,
    DEFAULT_SKY_RGB,
    RGB,
    Shape,
    World,
)
from roverlab.world.sdf_shapes import SdfShapeReader, _Geom, _join, _text

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


_Scope = tuple[Callable[[str], Transform3], dict[str, ET.Element]]
"""Frames a pose can name (a resolver to world transforms, and the names it knows)."""


@dataclass(eq=False)
class _State:
    """Poses from a ``<state>`` section (world frame)."""

    pose: Transform3 | None = None
    links: dict[str, Transform3] = field(default_factory=dict)
    models: dict[str, _State] = field(default_factory=dict)


class _SdfLoader(SdfShapeReader):
    def __init__(self, search: list[Path]) -> None:
        self.search = search
        self.warnings: list[str] = []
        self.movable: list[str] = []  # top-level models Gazebo would move (not <static>)
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
            wframes = {f.get("name", ""): f for f in world.findall("frame")}
            scope = self._frame_scope(doc, wframes, _IDENTITY, {}, "world", None)
            self._children(doc, world, _IDENTITY, states, "", scope)
        return World(
            name=name,
            shapes=tuple(self.shapes),
            spawn_poses=(SE2(),),
            gravity=gravity,
            floor_rgb=self.floor_rgb or DEFAULT_FLOOR_RGB,
            sky_rgb=sky,
            source=path,
            warnings=tuple(self.warnings),
            notes=movable_note(path, self.movable)
            + world_notes(path, worlds[0] if worlds else None),
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
        scope: _Scope | None = None,
    ) -> None:
        for child in parent:
            tag = child.tag
            if tag == "model":
                name = child.get("name", "")
                self._model(doc, child, parent_tf, states.get(name), label, name=name, scope=scope)
            elif tag == "include":
                self._include(doc, child, parent_tf, states, label, scope)
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
        scope: _Scope | None = None,
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
        static = _text(el.find("static"))  # an <include>'s <static> replaces the model's
        override = None
        if el.find("pose") is not None:
            pose, frame = self._pose(doc, el, ilabel)
            override = (
                self._frame_base(doc, el, frame, parent_tf, {}, ilabel, *(scope or ())) * pose
            )
        self.include_stack.append(key)
        try:
            self._model(
                inc, model_el, parent_tf, states.get(name), label, name=name,
                world_pose=override, static=static,
            )  # fmt: skip
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
        scope: _Scope | None = None,
        static: str = "",
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
        movable = (static or _text(el.find("static"))).lower() not in ("1", "true")
        if not label and movable and el.find(".//collision") is not None:
            self.movable.append(name)  # Gazebo's physics would move it
        if state is not None and state.pose is not None:
            model_tf = state.pose
        elif world_pose is not None:
            model_tf = world_pose
        else:
            pose, frame = self._pose(doc, el, mlabel)
            base = self._frame_base(doc, el, frame, parent_tf, {}, mlabel, *(scope or ()))
            model_tf = base * pose

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
            base = self._frame_base(doc, lk, frame, model_tf, frames, llabel, *inner)
            link_tfs[lname] = base * pose
            visiting.discard(lname)
            return link_tfs[lname]

        model_frames = {name: model_tf, "__model__": model_tf}
        frame_els = {f.get("name", ""): f for f in el.findall("frame")}
        inner = self._frame_scope(doc, frame_els, model_tf, model_frames, mlabel, (link_tf, links))
        for lname, lk in links.items():
            self._link(
                doc, lk, link_tf(lname), model_tf, name, *inner, _join(mlabel, f"link {lname!r}")
            )  # fmt: skip
        nested_states = state.models if state is not None else {}
        for child in el:
            if child.tag == "model":
                cname = child.get("name", "")
                self._model(
                    doc, child, model_tf, nested_states.get(cname), mlabel, name=cname, scope=inner
                )
            elif child.tag == "include":
                self._include(doc, child, model_tf, nested_states, mlabel, inner)

    def _frame_scope(
        self,
        doc: XmlDoc,
        frame_els: dict[str, ET.Element],
        default: Transform3,
        frames: dict[str, Transform3],
        label: str,
        outer: _Scope | None,
    ) -> _Scope:
        """Names a pose may be ``relative_to``: SDF 1.7 ``<frame>`` elements (``attached_to``
        a link, a frame or the model; the pose is relative to ``attached_to`` unless it
        says otherwise), then ``outer``'s names (the model's links)."""
        names: dict[str, ET.Element] = {**(outer[1] if outer else {}), **frame_els}
        cache: dict[str, Transform3] = {}
        visiting: set[str] = set()

        def resolve(fname: str) -> Transform3:
            if fname not in frame_els:
                assert outer is not None  # only names in ``names`` are resolved
                return outer[0](fname)
            if fname not in cache:
                f = frame_els[fname]
                flabel = _join(label, f"frame {fname!r}")
                if fname in visiting:
                    raise WorldError(f"{doc.where(f)}: {flabel}: pose frames form a cycle")
                visiting.add(fname)
                pose, rel = self._pose(doc, f, flabel)
                base_name = rel or f.get("attached_to") or None
                base = self._frame_base(doc, f, base_name, default, frames, flabel, resolve, names)
                cache[fname] = base * pose
                visiting.discard(fname)
            return cache[fname]

        return (resolve, names)

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
