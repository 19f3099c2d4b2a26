"""The dashboard's wire format and the pure geometry behind its displays.

Binary websocket frames start with a 4-byte header ``<u8 kind, u8 flags, u16 slot>``
(``slot``: the display's index in the configuration; the header keeps the float payloads
that follow 4-byte aligned in the browser). All numbers are little-endian:

* :data:`KIND_MAP`: ``<u32 width, u32 height, f32 resolution, f32 origin x, f32 origin y,
  f32 origin yaw>`` then ``width * height`` int8 cells (row 0 at the origin's y); the
  grid's frame goes in the JSON state;
* :data:`KIND_MAP_PATCH`: ``<u32 x0, u32 y0, u32 width, u32 height>`` then the int8 cells
  of that window of the last full map (only changed cells travel);
* :data:`KIND_POINTS` (laser scans, point clouds): ``<u32 count, u32 buckets>``, then
  ``buckets`` u32 point counts, ``buckets`` RGBA u8 colours, then ``count`` float32
  ``(x, y)`` pairs in the fixed frame sorted by bucket (one colour per bucket); with
  flag :data:`POINTS_XYZ` ``(x, y, z)`` triples, with :data:`POINTS_RGB` then ``count``
  RGBA u8 colours, one per point (rviz's RGB8);
* :data:`KIND_POSES` (odometry, pose arrays, poses): ``<u32 count>`` then ``count`` float32
  ``(x, y, yaw)`` in the fixed frame; with flag :data:`POSES_3D` ``(x, y, z, qx, qy, qz,
  qw)``, the full pose (the page derives the top view's yaw);
* :data:`KIND_PATH`: ``<u32 count>`` then ``count`` float32 ``(x, y)`` in the fixed frame;
  with flag :data:`PATH_XYZ` ``(x, y, z)``;
* :data:`KIND_IMAGE`: a JPEG (``flags`` 0) or PNG (``flags`` 1) file.

Everything else (markers, the robot's projected outline, frames, statuses, topic lists)
goes as JSON text.
"""

from __future__ import annotations

import io
import math
import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from roverlab.description.model import Box, Cylinder, Mesh, RobotModel, Sphere
from roverlab.geometry import Transform3

__all__ = [
    "COLOR_MAPS",
    "IMAGE_JPEG",
    "IMAGE_PNG",
    "INITIALPOSE_COVARIANCE",
    "KIND_IMAGE",
    "KIND_MAP",
    "KIND_MAP_PATCH",
    "KIND_PATH",
    "KIND_POINTS",
    "KIND_POSES",
    "KIND_SCAN",
    "PATH_XYZ",
    "POINTS_RGB",
    "POINTS_XYZ",
    "POSES_3D",
    "VisualOutline",
    "VisualShape",
    "colorize",
    "convex_hull",
    "encode_image",
    "encode_image_file",
    "encode_map",
    "encode_map_patch",
    "encode_path",
    "encode_points",
    "encode_poses",
    "encode_scan",
    "image_to_rgb8",
    "rainbow",
    "robot_outlines",
    "robot_shapes",
]

KIND_MAP: Final = 1
KIND_POINTS: Final = 2
KIND_SCAN: Final = KIND_POINTS  # the first milestone's name
KIND_IMAGE: Final = 3
KIND_POSES: Final = 4
KIND_PATH: Final = 5
KIND_MAP_PATCH: Final = 6
POINTS_XYZ: Final = 1
POINTS_RGB: Final = 2
POSES_3D: Final = 1
PATH_XYZ: Final = 1
IMAGE_JPEG: Final = 0
IMAGE_PNG: Final = 1

# rviz's 2D Pose Estimate: x and y variance 0.5**2, yaw variance (pi/12)**2.
INITIALPOSE_COVARIANCE: Final[tuple[float, ...]] = tuple(
    {0: 0.25, 7: 0.25, 35: 0.06853891945200942}.get(i, 0.0) for i in range(36)
)

_CIRCLE_SAMPLES: Final = 16


