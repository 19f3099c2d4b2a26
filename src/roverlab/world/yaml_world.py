"""A small YAML world format, for users who would rather not write SDF.

Every key is optional; lengths in metres, angles in radians, colours ``[r, g, b]`` in
0..255, images relative to the YAML file. Unknown keys are errors. Example::

    name: office                      # default: the file name without suffix
    floor_rgb: [110, 110, 110]
    sky_rgb: [178, 204, 229]
    gravity: [0, 0, -9.8]
    walls:                            # wall boxes along a centre line
      - {from: [0, 0], to: [10, 0], thickness: 0.1, height: 2.5, rgb: [200, 200, 200]}
      - {points: [[0, 0], [0, 8], [10, 8]], closed: false}     # a chain of walls
    boxes:                            # standing on the floor, or on `z`
      - {center: [3, 2], size: [1, 0.6, 0.75], yaw: 0.3, rgb: [150, 100, 60], name: desk}
    cylinders:
      - {center: [5, 5], radius: 0.2, height: 1.0}
    polygons:                         # an extruded closed outline (SDF polyline)
      - {points: [[6, 1], [7, 1], [6.5, 2]], height: 0.5}
    posters:                          # an image on a wall face, seen by cameras
      - {image: face.png, from: [2, 4.95], to: [3, 4.95], z: [1.0, 2.0]}
    spawn: {x: 1.0, y: 1.0, yaw: 0.0}  # or a list of poses; default x=y=yaw=0

Defaults: walls ``thickness: 0.1``, ``height: 2.5``; boxes, cylinders and polygons stand
on ``z: 0``; ``yaw: 0``; colour ``[200, 200, 200]``. A wall runs from ``from`` to ``to``
and is extended by half its thickness at each end so that walls meeting at a corner
close it. A box may carry ``texture: image.png`` (drawn on its four sides). A poster's
image reads left to right from ``from`` to ``to`` as seen by a viewer facing it; it has
no thickness and is visual only (place it a little in front of its wall).
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from roverlab.geometry import SE2
from roverlab.world.errors import WorldError
from roverlab.world.model import (
    DEFAULT_FLOOR_RGB,
    DEFAULT_RGB,
    DEFAULT_SKY_RGB,
    RGB,
    BoxShape,
    CylinderShape,
    PolylineShape,
    PosterShape,
    Shape,
    World,
)

__all__ = ["load_yaml_world", "read_yaml", "world_from_dict"]

_TOP_KEYS = (
    "name",
    "floor_rgb",
    "sky_rgb",
    "gravity",
    "walls",
    "boxes",
    "cylinders",
    "polygons",
    "posters",
    "spawn",
)
_WALL_KEYS = ("from", "to", "points", "closed", "thickness", "height", "z", "rgb", "name")
_BOX_KEYS = ("center", "size", "yaw", "z", "rgb", "texture", "name")
_CYL_KEYS = ("center", "radius", "height", "z", "rgb", "name")
_POLY_KEYS = ("points", "height", "z", "rgb", "name")
_POSTER_KEYS = ("image", "from", "to", "z", "name")
_SPAWN_KEYS = ("x", "y", "yaw")

DEFAULT_WALL_THICKNESS = 0.1
DEFAULT_WALL_HEIGHT = 2.5


def read_yaml(path: Path) -> Any:
    """Parse a YAML file; errors name the file (and line for syntax errors)."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise WorldError(f"{path}: cannot read: {err.strerror or err}") from err
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark is not None else str(path)
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise WorldError(f"{where}: malformed YAML: {problem}") from err


def load_yaml_world(path: str | os.PathLike[str]) -> World:
    """Load a YAML world file (format in the module docstring).

    Raises:
        WorldError: unreadable file, malformed YAML, an unknown key, a bad value; one line
            naming the file and the key.
    """
    p = Path(path)
    return world_from_dict(read_yaml(p), source=p)


def world_from_dict(data: Any, *, source: Path) -> World:
    """Build a World from parsed YAML ``data``; ``source`` names the file in errors and
    is the folder images are relative to."""
    return _Reader(source).world(data)


