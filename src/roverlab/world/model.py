"""The world model: static shapes, compiled into the ray-casting scene and occupancy grids.

A :class:`World` holds immutable shapes in SI units (metres, radians) in the world frame:

* :class:`BoxShape` — a box centred on its pose (SDF ``<box>``), optionally textured;
* :class:`CylinderShape` — a cylinder along its local z axis, centred on its pose;
* :class:`SphereShape`;
* :class:`PolylineShape` — SDF ``<polyline>``: a closed 2-D outline in the shape's xy
  plane extruded ``height`` metres along its local +z (a prism);
* :class:`PosterShape` — a flat image on a vertical face (visual only: cameras see it,
  occupancy and collisions ignore it).

Poses are ``(x, y, z, roll, pitch, yaw)`` (fixed-axis roll-pitch-yaw, as SDF ``<pose>``)
or a :class:`~roverlab.geometry.Transform3`. Colours are ``(r, g, b)`` in 0..255.

**2.5-D approximation.** Ray casters, occupancy grids and collision checks see every shape
as an upright extrusion between a lowest and a highest z. Upright boxes, cylinders and
polylines (and those turned by multiples of 90 degrees about x or y) are exact; a shape
with any other roll or pitch becomes the smallest upright prism that contains it (the
convex hull of its projected corners, from its lowest to its highest point); a sphere
becomes its bounding cylinder.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from PIL import Image, UnidentifiedImageError

from roverlab.geometry import SE2, Transform3, quat_from_rpy
from roverlab.raycast.scene import Scene
from roverlab.world._compile import (
    Compiled,
    Panel,
    Primitive,
    box_primitive,
    cylinder_primitive,
    polyline_primitive,
    sphere_primitive,
)
from roverlab.world.errors import WorldError

__all__ = [
    "DEFAULT_FLOOR_RGB",
    "DEFAULT_RGB",
    "DEFAULT_SKY_RGB",
    "RGB",
    "BoxShape",
    "CylinderShape",
    "PolylineShape",
    "PoseLike",
    "PosterShape",
    "Shape",
    "SphereShape",
    "World",
    "pose_to_transform",
]

RGB = tuple[int, int, int]
PoseLike = Transform3 | Sequence[float]

DEFAULT_RGB: RGB = (200, 200, 200)
DEFAULT_FLOOR_RGB: RGB = (110, 110, 110)
DEFAULT_SKY_RGB: RGB = (178, 204, 229)


def pose_to_transform(pose: PoseLike) -> Transform3:
    """A :class:`Transform3` from ``(x, y, z, roll, pitch, yaw)`` (or a Transform3 as is)."""
    if isinstance(pose, Transform3):
        return pose
    try:
        vals = [float(v) for v in pose]
    except (TypeError, ValueError) as err:
        raise WorldError(f"pose must be 6 numbers x y z roll pitch yaw, got {pose!r}") from err
    if len(vals) != 6 or not all(math.isfinite(v) for v in vals):
        raise WorldError(f"pose must be 6 finite numbers x y z roll pitch yaw, got {pose!r}")
    x, y, z, roll, pitch, yaw = vals
    return Transform3.from_arrays((x, y, z), quat_from_rpy(roll, pitch, yaw))


def _label(kind: str, name: str) -> str:
    return f"{kind} {name!r}" if name else kind


def _positive(value: float, what: str, label: str) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise WorldError(f"{label}: {what} must be a positive number, got {value!r}")
    return v


def _check_rgb(rgb: Sequence[int], label: str) -> RGB:
    vals = tuple(rgb)
    if len(vals) != 3 or not all(
        isinstance(v, int | np.integer) and not isinstance(v, bool) and 0 <= v <= 255 for v in vals
    ):
        raise WorldError(f"{label}: rgb must be 3 integers in 0..255, got {rgb!r}")
    return (int(vals[0]), int(vals[1]), int(vals[2]))


def _set(obj: object, name: str, value: object) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True, kw_only=True)
class BoxShape:
    """A box of ``size`` (sx, sy, sz) metres centred on ``pose``.

    ``texture`` (an image file) is drawn on each of the four side faces, left to right as
    seen from outside the box and top to bottom.
    """

    pose: PoseLike = field(default_factory=Transform3)
    size: tuple[float, float, float]
    rgb: RGB = DEFAULT_RGB
    texture: Path | None = None
    name: str = ""

    def __post_init__(self) -> None:
        label = _label("box", self.name)
        _set(self, "pose", pose_to_transform(self.pose))
        if len(tuple(self.size)) != 3:
            raise WorldError(f"{label}: size must be 3 numbers, got {self.size!r}")
        sx, sy, sz = (_positive(v, "size", label) for v in self.size)
        _set(self, "size", (sx, sy, sz))
        _set(self, "rgb", _check_rgb(self.rgb, label))
        if self.texture is not None:
            _set(self, "texture", Path(self.texture))

    @property
    def transform(self) -> Transform3:
        return cast(Transform3, self.pose)

    def primitive(self) -> Primitive:
        return box_primitive(self.transform, self.size)


@dataclass(frozen=True, kw_only=True)
class CylinderShape:
    """A cylinder of ``radius`` and ``length`` along its local z axis, centred on ``pose``."""

    pose: PoseLike = field(default_factory=Transform3)
    radius: float
    length: float
    rgb: RGB = DEFAULT_RGB
    name: str = ""

    def __post_init__(self) -> None:
        label = _label("cylinder", self.name)
        _set(self, "pose", pose_to_transform(self.pose))
        _set(self, "radius", _positive(self.radius, "radius", label))
        _set(self, "length", _positive(self.length, "length", label))
        _set(self, "rgb", _check_rgb(self.rgb, label))

    @property
    def transform(self) -> Transform3:
        return cast(Transform3, self.pose)

    def primitive(self) -> Primitive:
        return cylinder_primitive(self.transform, self.radius, self.length)


@dataclass(frozen=True, kw_only=True)
class SphereShape:
    """A sphere of ``radius`` centred on ``pose`` (seen as its bounding cylinder)."""

    pose: PoseLike = field(default_factory=Transform3)
    radius: float
    rgb: RGB = DEFAULT_RGB
    name: str = ""

    def __post_init__(self) -> None:
        label = _label("sphere", self.name)
        _set(self, "pose", pose_to_transform(self.pose))
        _set(self, "radius", _positive(self.radius, "radius", label))
        _set(self, "rgb", _check_rgb(self.rgb, label))

    @property
    def transform(self) -> Transform3:
        return cast(Transform3, self.pose)

    def primitive(self) -> Primitive:
        return sphere_primitive(self.transform, self.radius)


@dataclass(frozen=True, kw_only=True)
class PolylineShape:
    """SDF ``<polyline>``: the closed outline ``points`` (x, y in the shape frame, at least
    3) extruded ``height`` metres along the shape's +z; the last point joins the first."""

    pose: PoseLike = field(default_factory=Transform3)
    points: tuple[tuple[float, float], ...]
    height: float
    rgb: RGB = DEFAULT_RGB
    name: str = ""

    def __post_init__(self) -> None:
        label = _label("polyline", self.name)
        _set(self, "pose", pose_to_transform(self.pose))
        try:
            pts = np.asarray(self.points, dtype=np.float64)
        except (TypeError, ValueError) as err:
            raise WorldError(f"{label}: points must be (x, y) pairs, got {self.points!r}") from err
        if pts.ndim != 2 or pts.shape[1] != 2 or not np.all(np.isfinite(pts)):
            raise WorldError(f"{label}: points must be finite (x, y) pairs, got {self.points!r}")
        distinct = np.unique(pts, axis=0)
        if len(distinct) < 3:
            raise WorldError(f"{label}: needs at least 3 distinct points, got {len(distinct)}")
        _set(self, "points", tuple((float(x), float(y)) for x, y in pts))
        _set(self, "height", _positive(self.height, "height", label))
        _set(self, "rgb", _check_rgb(self.rgb, label))

    @property
    def transform(self) -> Transform3:
        return cast(Transform3, self.pose)

    def primitive(self) -> Primitive:
        return polyline_primitive(self.transform, self.points, self.height)