def encode_map(
    cells: NDArray[np.int8],
    *,
    resolution_m: float,
    origin: tuple[float, float, float],
    slot: int = 0,
) -> bytes:
    """A :data:`KIND_MAP` frame for an int8 ``(height, width)`` occupancy array."""
    height, width = cells.shape
    head = struct.pack("<BBHIIffff", KIND_MAP, 0, slot, width, height, resolution_m, *origin[:3])
    return head + np.ascontiguousarray(cells, dtype=np.int8).tobytes()


def encode_map_patch(cells: NDArray[np.int8], x0: int, y0: int, *, slot: int = 0) -> bytes:
    """A :data:`KIND_MAP_PATCH` frame: ``cells`` (a window) replace the map's from
    column ``x0``, row ``y0``."""
    height, width = cells.shape
    head = struct.pack("<BBHIIII", KIND_MAP_PATCH, 0, slot, x0, y0, width, height)
    return head + np.ascontiguousarray(cells, dtype=np.int8).tobytes()


def encode_points(
    points_xy: NDArray[np.floating[Any]],
    buckets: NDArray[np.integer[Any]] | None = None,
    palette: NDArray[np.uint8] | Sequence[Sequence[int]] = ((255, 0, 0, 255),),
    *,
    slot: int = 0,
    rgb: NDArray[np.uint8] | None = None,
) -> bytes:
    """A :data:`KIND_POINTS` frame: ``(N, 2)`` or ``(N, 3)`` points in the fixed frame, m,
    each drawn in ``palette[buckets[i]]`` (RGBA 0..255; all in ``palette[0]`` when
    ``buckets`` is None). ``(N, 3)`` points set flag :data:`POINTS_XYZ`; per-point ``rgb``
    (``(N, 3)`` uint8, rviz's RGB8 transformer) sets :data:`POINTS_RGB` and follows the
    points as RGBA bytes (alpha from ``palette[0]``)."""
    arr = np.asarray(points_xy, dtype=np.float64)
    dims = 3 if arr.ndim == 2 and arr.shape[1] == 3 else 2
    pts = arr.reshape(-1, dims)
    colours = np.asarray(palette, dtype=np.uint8).reshape(-1, 4)
    n_buckets = len(colours)
    flags = POINTS_XYZ if dims == 3 else 0
    per_point = b""  # RGBA bytes per point, after the points (with rgb only)
    if rgb is not None:
        flags |= POINTS_RGB
        alpha = np.full((len(pts), 1), colours[0, 3], dtype=np.uint8)
        per_point = np.hstack((np.asarray(rgb, dtype=np.uint8).reshape(-1, 3), alpha)).tobytes()
    if rgb is not None or buckets is None:
        counts = np.array([len(pts)] + [0] * (n_buckets - 1), dtype="<u4")
    else:
        idx = np.clip(np.asarray(buckets, dtype=np.int64).reshape(-1), 0, n_buckets - 1)
        order = np.argsort(idx, kind="stable")
        pts = pts[order]
        counts = np.bincount(idx, minlength=n_buckets).astype("<u4")
    head = struct.pack("<BBHII", KIND_POINTS, flags, slot, len(pts), n_buckets)
    return (
        head
        + counts.tobytes()
        + colours.tobytes()
        + np.ascontiguousarray(pts, dtype="<f4").tobytes()
        + per_point
    )


def encode_scan(points_xy: NDArray[np.floating[Any]], *, slot: int = 0) -> bytes:
    """A :data:`KIND_POINTS` frame of one colour (red) for ``(N, 2)`` points, m."""
    return encode_points(points_xy, slot=slot)


def encode_poses(poses: NDArray[np.floating[Any]], *, slot: int = 0) -> bytes:
    """A :data:`KIND_POSES` frame for ``(N, 3)`` ``(x, y, yaw)`` or ``(N, 7)`` ``(x, y, z,
    qx, qy, qz, qw)`` poses in the fixed frame (flag :data:`POSES_3D`)."""
    raw = np.asarray(poses, dtype=np.float64)
    width = 7 if raw.ndim == 2 and raw.shape[1] == 7 else 3
    arr = np.ascontiguousarray(raw, dtype="<f4").reshape(-1, width)
    flags = POSES_3D if width == 7 else 0
    return struct.pack("<BBHI", KIND_POSES, flags, slot, len(arr)) + arr.tobytes()


