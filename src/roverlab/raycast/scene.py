"""The static 2.5-D scene that every ray caster works on.

A world (Gazebo SDF, YAML or map image) is compiled into flat numpy arrays:

* **segments**: vertical wall faces, each a 2-D segment ``(x0, y0, x1, y1)`` extruded from
  ``zmin`` to ``zmax``, with an RGB colour and an optional texture (a poster) whose
  horizontal coordinate runs from the segment's start (u=0) to its end (u=1) and whose
  vertical coordinate runs from ``zmax`` (v=0, top row) to ``zmin`` (v=1);
* **circles**: vertical cylinders ``(cx, cy, r)`` from ``zmin`` to ``zmax`` with a colour
  (spheres are approximated by the cylinder of their bounding box);
* the floor (z = 0) and sky colours.

Boxes become their four side faces, polylines their edges. Coordinates are metres in the
world (map) frame; angles radians. Kernels in :mod:`roverlab.raycast` take a Scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

__all__ = ["Scene"]


def _f64(a: object, cols: int) -> NDArray[np.float64]:
    arr = np.asarray(a, dtype=np.float64)
    if arr.size == 0:
        return np.zeros((0, cols), dtype=np.float64)
    return np.ascontiguousarray(arr.reshape(-1, cols))


def _u8(a: object, cols: int) -> NDArray[np.uint8]:
    arr = np.asarray(a, dtype=np.uint8)
    if arr.size == 0:
        return np.zeros((0, cols), dtype=np.uint8)
    return np.ascontiguousarray(arr.reshape(-1, cols))


@dataclass(eq=False)
class Scene:
    """Flat arrays of a static scene (see the module docstring).

    Attributes:
        segments: (N, 4) float64 ``x0, y0, x1, y1``.
        segment_z: (N, 2) float64 ``zmin, zmax``.
        segment_rgb: (N, 3) uint8.
        segment_texture: (N,) int32 index into ``textures`` or -1.
        circles: (M, 3) float64 ``cx, cy, r``.
        circle_z: (M, 2) float64 ``zmin, zmax``.
        circle_rgb: (M, 3) uint8.
        textures: list of (H, W, 3) uint8 images.
        floor_rgb, sky_rgb: colours of the ground plane and of empty space.
    """

    segments: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 4)))
    segment_z: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    segment_rgb: NDArray[np.uint8] = field(default_factory=lambda: np.zeros((0, 3), dtype=np.uint8))
    segment_texture: NDArray[np.int32] = field(default_factory=lambda: np.zeros(0, dtype=np.int32))
    circles: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    circle_z: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 2)))
    circle_rgb: NDArray[np.uint8] = field(default_factory=lambda: np.zeros((0, 3), dtype=np.uint8))
    textures: list[NDArray[np.uint8]] = field(default_factory=list)
    floor_rgb: tuple[int, int, int] = (110, 110, 110)
    sky_rgb: tuple[int, int, int] = (178, 204, 229)

    def __post_init__(self) -> None:
        self.segments = _f64(self.segments, 4)
        n = len(self.segments)
        self.segment_z = (
            _f64(self.segment_z, 2) if len(self.segment_z) else np.tile([0.0, 1.0], (n, 1))
        )
        self.segment_rgb = (
            _u8(self.segment_rgb, 3) if len(self.segment_rgb) else np.full((n, 3), 200, np.uint8)
        )
        tex = np.asarray(self.segment_texture, dtype=np.int32).reshape(-1)
        self.segment_texture = tex if len(tex) else np.full(n, -1, np.int32)
        self.circles = _f64(self.circles, 3)
        m = len(self.circles)
        self.circle_z = (
            _f64(self.circle_z, 2) if len(self.circle_z) else np.tile([0.0, 1.0], (m, 1))
        )
        self.circle_rgb = (
            _u8(self.circle_rgb, 3) if len(self.circle_rgb) else np.full((m, 3), 200, np.uint8)
        )
        for name, arr, rows in (
            ("segment_z", self.segment_z, n),
            ("segment_rgb", self.segment_rgb, n),
            ("segment_texture", self.segment_texture, n),
            ("circle_z", self.circle_z, m),
            ("circle_rgb", self.circle_rgb, m),
        ):
            if len(arr) != rows:
                raise ValueError(f"Scene.{name} has {len(arr)} rows, expected {rows}")
        if np.any(~np.isfinite(self.segments)) or np.any(~np.isfinite(self.circles)):
            raise ValueError("Scene geometry holds NaN or infinite coordinates")
        bad = self.segment_texture[(self.segment_texture >= len(self.textures))]
        if len(bad):
            raise ValueError(f"Scene.segment_texture refers to missing texture {int(bad[0])}")

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` of all geometry (zeros for an empty scene)."""
        xs: list[NDArray[np.float64]] = []
        ys: list[NDArray[np.float64]] = []
        if len(self.segments):
            xs += [self.segments[:, 0], self.segments[:, 2]]
            ys += [self.segments[:, 1], self.segments[:, 3]]
        if len(self.circles):
            xs += [self.circles[:, 0] - self.circles[:, 2], self.circles[:, 0] + self.circles[:, 2]]
            ys += [self.circles[:, 1] - self.circles[:, 2], self.circles[:, 1] + self.circles[:, 2]]
        if not xs:
            return (0.0, 0.0, 0.0, 0.0)
        x = np.concatenate(xs)
        y = np.concatenate(ys)
        return (float(x.min()), float(y.min()), float(x.max()), float(y.max()))

    @staticmethod
    def concat(scenes: list[Scene]) -> Scene:
        """One scene holding all the geometry of ``scenes`` (textures re-indexed)."""
        if not scenes:
            return Scene()
        textures: list[NDArray[np.uint8]] = []
        tex_idx: list[NDArray[np.int32]] = []
        for s in scenes:
            t = s.segment_texture.copy()
            t[t >= 0] += len(textures)
            tex_idx.append(t)
            textures.extend(s.textures)
        return Scene(
            segments=np.concatenate([s.segments for s in scenes]),
            segment_z=np.concatenate([s.segment_z for s in scenes]),
            segment_rgb=np.concatenate([s.segment_rgb for s in scenes]),
            segment_texture=np.concatenate(tex_idx),
            circles=np.concatenate([s.circles for s in scenes]),
            circle_z=np.concatenate([s.circle_z for s in scenes]),
            circle_rgb=np.concatenate([s.circle_rgb for s in scenes]),
            textures=textures,
            floor_rgb=scenes[0].floor_rgb,
            sky_rgb=scenes[0].sky_rgb,
        )