@dataclass(frozen=True, kw_only=True)
class PosterShape:
    """An image on a vertical face from ``start`` to ``end`` (x, y) and z in ``z_range``.

    The image reads left to right from ``start`` to ``end`` for a viewer on the right-hand
    side of the direction start -> end (list the ends left to right as you face the
    poster), top row at ``z_range[1]``. Visual only: it has no thickness, so occupancy
    grids and collision checks ignore it.
    """

    start: tuple[float, float]
    end: tuple[float, float]
    z_range: tuple[float, float]
    image: Path
    rgb: RGB = DEFAULT_RGB
    name: str = ""

    def __post_init__(self) -> None:
        label = _label("poster", self.name)
        vals = [*self.start, *self.end, *self.z_range]
        if len(vals) != 6 or not all(math.isfinite(float(v)) for v in vals):
            raise WorldError(f"{label}: start, end and z_range must be finite pairs")
        x0, y0, x1, y1, z0, z1 = (float(v) for v in vals)
        if math.hypot(x1 - x0, y1 - y0) <= 0.0:
            raise WorldError(f"{label}: start and end must differ")
        if not z1 > z0:
            raise WorldError(f"{label}: z_range must rise, got {self.z_range!r}")
        _set(self, "start", (x0, y0))
        _set(self, "end", (x1, y1))
        _set(self, "z_range", (z0, z1))
        _set(self, "image", Path(self.image))
        _set(self, "rgb", _check_rgb(self.rgb, label))

    def primitive(self) -> Primitive:
        return Panel((*self.start, *self.end), *self.z_range)