def encode_path(points: NDArray[np.floating[Any]], *, slot: int = 0) -> bytes:
    """A :data:`KIND_PATH` frame for an ``(N, 2)`` or ``(N, 3)`` (flag :data:`PATH_XYZ`)
    polyline in the fixed frame, m."""
    raw = np.asarray(points, dtype=np.float64)
    width = 3 if raw.ndim == 2 and raw.shape[1] == 3 else 2
    arr = np.ascontiguousarray(raw, dtype="<f4").reshape(-1, width)
    flags = PATH_XYZ if width == 3 else 0
    return struct.pack("<BBHI", KIND_PATH, flags, slot, len(arr)) + arr.tobytes()


def _lut(name: str) -> NDArray[np.uint8]:
    x = np.linspace(0.0, 1.0, 256)
    if name == "gray":
        rgb = np.column_stack((x, x, x))
    elif name == "jet":
        rgb = np.column_stack(
            (
                np.clip(1.5 - np.abs(4.0 * x - 3.0), 0.0, 1.0),
                np.clip(1.5 - np.abs(4.0 * x - 2.0), 0.0, 1.0),
                np.clip(1.5 - np.abs(4.0 * x - 1.0), 0.0, 1.0),
            )
        )
    elif name == "hot":
        rgb = np.column_stack(
            (np.clip(3.0 * x, 0, 1), np.clip(3.0 * x - 1.0, 0, 1), np.clip(3.0 * x - 2.0, 0, 1))
        )
    elif name == "rainbow":
        return (rainbow(x) * 255.0 + 0.5).astype(np.uint8)
    else:
        raise ValueError(f"unknown colour map {name!r} (gray, jet, hot, rainbow)")
    return (rgb * 255.0 + 0.5).astype(np.uint8)


COLOR_MAPS: Final[tuple[str, ...]] = ("gray", "jet", "hot", "rainbow")


def rainbow(values: NDArray[np.floating[Any]]) -> NDArray[np.float64]:
    """rviz's rainbow colour scale: 0 -> magenta, blue, cyan, green, yellow, 1 -> red.

    Returns ``(N, 3)`` RGB in 0..1 for values in 0..1 (clipped).
    """
    v = np.clip(np.asarray(values, dtype=np.float64).reshape(-1), 0.0, 1.0)
    h = (1.0 - v) * 5.0  # 0 red .. 5 magenta, six linear segments of the hue circle
    seg = np.minimum(np.floor(h).astype(np.int64), 4)
    f = h - seg
    r = np.select([seg == 0, seg == 1, seg == 2, seg == 3], [1.0, 1.0 - f, 0.0, 0.0], f)
    g = np.select([seg == 0, seg == 1, seg == 2, seg == 3], [f, 1.0, 1.0, 1.0 - f], 0.0)
    b = np.select([seg == 0, seg == 1, seg == 2, seg == 3], [0.0, 0.0, f, 1.0], 1.0)
    return np.column_stack((r, g, b))


def colorize(
    values: NDArray[Any],
    color_map: str = "jet",
    *,
    min_value: float = 0.0,
    max_value: float = 0.0,
    invalid_zero: bool = False,
) -> NDArray[np.uint8]:
    """Single-channel ``values`` (e.g. depth) as RGB uint8 through a colour map.

    ``min_value`` .. ``max_value`` map to the ends of the scale; both 0 means the finite
    (and, with ``invalid_zero``, non-zero) minimum and maximum of the image, as
    rqt_image_view's dynamic range. Non-finite (and zero, with ``invalid_zero``) pixels
    are black.

    Raises:
        ValueError: unknown ``color_map``.
    """
    lut = _lut(color_map)
    work = np.asarray(values, dtype=np.float64)
    valid = np.isfinite(work)
    if invalid_zero:
        valid &= work != 0
    lo, hi = float(min_value), float(max_value)
    if lo == 0.0 and hi == 0.0 and valid.any():
        lo, hi = float(work[valid].min()), float(work[valid].max())
    scale = 255.0 / (hi - lo) if hi > lo else 0.0
    idx = np.clip(np.where(valid, (work - lo) * scale, 0.0), 0, 255).astype(np.uint8)
    rgb = lut[idx]
    rgb[~valid] = 0
    return np.ascontiguousarray(rgb)