def _key(ctx: str, key: str) -> str:
    return f"{ctx}.{key}" if ctx else key


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path
        self.base = path.resolve().parent

    def fail(self, ctx: str, msg: str) -> WorldError:
        return WorldError(f"{self.path}: {ctx}: {msg}" if ctx else f"{self.path}: {msg}")

    def mapping(self, value: Any, ctx: str, allowed: tuple[str, ...]) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.fail(ctx, f"must be a mapping of keys, got {type(value).__name__}")
        for key in value:
            if key not in allowed:
                raise self.fail(ctx, f"unknown key {key!r} (allowed: {', '.join(allowed)})")
        return value

    def items(self, data: Mapping[str, Any], key: str) -> list[Any]:
        value = data.get(key)
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.fail(key, f"must be a list, got {type(value).__name__}")
        return value

    def number(
        self, d: Mapping[str, Any], key: str, ctx: str, default: float | None = None
    ) -> float:
        value = d.get(key, default)
        if value is None:
            raise self.fail(ctx, f"missing key {key!r}")
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise self.fail(_key(ctx, key), f"must be a finite number, got {value!r}")
        return float(value)

    def positive(
        self, d: Mapping[str, Any], key: str, ctx: str, default: float | None = None
    ) -> float:
        v = self.number(d, key, ctx, default)
        if v <= 0.0:
            raise self.fail(_key(ctx, key), f"must be positive, got {d.get(key)!r}")
        return v

    def numbers(self, value: Any, n: int, ctx: str) -> tuple[float, ...]:
        if (
            not isinstance(value, list | tuple)
            or len(value) != n
            or not all(
                isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                for v in value
            )
        ):
            raise self.fail(ctx, f"must be a list of {n} finite numbers, got {value!r}")
        return tuple(float(v) for v in value)

    def pair(self, d: Mapping[str, Any], key: str, ctx: str) -> tuple[float, float]:
        if key not in d:
            raise self.fail(ctx, f"missing key {key!r}")
        x, y = self.numbers(d[key], 2, _key(ctx, key))
        return (x, y)

    def points(self, d: Mapping[str, Any], ctx: str, minimum: int) -> list[tuple[float, float]]:
        raw = d.get("points")
        if not isinstance(raw, list) or len(raw) < minimum:
            raise self.fail(f"{ctx}.points", f"must be a list of at least {minimum} [x, y] points")
        out: list[tuple[float, float]] = []
        for i, p in enumerate(raw):
            x, y = self.numbers(p, 2, f"{ctx}.points[{i}]")
            out.append((x, y))
        return out

    def rgb(self, d: Mapping[str, Any], key: str, ctx: str, default: RGB) -> RGB:
        value = d.get(key)
        if value is None:
            return default
        if (
            not isinstance(value, list | tuple)
            or len(value) != 3
            or not all(
                isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 255 for v in value
            )
        ):
            raise self.fail(_key(ctx, key), f"must be [r, g, b] integers in 0..255, got {value!r}")
        return (int(value[0]), int(value[1]), int(value[2]))

    def name(self, d: Mapping[str, Any], ctx: str, default: str = "") -> str:
        value = d.get("name", default)
        if not isinstance(value, str):
            raise self.fail(_key(ctx, "name"), f"must be a string, got {value!r}")
        return value

    def image(self, d: Mapping[str, Any], key: str, ctx: str) -> Path:
        value = d.get(key)
        if not isinstance(value, str) or not value:
            raise self.fail(ctx, f"{key!r} must name an image file")
        p = Path(value)
        p = p if p.is_absolute() else self.base / p
        if not p.is_file():
            raise self.fail(_key(ctx, key), f"image {value} not found")
        return p

    # -------------------------------------------------------------------------

    def world(self, data: Any) -> World:
        if data is None:
            data = {}
        top = self.mapping(data, "", _TOP_KEYS)
        shapes: list[Shape] = []
        for i, w in enumerate(self.items(top, "walls")):
            shapes += self.wall(w, f"walls[{i}]")
        for i, b in enumerate(self.items(top, "boxes")):
            shapes.append(self.box(b, f"boxes[{i}]"))
        for i, c in enumerate(self.items(top, "cylinders")):
            shapes.append(self.cylinder(c, f"cylinders[{i}]"))
        for i, p in enumerate(self.items(top, "polygons")):
            shapes.append(self.polygon(p, f"polygons[{i}]"))
        for i, p in enumerate(self.items(top, "posters")):
            shapes.append(self.poster(p, f"posters[{i}]"))
        gravity = (0.0, 0.0, -9.8)
        if top.get("gravity") is not None:
            gx, gy, gz = self.numbers(top["gravity"], 3, "gravity")
            gravity = (gx, gy, gz)
        return World(
            name=self.name(top, "", self.path.stem) or self.path.stem,
            shapes=tuple(shapes),
            spawn_poses=self.spawn(top.get("spawn")),
            gravity=gravity,
            floor_rgb=self.rgb(top, "floor_rgb", "", DEFAULT_FLOOR_RGB),
            sky_rgb=self.rgb(top, "sky_rgb", "", DEFAULT_SKY_RGB),
            source=self.path,
        )

    def spawn(self, value: Any) -> tuple[SE2, ...]:
        if value is None:
            return (SE2(),)
        entries = value if isinstance(value, list) else [value]
        poses = []
        for i, s in enumerate(entries):
            ctx = f"spawn[{i}]" if isinstance(value, list) else "spawn"
            d = self.mapping(s, ctx, _SPAWN_KEYS)
            poses.append(
                SE2(
                    self.number(d, "x", ctx, 0.0),
                    self.number(d, "y", ctx, 0.0),
                    self.number(d, "yaw", ctx, 0.0),
                )
            )
        return tuple(poses) or (SE2(),)

    def wall(self, value: Any, ctx: str) -> list[Shape]:
        d = self.mapping(value, ctx, _WALL_KEYS)
        thickness = self.positive(d, "thickness", ctx, DEFAULT_WALL_THICKNESS)
        height = self.positive(d, "height", ctx, DEFAULT_WALL_HEIGHT)
        z = self.number(d, "z", ctx, 0.0)
        rgb = self.rgb(d, "rgb", ctx, DEFAULT_RGB)
        name = self.name(d, ctx)
        if "points" in d:
            if "from" in d or "to" in d:
                raise self.fail(ctx, "give either 'from'/'to' or 'points', not both")
            pts = self.points(d, ctx, 2)
            closed = d.get("closed", False)
            if not isinstance(closed, bool):
                raise self.fail(f"{ctx}.closed", f"must be true or false, got {closed!r}")
            if closed:
                pts = [*pts, pts[0]]
        else:
            if "closed" in d:
                raise self.fail(ctx, "'closed' only goes with 'points'")
            pts = [self.pair(d, "from", ctx), self.pair(d, "to", ctx)]
        shapes: list[Shape] = []
        for k, ((x0, y0), (x1, y1)) in enumerate(itertools.pairwise(pts)):
            length = math.hypot(x1 - x0, y1 - y0)
            if length <= 0.0:
                raise self.fail(ctx, f"wall {k} has zero length ({x0}, {y0}) -> ({x1}, {y1})")
            shapes.append(
                BoxShape(
                    pose=(
                        0.5 * (x0 + x1),
                        0.5 * (y0 + y1),
                        z + 0.5 * height,
                        0.0,
                        0.0,
                        math.atan2(y1 - y0, x1 - x0),
                    ),
                    size=(length + thickness, thickness, height),
                    rgb=rgb,
                    name=f"{name}_{k}" if name and len(pts) > 2 else name,
                )
            )
        return shapes

    def box(self, value: Any, ctx: str) -> Shape:
        d = self.mapping(value, ctx, _BOX_KEYS)
        cx, cy = self.pair(d, "center", ctx)
        if "size" not in d:
            raise self.fail(ctx, "missing key 'size'")
        sx, sy, sz = self.numbers(d["size"], 3, f"{ctx}.size")
        if min(sx, sy, sz) <= 0.0:
            raise self.fail(f"{ctx}.size", f"must be positive, got {d['size']!r}")
        z = self.number(d, "z", ctx, 0.0)
        texture = self.image(d, "texture", ctx) if "texture" in d else None
        return BoxShape(
            pose=(cx, cy, z + 0.5 * sz, 0.0, 0.0, self.number(d, "yaw", ctx, 0.0)),
            size=(sx, sy, sz),
            rgb=self.rgb(d, "rgb", ctx, DEFAULT_RGB),
            texture=texture,
            name=self.name(d, ctx),
        )

    def cylinder(self, value: Any, ctx: str) -> Shape:
        d = self.mapping(value, ctx, _CYL_KEYS)
        cx, cy = self.pair(d, "center", ctx)
        radius = self.positive(d, "radius", ctx)
        height = self.positive(d, "height", ctx)
        z = self.number(d, "z", ctx, 0.0)
        return CylinderShape(
            pose=(cx, cy, z + 0.5 * height, 0.0, 0.0, 0.0),
            radius=radius,
            length=height,
            rgb=self.rgb(d, "rgb", ctx, DEFAULT_RGB),
            name=self.name(d, ctx),
        )

    def polygon(self, value: Any, ctx: str) -> Shape:
        d = self.mapping(value, ctx, _POLY_KEYS)
        pts = self.points(d, ctx, 3)
        if len(set(pts)) < 3:
            raise self.fail(f"{ctx}.points", "needs at least 3 distinct points")
        return PolylineShape(
            pose=(0.0, 0.0, self.number(d, "z", ctx, 0.0), 0.0, 0.0, 0.0),
            points=tuple(pts),
            height=self.positive(d, "height", ctx),
            rgb=self.rgb(d, "rgb", ctx, DEFAULT_RGB),
            name=self.name(d, ctx),
        )

    def poster(self, value: Any, ctx: str) -> Shape:
        d = self.mapping(value, ctx, _POSTER_KEYS)
        start = self.pair(d, "from", ctx)
        end = self.pair(d, "to", ctx)
        if start == end:
            raise self.fail(ctx, "'from' and 'to' must differ")
        if "z" not in d:
            raise self.fail(ctx, "missing key 'z' ([bottom, top])")
        z0, z1 = self.numbers(d["z"], 2, f"{ctx}.z")
        if not z1 > z0:
            raise self.fail(f"{ctx}.z", f"top must be above bottom, got {d['z']!r}")
        return PosterShape(
            start=start,
            end=end,
            z_range=(z0, z1),
            image=self.image(d, "image", ctx),
            name=self.name(d, ctx),
        )
