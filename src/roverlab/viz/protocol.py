"""The dashboard's wire format and the pure geometry behind its displays.

Binary websocket frames start with a one-byte kind and three bytes of padding (so the
float payloads that follow are 4-byte aligned in the browser):

* :data:`KIND_MAP`: ``<u32 width, u32 height, f32 resolution, f32 origin x, f32 origin y,
  f32 origin yaw>`` then ``width * height`` int8 cells (row 0 at the origin's y), frame
  name in the JSON ``map_info`` message;
* :data:`KIND_SCAN`: ``<u32 count>`` then ``count`` float32 ``(x, y)`` pairs in the fixed frame;
* :data:`KIND_IMAGE`: a JPEG file.

Everything else (poses, the robot's projected outline, topic lists) goes as JSON text.
"""

from __future__ import annotations

import io
import math
import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from roverlab.description.model import Box, Cylinder, RobotModel, Sphere
from roverlab.geometry import Transform3

__all__ = [
    "INITIALPOSE_COVARIANCE",
    "KIND_IMAGE",
    "KIND_MAP",
    "KIND_SCAN",
    "VisualOutline",
    "convex_hull",
    "encode_image",
    "encode_map",
    "encode_scan",
    "image_to_rgb8",
    "robot_outlines",
]

KIND_MAP: Final = 1
KIND_SCAN: Final = 2
KIND_IMAGE: Final = 3

# rviz's 2D Pose Estimate: x and y variance 0.5**2, yaw variance (pi/12)**2.
INITIALPOSE_COVARIANCE: Final[tuple[float, ...]] = tuple(
    {0: 0.25, 7: 0.25, 35: 0.06853891945200942}.get(i, 0.0) for i in range(36)
)

_CIRCLE_SAMPLES: Final = 16


def encode_map(
    cells: NDArray[np.int8], *, resolution_m: float, origin: tuple[float, float, float]
) -> bytes:
    """A :data:`KIND_MAP` frame for an int8 ``(height, width)`` occupancy array."""
    height, width = cells.shape
    head = struct.pack(
        "<B3xIIffff", KIND_MAP, width, height, resolution_m, origin[0], origin[1], origin[2]
    )
    return head + np.ascontiguousarray(cells, dtype=np.int8).tobytes()


def encode_scan(points_xy: NDArray[np.floating[Any]]) -> bytes:
    """A :data:`KIND_SCAN` frame for ``(N, 2)`` points in the fixed frame, m."""
    pts = np.ascontiguousarray(points_xy, dtype="<f4").reshape(-1, 2)
    return struct.pack("<B3xI", KIND_SCAN, len(pts)) + pts.tobytes()


def image_to_rgb8(pixels: NDArray[Any], encoding: str) -> NDArray[np.uint8]:
    """Pixels of :func:`roverlab.msgs.image_to_array` as displayable RGB or grey uint8.

    BGR(A) is swapped to RGB(A) and alpha dropped; depth and other non-8-bit images are
    scaled from their finite minimum..maximum to 0..255, as rqt_image_view does.
    """
    arr = np.asarray(pixels)
    enc = encoding.lower()
    if arr.ndim == 3:
        arr = arr[..., [2, 1, 0]] if enc.startswith("bgr") else arr[..., :3]
    if arr.dtype != np.uint8:
        work = arr.astype(np.float64)
        finite = np.isfinite(work)
        if finite.any():
            lo, hi = float(work[finite].min()), float(work[finite].max())
            scale = 255.0 / (hi - lo) if hi > lo else 0.0
            work = np.where(finite, (work - lo) * scale, 0.0)
        else:
            work = np.zeros_like(work)
        arr = work.astype(np.uint8)
    return np.ascontiguousarray(arr)


def encode_image(rgb: NDArray[np.uint8], *, quality: int = 80) -> bytes:
    """A :data:`KIND_IMAGE` frame: the header then a JPEG of ``rgb`` (grey or RGB)."""
    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="JPEG", quality=quality)
    return struct.pack("<B3x", KIND_IMAGE) + buf.getvalue()


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
    for link in model.links.values():
        for visual in link.visuals:
            pts = _shape_points(visual.geometry)
            if pts is None:
                continue
            rgba = (0.6, 0.6, 0.6, 1.0)
            if visual.material is not None and visual.material.rgba is not None:
                rgba = tuple(float(c) for c in visual.material.rgba)  # type: ignore[assignment]
            out.append(VisualOutline(link.name, visual.origin.apply(pts), rgba))
    return out