def image_to_rgb8(
    pixels: NDArray[Any],
    encoding: str,
    *,
    color_map: str = "gray",
    min_value: float = 0.0,
    max_value: float = 0.0,
) -> NDArray[np.uint8]:
    """Pixels of :func:`roverlab.msgs.image_to_array` as displayable RGB or grey uint8.

    BGR(A) is swapped to RGB(A) and alpha dropped. Single-channel images that are not
    8-bit (depth ``16UC1`` / ``32FC1``, ...) go through :func:`colorize` with
    ``color_map`` (``gray`` keeps them one channel); depth encodings treat 0 as no data.
    """
    arr = np.asarray(pixels)
    enc = encoding.lower()
    if arr.ndim == 3 and arr.shape[2] == 1:
        arr = arr[..., 0]
    if arr.ndim == 3:
        arr = arr[..., [2, 1, 0]] if enc.startswith("bgr") else arr[..., :3]
    if arr.dtype == np.uint8:
        return np.ascontiguousarray(arr)
    if arr.ndim == 2:
        depth = enc in ("16uc1", "32fc1", "mono16")
        rgb = colorize(
            arr,
            color_map,
            min_value=min_value,
            max_value=max_value,
            invalid_zero=depth and enc != "mono16",
        )
        return np.ascontiguousarray(rgb[..., 0]) if color_map == "gray" else rgb
    work = arr.astype(np.float64)  # multi-channel, not 8-bit: scale each image to 0..255
    finite = np.isfinite(work)
    if finite.any():
        lo, hi = float(work[finite].min()), float(work[finite].max())
        scale = 255.0 / (hi - lo) if hi > lo else 0.0
        work = np.where(finite, (work - lo) * scale, 0.0)
    else:
        work = np.zeros_like(work)
    return np.ascontiguousarray(work.astype(np.uint8))


def encode_image(rgb: NDArray[np.uint8], *, quality: int = 80) -> bytes:
    """A :data:`KIND_IMAGE` frame: the header then a JPEG of ``rgb`` (grey or RGB)."""
    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="JPEG", quality=quality)
    return struct.pack("<BBH", KIND_IMAGE, IMAGE_JPEG, 0) + buf.getvalue()


def encode_image_file(data: bytes) -> bytes:
    """A :data:`KIND_IMAGE` frame passing a JPEG or PNG file through untouched.

    Raises:
        ValueError: ``data`` is neither a JPEG nor a PNG file.
    """
    if data[:3] == b"\xff\xd8\xff":
        flag = IMAGE_JPEG
    elif data[:8] == b"\x89PNG\r\n\x1a\n":
        flag = IMAGE_PNG
    else:
        raise ValueError("compressed image is neither JPEG nor PNG")
    return struct.pack("<BBH", KIND_IMAGE, flag, 0) + data