Shape = BoxShape | CylinderShape | SphereShape | PolylineShape | PosterShape


@dataclass(frozen=True, kw_only=True)
class World:
    """A static world: shapes, where robots spawn, and scene colours.

    Attributes:
        name: world name (SDF ``<world name>``, YAML ``name`` or the file stem).
        shapes: static geometry in the world frame.
        spawn_poses: robot spawn poses (x, y, yaw); the first is the default. Gazebo
            spawns at the origin, so SDF worlds spawn at (0, 0, 0).
        gravity: m/s^2 in the world frame.
        floor_rgb, sky_rgb: colours of the ground plane (z = 0) and of empty space.
        source: the file the world was loaded from, if any.
        warnings: one line per element the loader skipped (meshes, robots, ...).
        notes: what the file says that is loaded otherwise than Gazebo would run it, and
            is not a fault of the file (non-static models kept as fixed obstacles).
    """

    name: str = "default"
    shapes: tuple[Shape, ...] = ()
    spawn_poses: tuple[SE2, ...] = (SE2(),)
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.8)
    floor_rgb: RGB = DEFAULT_FLOOR_RGB
    sky_rgb: RGB = DEFAULT_SKY_RGB
    source: Path | None = None
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        _set(self, "shapes", tuple(self.shapes))
        _set(self, "spawn_poses", tuple(self.spawn_poses) or (SE2(),))
        _set(self, "warnings", tuple(self.warnings))
        _set(self, "floor_rgb", _check_rgb(self.floor_rgb, f"world {self.name!r} floor"))
        _set(self, "sky_rgb", _check_rgb(self.sky_rgb, f"world {self.name!r} sky"))

    @property
    def spawn(self) -> SE2:
        """The default spawn pose."""
        return self.spawn_poses[0]

    @cached_property
    def _compiled(self) -> Compiled:
        items: list[tuple[Primitive, RGB, Path | None]] = []
        for s in self.shapes:
            if isinstance(s, BoxShape):
                items.append((s.primitive(), s.rgb, s.texture))
            elif isinstance(s, PosterShape):
                items.append((s.primitive(), s.rgb, s.image))
            else:
                items.append((s.primitive(), s.rgb, None))
        return Compiled.build(items)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of all geometry; zeros for an empty world."""
        b = self._compiled.bounds()
        return b if b is not None else (0.0, 0.0, 0.0, 0.0)

    # ------------------------------------------------------------------ scene

    def to_scene(self) -> Scene:
        """The ray-casting :class:`~roverlab.raycast.scene.Scene` of this world.

        Boxes and polylines become their side faces (counter-clockwise seen from above, so
        textures read correctly from outside), cylinders and spheres circles, posters one
        textured face. A new Scene is returned on every call.

        Raises:
            WorldError: a texture image cannot be read.
        """
        c = self._compiled
        segs = np.concatenate([c.edges, c.panels])
        return Scene(
            segments=segs,
            segment_z=np.concatenate([c.poly_z[c.edge_owner], c.panel_z]),
            segment_rgb=np.concatenate([c.poly_rgb[c.edge_owner], c.panel_rgb]),
            segment_texture=np.concatenate([c.poly_texture[c.edge_owner], c.panel_texture]),
            circles=c.circles.copy(),
            circle_z=c.circle_z.copy(),
            circle_rgb=c.circle_rgb.copy(),
            textures=list(self._textures),
            floor_rgb=self.floor_rgb,
            sky_rgb=self.sky_rgb,
        )

    @cached_property
    def _textures(self) -> tuple[NDArray[np.uint8], ...]:
        images: list[NDArray[np.uint8]] = []
        for path in self._compiled.texture_paths:
            try:
                with Image.open(path) as im:
                    arr = np.array(im.convert("RGB"), dtype=np.uint8)
            except (OSError, UnidentifiedImageError) as err:
                raise WorldError(f"{path}: cannot read texture image: {err}") from err
            arr.flags.writeable = False
            images.append(arr)
        return tuple(images)

    # -------------------------------------------------------------- occupancy

    def occupancy(
        self,
        resolution: float,
        z_min: float = 0.0,
        z_max: float = math.inf,
        *,
        bounds: tuple[float, float, float, float] | None = None,
        padding: float = 0.5,
    ) -> tuple[NDArray[np.bool_], tuple[float, float]]:
        """Rasterise every solid shape that reaches into the height band [z_min, z_max].

        A cell is occupied when a shape overlaps the cell's open square (so walls thinner
        than a cell still close, and a shape exactly covering cells marks only them).

        Args:
            resolution: cell size in metres.
            z_min, z_max: height band in metres (``z_min == z_max`` samples one plane).
            bounds: ``(xmin, ymin, xmax, ymax)`` of the grid; ``None`` means the world's
                solid bounds grown by ``padding`` and snapped to multiples of the
                resolution.
            padding: margin in metres around the world bounds (ignored with ``bounds``).

        Returns:
            ``(grid, origin)``: a (rows, cols) bool array, row 0 at the lowest y and
            column 0 at the lowest x (``nav_msgs/OccupancyGrid`` order, so flip it
            vertically to view it as an image), and ``origin``, the (x, y) of the lower
            left corner of cell (0, 0).
        """
        res = _positive(resolution, "resolution", "occupancy")
        if bounds is None:
            b = self._compiled.bounds(solid_only=True) or (0.0, 0.0, 0.0, 0.0)
            xmin = math.floor((b[0] - padding) / res + 1e-9) * res
            ymin = math.floor((b[1] - padding) / res + 1e-9) * res
            xmax, ymax = b[2] + padding, b[3] + padding
        else:
            xmin, ymin, xmax, ymax = (float(v) for v in bounds)
            if not (xmax > xmin and ymax > ymin):
                raise WorldError(
                    f"occupancy: bounds must be (xmin, ymin, xmax, ymax), got {bounds}"
                )
        width = max(1, math.ceil((xmax - xmin) / res - 1e-9))
        height = max(1, math.ceil((ymax - ymin) / res - 1e-9))
        grid = self._compiled.rasterise((xmin, ymin), res, (height, width), z_min, z_max)
        return grid, (xmin, ymin)

    # ------------------------------------------------------------- collisions

    def footprint_collides(
        self,
        x: float,
        y: float,
        yaw: float,
        footprint: float | ArrayLike,
        *,
        z_min: float = 0.0,
        z_max: float = math.inf,
    ) -> bool:
        """Does a robot footprint at pose (x, y, yaw) overlap a solid shape?

        Exact 2-D test against every shape reaching into [z_min, z_max] (touching is not
        overlapping).

        Args:
            x, y, yaw: robot pose in the world frame (m, m, rad).
            footprint: a radius in metres, or a polygon ``[(x, y), ...]`` in the robot
                frame (as move_base's ``footprint`` parameter).
            z_min, z_max: height band of the robot body.
        """
        c = self._compiled
        if np.ndim(footprint) == 0:
            radius = _positive(cast(float, footprint), "footprint radius", "footprint")
            return c.disc_collides(float(x), float(y), radius, z_min, z_max)
        poly = np.asarray(footprint, dtype=np.float64)
        if poly.ndim != 2 or poly.shape[1] != 2 or len(poly) < 3:
            raise WorldError(f"footprint: need a radius or >= 3 (x, y) points, got {footprint!r}")
        cy, sy = math.cos(yaw), math.sin(yaw)
        world = poly @ np.array([[cy, sy], [-sy, cy]]) + np.array([x, y])
        return c.polygon_collides(world, z_min, z_max)
