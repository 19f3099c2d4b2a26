"""Compile shapes into 2.5-D primitives and flat arrays (private to :mod:`roverlab.world`).

Every shape becomes one primitive standing upright between ``zmin`` and ``zmax``:

* a **prism**: a polygon (counter-clockwise, so a texture reads left to right when seen
  from outside) extruded vertically;
* a **disc**: a vertical cylinder ``(cx, cy, r)``;
* a **panel**: one vertical face with no thickness (a poster; visual only).

Upright boxes, cylinders and polylines are exact. A shape whose axes are tilted (roll or
pitch not a multiple of 90 degrees) becomes the vertical prism over the convex hull of its
projected corners between its lowest and highest point: the smallest upright prism that
contains it (a 2.5-D approximation). Spheres become their bounding cylinder.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import Transform3, quat_rotate
from roverlab.world._geom import (
    BoolArray,
    FloatArray,
    convex_hull,
    crossings,
    edges_hit_boxes,
    point_segment_distance,
    points_in_polygon,
    polygon_edges,
    segments_cross,
    signed_area,
)

_VERTICAL_TOL = 1e-6
_HULL_SAMPLES = 32


@dataclass(frozen=True, eq=False)
class Prism:
    polygon: FloatArray
    zmin: float
    zmax: float


@dataclass(frozen=True, eq=False)
class Disc:
    cx: float
    cy: float
    r: float
    zmin: float
    zmax: float


@dataclass(frozen=True, eq=False)
class Panel:
    segment: tuple[float, float, float, float]
    zmin: float
    zmax: float


Primitive = Prism | Disc | Panel


def _axes(tf: Transform3) -> FloatArray:
    """Row k = local axis k expressed in the world frame."""
    axes: FloatArray = quat_rotate(tf.rotation, np.eye(3))
    return axes


def _clean_polygon(poly: FloatArray) -> FloatArray:
    """Drop repeated and closing vertices; orient counter-clockwise."""
    keep = np.ones(len(poly), dtype=bool)
    keep[1:] = np.any(np.abs(np.diff(poly, axis=0)) > 1e-12, axis=1)
    p = poly[keep]
    if len(p) > 1 and np.allclose(p[0], p[-1], atol=1e-12):
        p = p[:-1]
    if signed_area(p) < 0.0:
        p = p[::-1]
    return np.ascontiguousarray(p)


def box_primitive(tf: Transform3, size: tuple[float, float, float]) -> Prism:
    axes = _axes(tf)
    half = 0.5 * np.asarray(size, dtype=np.float64)
    c = np.asarray(tf.translation, dtype=np.float64)
    vertical = np.flatnonzero(np.abs(np.abs(axes[:, 2]) - 1.0) < _VERTICAL_TOL)
    if len(vertical):
        k = int(vertical[0])
        a, b = (k + 1) % 3, (k + 2) % 3
        ua = axes[a, :2] * half[a]
        ub = axes[b, :2] * half[b]
        poly = c[:2] + np.array([-ua - ub, ua - ub, ua + ub, -ua + ub])
        return Prism(_clean_polygon(poly), float(c[2] - half[k]), float(c[2] + half[k]))
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    corners = c + (signs * half) @ axes
    return Prism(
        convex_hull(corners[:, :2]), float(corners[:, 2].min()), float(corners[:, 2].max())
    )


def cylinder_primitive(tf: Transform3, radius: float, length: float) -> Disc | Prism:
    axes = _axes(tf)
    c = np.asarray(tf.translation, dtype=np.float64)
    axis = axes[2]
    az = abs(float(axis[2]))
    if abs(az - 1.0) < _VERTICAL_TOL:
        h = 0.5 * length
        return Disc(float(c[0]), float(c[1]), radius, float(c[2] - h), float(c[2] + h))
    if az < _VERTICAL_TOL:
        along = axis[:2] / np.linalg.norm(axis[:2]) * (0.5 * length)
        across = np.array([-along[1], along[0]]) / np.linalg.norm(along) * radius
        poly = c[:2] + np.array([-along - across, along - across, along + across, -along + across])
        return Prism(_clean_polygon(poly), float(c[2] - radius), float(c[2] + radius))
    theta = np.linspace(0.0, 2.0 * math.pi, _HULL_SAMPLES, endpoint=False)
    r_out = radius / math.cos(math.pi / _HULL_SAMPLES)
    ring = r_out * (np.cos(theta)[:, None] * axes[0] + np.sin(theta)[:, None] * axes[1])
    ends = np.concatenate([c + 0.5 * length * axis + ring, c - 0.5 * length * axis + ring])
    return Prism(convex_hull(ends[:, :2]), float(ends[:, 2].min()), float(ends[:, 2].max()))


def sphere_primitive(tf: Transform3, radius: float) -> Disc:
    x, y, z = tf.translation
    return Disc(x, y, radius, z - radius, z + radius)


def polyline_primitive(
    tf: Transform3, points: tuple[tuple[float, float], ...], height: float
) -> Prism:
    local = np.asarray(points, dtype=np.float64)
    axes = _axes(tf)
    bottom = tf.apply(np.column_stack([local, np.zeros(len(local))]))
    az = float(axes[2, 2])
    if abs(abs(az) - 1.0) < _VERTICAL_TOL:
        z0 = float(tf.translation[2])
        z1 = z0 + math.copysign(height, az)
        return Prism(_clean_polygon(bottom[:, :2]), min(z0, z1), max(z0, z1))
    top = bottom + height * axes[2]
    allp = np.concatenate([bottom, top])
    return Prism(convex_hull(allp[:, :2]), float(allp[:, 2].min()), float(allp[:, 2].max()))


@dataclass(frozen=True, eq=False)
class Compiled:
    """Flat arrays of a world's primitives (see the module docstring)."""

    poly_xy: FloatArray  # (V, 2) vertices of all prisms, concatenated
    poly_offsets: NDArray[np.int64]  # (P + 1,) prism p owns vertices/edges [off[p], off[p+1])
    poly_z: FloatArray  # (P, 2)
    poly_rgb: NDArray[np.uint8]  # (P, 3)
    poly_texture: NDArray[np.int32]  # (P,) index into texture_paths or -1
    poly_rect: BoolArray  # (P,) axis-aligned rectangle
    poly_bbox: FloatArray  # (P, 4) xmin, ymin, xmax, ymax
    edges: FloatArray  # (V, 4) prism edges, same indexing as poly_xy
    edge_owner: NDArray[np.int64]  # (V,)
    circles: FloatArray  # (C, 3)
    circle_z: FloatArray  # (C, 2)
    circle_rgb: NDArray[np.uint8]  # (C, 3)
    panels: FloatArray  # (S, 4)
    panel_z: FloatArray  # (S, 2)
    panel_rgb: NDArray[np.uint8]  # (S, 3)
    panel_texture: NDArray[np.int32]  # (S,)
    texture_paths: tuple[Path, ...]

    @staticmethod
    def build(items: list[tuple[Primitive, tuple[int, int, int], Path | None]]) -> Compiled:
        textures: dict[Path, int] = {}

        def tex_index(path: Path | None) -> int:
            if path is None:
                return -1
            return textures.setdefault(path, len(textures))

        polys: list[FloatArray] = []
        pz: list[tuple[float, float]] = []
        prgb: list[tuple[int, int, int]] = []
        ptex: list[int] = []
        circ: list[tuple[float, float, float]] = []
        cz: list[tuple[float, float]] = []
        crgb: list[tuple[int, int, int]] = []
        pan: list[tuple[float, float, float, float]] = []
        panz: list[tuple[float, float]] = []
        panrgb: list[tuple[int, int, int]] = []
        pantex: list[int] = []
        for prim, rgb, texture in items:
            if isinstance(prim, Prism):
                polys.append(prim.polygon)
                pz.append((prim.zmin, prim.zmax))
                prgb.append(rgb)
                ptex.append(tex_index(texture))
            elif isinstance(prim, Disc):
                circ.append((prim.cx, prim.cy, prim.r))
                cz.append((prim.zmin, prim.zmax))
                crgb.append(rgb)
            else:
                pan.append(prim.segment)
                panz.append((prim.zmin, prim.zmax))
                panrgb.append(rgb)
                pantex.append(tex_index(texture))
        counts = np.array([len(p) for p in polys], dtype=np.int64)
        offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        xy = np.concatenate(polys) if polys else np.zeros((0, 2))
        edges = np.concatenate([polygon_edges(p) for p in polys]) if polys else np.zeros((0, 4))
        owner = np.repeat(np.arange(len(polys), dtype=np.int64), counts)
        rect = np.array([_is_rect(p) for p in polys], dtype=bool)
        bbox = (
            np.array([[*p.min(axis=0), *p.max(axis=0)] for p in polys])
            if polys
            else np.zeros((0, 4))
        )
        return Compiled(
            poly_xy=xy,
            poly_offsets=offsets,
            poly_z=_arr(pz, 2),
            poly_rgb=_rgb(prgb),
            poly_texture=np.array(ptex, dtype=np.int32),
            poly_rect=rect,
            poly_bbox=bbox,
            edges=edges,
            edge_owner=owner,
            circles=_arr(circ, 3),
            circle_z=_arr(cz, 2),
            circle_rgb=_rgb(crgb),
            panels=_arr(pan, 4),
            panel_z=_arr(panz, 2),
            panel_rgb=_rgb(panrgb),
            panel_texture=np.array(pantex, dtype=np.int32),
            texture_paths=tuple(textures),
        )

    def bounds(self, *, solid_only: bool = False) -> tuple[float, float, float, float] | None:
        xs: list[FloatArray] = [self.poly_xy[:, 0]]
        ys: list[FloatArray] = [self.poly_xy[:, 1]]
        c = self.circles
        xs += [c[:, 0] - c[:, 2], c[:, 0] + c[:, 2]]
        ys += [c[:, 1] - c[:, 2], c[:, 1] + c[:, 2]]
        if not solid_only:
            xs += [self.panels[:, 0], self.panels[:, 2]]
            ys += [self.panels[:, 1], self.panels[:, 3]]
        x = np.concatenate(xs)
        y = np.concatenate(ys)
        if not len(x):
            return None
        return (float(x.min()), float(y.min()), float(x.max()), float(y.max()))

    def band(self, z_min: float, z_max: float) -> tuple[BoolArray, BoolArray]:
        """Masks of the prisms and discs that reach into the height band [z_min, z_max]."""
        return _in_band(self.poly_z, z_min, z_max), _in_band(self.circle_z, z_min, z_max)

    # ----------------------------------------------------------------- rasterising

    def rasterise(
        self,
        origin: tuple[float, float],
        resolution: float,
        shape: tuple[int, int],
        z_min: float,
        z_max: float,
    ) -> BoolArray:
        """Cells (row 0 at ``origin`` y) whose open square overlaps a solid primitive."""
        height, width = shape
        ox, oy = origin
        grid = np.zeros(shape, dtype=bool)
        psel, csel = self.band(z_min, z_max)
        eps = 1e-6
        # Axis-aligned rectangles: all at once through a 2-D difference array.
        rects = self.poly_bbox[psel & self.poly_rect]
        if len(rects):
            a0 = np.clip(np.floor((rects[:, 0] - ox) / resolution + eps), 0, width).astype(int)
            a1 = np.clip(np.ceil((rects[:, 2] - ox) / resolution - eps), 0, width).astype(int)
            b0 = np.clip(np.floor((rects[:, 1] - oy) / resolution + eps), 0, height).astype(int)
            b1 = np.clip(np.ceil((rects[:, 3] - oy) / resolution - eps), 0, height).astype(int)
            ok = (a1 > a0) & (b1 > b0)
            a0, a1, b0, b1 = a0[ok], a1[ok], b0[ok], b1[ok]
            diff = np.zeros((height + 1, width + 1), dtype=np.int64)
            np.add.at(diff, (b0, a0), 1)
            np.add.at(diff, (b0, a1), -1)
            np.add.at(diff, (b1, a0), -1)
            np.add.at(diff, (b1, a1), 1)
            grid |= np.cumsum(np.cumsum(diff, axis=0), axis=1)[:height, :width] > 0
        half = resolution * (0.5 - eps)
        # Other polygons: one window per polygon, every cell of the window at once.
        for p in np.flatnonzero(psel & ~self.poly_rect):
            win = _window(self.poly_bbox[p], origin, resolution, shape)
            if win is None:
                continue
            i0, i1, j0, j1 = win
            edges = self.edges[self.poly_offsets[p] : self.poly_offsets[p + 1]]
            cx = ox + (np.arange(i0, i1) + 0.5) * resolution
            rows_per_chunk = max(1, 2_000_000 // max(1, (i1 - i0) * len(edges)))
            for r0 in range(j0, j1, rows_per_chunk):
                r1 = min(j1, r0 + rows_per_chunk)
                cy = oy + (np.arange(r0, r1) + 0.5) * resolution
                X, Y = (a.ravel() for a in np.meshgrid(cx, cy))
                hit = points_in_polygon(X, Y, edges) | edges_hit_boxes(X, Y, half, edges)
                grid[r0:r1, i0:i1] |= hit.reshape(r1 - r0, i1 - i0)
        for cx_, cy_, r in self.circles[csel]:
            win = _window((cx_ - r, cy_ - r, cx_ + r, cy_ + r), origin, resolution, shape)
            if win is None:
                continue
            i0, i1, j0, j1 = win
            xs = ox + (np.arange(i0, i1) + 0.5) * resolution
            ys = oy + (np.arange(j0, j1) + 0.5) * resolution
            dx = np.maximum(np.abs(xs - cx_) - half, 0.0)[None, :]
            dy = np.maximum(np.abs(ys - cy_) - half, 0.0)[:, None]
            grid[j0:j1, i0:i1] |= dx * dx + dy * dy < r * r
        return grid

    # ------------------------------------------------------------------ collisions

    def disc_collides(self, x: float, y: float, radius: float, z_min: float, z_max: float) -> bool:
        psel, csel = self.band(z_min, z_max)
        c = self.circles[csel]
        if len(c) and bool(np.any(np.hypot(c[:, 0] - x, c[:, 1] - y) < c[:, 2] + radius)):
            return True
        near = psel & _bbox_overlap(
            self.poly_bbox, (x - radius, y - radius, x + radius, y + radius)
        )
        if not np.any(near):
            return False
        emask = near[self.edge_owner]
        edges = self.edges[emask]
        px = np.array([x])
        py = np.array([y])
        if bool(np.any(point_segment_distance(px, py, edges) < radius)):
            return True
        cross = crossings(px, py, edges)[0]
        counts = np.bincount(self.edge_owner[emask][cross], minlength=len(near))
        return bool(np.any(counts % 2 == 1))

    def polygon_collides(self, poly: FloatArray, z_min: float, z_max: float) -> bool:
        psel, csel = self.band(z_min, z_max)
        box = (*poly.min(axis=0), *poly.max(axis=0))
        redges = polygon_edges(poly)
        c = self.circles[csel]
        if len(c):
            inside = points_in_polygon(c[:, 0], c[:, 1], redges)
            close = np.min(point_segment_distance(c[:, 0], c[:, 1], redges), axis=1) < c[:, 2]
            if bool(np.any(inside | close)):
                return True
        near = psel & _bbox_overlap(self.poly_bbox, box)
        if not np.any(near):
            return False
        emask = near[self.edge_owner]
        edges = self.edges[emask]
        owner = self.edge_owner[emask]
        if bool(np.any(segments_cross(redges, edges))):
            return True
        # A robot vertex inside a shape (covers the robot lying wholly inside one).
        cross = crossings(poly[:, 0], poly[:, 1], edges)
        k, e = np.nonzero(cross)
        counts = np.bincount(k * len(near) + owner[e], minlength=len(poly) * len(near))
        if bool(np.any(counts % 2 == 1)):
            return True
        # A shape vertex inside the robot (covers a shape lying wholly inside the robot).
        verts = self.poly_xy[emask]
        return bool(np.any(points_in_polygon(verts[:, 0], verts[:, 1], redges)))


def _in_band(z: FloatArray, z_min: float, z_max: float) -> BoolArray:
    if z_max > z_min:
        result: BoolArray = (z[:, 0] < z_max) & (z[:, 1] > z_min)
    else:
        result = (z[:, 0] <= z_min) & (z[:, 1] >= z_min)
    return result


def _bbox_overlap(bbox: FloatArray, box: tuple[float, ...]) -> BoolArray:
    result: BoolArray = (
        (bbox[:, 0] < box[2])
        & (bbox[:, 2] > box[0])
        & (bbox[:, 1] < box[3])
        & (bbox[:, 3] > box[1])
    )
    return result


def _window(
    bbox: FloatArray | tuple[float, float, float, float],
    origin: tuple[float, float],
    resolution: float,
    shape: tuple[int, int],
) -> tuple[int, int, int, int] | None:
    height, width = shape
    i0 = max(0, math.floor((bbox[0] - origin[0]) / resolution))
    i1 = min(width, math.ceil((bbox[2] - origin[0]) / resolution))
    j0 = max(0, math.floor((bbox[1] - origin[1]) / resolution))
    j1 = min(height, math.ceil((bbox[3] - origin[1]) / resolution))
    if i1 <= i0 or j1 <= j0:
        return None
    return i0, i1, j0, j1


def _is_rect(poly: FloatArray) -> bool:
    if len(poly) != 4:
        return False
    d = np.roll(poly, -1, axis=0) - poly
    scale = max(1.0, float(np.abs(poly).max()))
    axis_parallel = (np.abs(d[:, 0]) < 1e-9 * scale) | (np.abs(d[:, 1]) < 1e-9 * scale)
    return bool(np.all(axis_parallel))


def _arr(rows: Sequence[tuple[float, ...]], cols: int) -> FloatArray:
    if not rows:
        return np.zeros((0, cols))
    return np.asarray(rows, dtype=np.float64).reshape(-1, cols)


def _rgb(rows: list[tuple[int, int, int]]) -> NDArray[np.uint8]:
    if not rows:
        return np.zeros((0, 3), dtype=np.uint8)
    return np.asarray(rows, dtype=np.uint8).reshape(-1, 3)