def convex_hull(points: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """Counter-clockwise convex hull of 2-D points (Andrew's monotone chain)."""
    pts = sorted(set(points))
    if len(pts) <= 2:
        return pts

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[tuple[float, float]] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


@dataclass(frozen=True)
class VisualOutline:
    """One URDF visual as 3-D points in its link's frame whose top view is the shape.

    Attributes:
        link: the link the visual belongs to.
        points: ``(N, 3)`` points (box corners, sampled cylinder rims, a sphere's equator).
        rgba: colour 0..1, grey when the URDF gives none.
    """

    link: str
    points: NDArray[np.float64]
    rgba: tuple[float, float, float, float]

    def footprint(self, fixed_from_link: Transform3) -> list[tuple[float, float]]:
        """The outline seen from above in the fixed frame: a convex polygon, m."""
        world = fixed_from_link.apply(self.points)
        return convex_hull([(float(x), float(y)) for x, y in world[:, :2]])


def _shape_points(geometry: object) -> NDArray[np.float64] | None:
    ring = np.linspace(0.0, 2.0 * math.pi, _CIRCLE_SAMPLES, endpoint=False)
    if isinstance(geometry, Box):
        sx, sy, sz = (s / 2.0 for s in geometry.size)
        return np.array(
            [(x, y, z) for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)], dtype=np.float64
        )
    if isinstance(geometry, Cylinder):  # axis along z of the visual frame
        r, h = geometry.radius, geometry.length / 2.0
        rim = np.column_stack((r * np.cos(ring), r * np.sin(ring)))
        return np.vstack(
            (
                np.column_stack((rim, np.full(len(rim), -h))),
                np.column_stack((rim, np.full(len(rim), h))),
            )
        )
    if isinstance(geometry, Sphere):  # any view of a sphere is its equator's disc
        r = geometry.radius
        return np.column_stack((r * np.cos(ring), r * np.sin(ring), np.zeros(len(ring))))
    return None  # meshes: not drawn in this first version


def robot_outlines(model: RobotModel) -> list[VisualOutline]:
    """The top-view outline of every box, cylinder and sphere visual of ``model``."""
    out: list[VisualOutline] = []
    for link_name, visual, rgba in _visuals(model):
        pts = _shape_points(visual.geometry)
        if pts is not None:
            out.append(VisualOutline(link_name, visual.origin.apply(pts), rgba))
    return out


def _visuals(model: RobotModel) -> Iterator[tuple[str, Any, tuple[float, float, float, float]]]:
    """``(link name, visual, rgba)`` of every visual of ``model``; grey where the URDF
    material gives no colour."""
    for link in model.links.values():
        for visual in link.visuals:
            rgba = (0.6, 0.6, 0.6, 1.0)
            if visual.material is not None and visual.material.rgba is not None:
                rgba = tuple(float(c) for c in visual.material.rgba)  # type: ignore[assignment]
            yield link.name, visual, rgba


@dataclass(frozen=True)
class VisualShape:
    """One URDF visual for the 3D view: geometry, pose in its link and colour.

    Attributes:
        link: the link the visual belongs to.
        geometry: ``{"type": "box", "size": [x, y, z]}``, ``{"type": "cylinder",
            "radius", "length"}`` (along z), ``{"type": "sphere", "radius"}`` or
            ``{"type": "mesh", "filename", "scale"}``.
        origin: ``[x, y, z, qx, qy, qz, qw]`` of the visual in the link's frame.
        rgba: the URDF material's colour 0..1, grey when it gives none.
    """

    link: str
    geometry: dict[str, Any]
    origin: list[float]
    rgba: tuple[float, float, float, float]

    def to_dict(self) -> dict[str, Any]:
        return {
            "link": self.link,
            "geometry": self.geometry,
            "origin": self.origin,
            "rgba": list(self.rgba),
        }


def _geometry_dict(geometry: object) -> dict[str, Any] | None:
    if isinstance(geometry, Box):
        return {"type": "box", "size": [float(s) for s in geometry.size]}
    if isinstance(geometry, Cylinder):
        return {"type": "cylinder", "radius": geometry.radius, "length": geometry.length}
    if isinstance(geometry, Sphere):
        return {"type": "sphere", "radius": geometry.radius}
    if isinstance(geometry, Mesh):
        return {
            "type": "mesh",
            "filename": geometry.filename,
            "scale": [float(s) for s in geometry.scale],
        }
    return None


def robot_shapes(model: RobotModel) -> list[VisualShape]:
    """Every visual of ``model`` as a :class:`VisualShape` (rviz's RobotModel display)."""
    out: list[VisualShape] = []
    for link_name, visual, rgba in _visuals(model):
        geometry = _geometry_dict(visual.geometry)
        if geometry is not None:
            o = visual.origin
            origin = [round(float(v), 6) for v in (*o.translation, *o.rotation)]
            out.append(VisualShape(link_name, geometry, origin, rgba))
    return out
