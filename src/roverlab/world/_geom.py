"""Small vectorised planar-geometry kernels used by the world model (private).

Polygons are ``(K, 2)`` vertex arrays (implicitly closed); edge arrays are ``(E, 4)``
``x0, y0, x1, y1``. Nothing here loops over cells, points or edges in Python.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


def signed_area(poly: ArrayLike) -> float:
    """Shoelace area of a closed polygon: positive when counter-clockwise."""
    p = np.asarray(poly, dtype=np.float64)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def convex_hull(points: ArrayLike) -> FloatArray:
    """Counter-clockwise convex hull (Andrew's monotone chain) of a few (N, 2) points."""
    pts = np.unique(np.asarray(points, dtype=np.float64).reshape(-1, 2), axis=0)
    if len(pts) < 3:
        return pts

    def cross(o: FloatArray, a: FloatArray, b: FloatArray) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    lower: list[FloatArray] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0.0:
            lower.pop()
        lower.append(p)
    upper: list[FloatArray] = []
    for p in pts[::-1]:
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0.0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def polygon_edges(poly: FloatArray) -> FloatArray:
    """(K, 4) edges of a closed polygon, vertex i to vertex i+1 (mod K)."""
    return np.concatenate([poly, np.roll(poly, -1, axis=0)], axis=1)


def crossings(px: FloatArray, py: FloatArray, edges: FloatArray) -> BoolArray:
    """(N, E): does the ray from point n towards +x cross edge e (even-odd rule)?"""
    x0, y0, x1, y1 = (edges[:, k][None, :] for k in range(4))
    ys = py[:, None]
    straddles = (y0 > ys) != (y1 > ys)
    dy = np.where(y1 == y0, 1.0, y1 - y0)
    xc = x0 + (ys - y0) * (x1 - x0) / dy
    result: BoolArray = straddles & (px[:, None] < xc)
    return result


def points_in_polygon(px: FloatArray, py: FloatArray, edges: FloatArray) -> BoolArray:
    """(N,) even-odd inside test of points against one polygon given by its edges."""
    result: BoolArray = (np.count_nonzero(crossings(px, py, edges), axis=1) % 2) == 1
    return result


def edges_hit_boxes(cx: FloatArray, cy: FloatArray, half: float, edges: FloatArray) -> BoolArray:
    """(N,): does any edge intersect the open square of half-size ``half`` at (cx, cy)?

    Separating-axis test with the two box axes and the edge normal (exact for a segment
    against an axis-aligned box).
    """
    x0, y0, x1, y1 = (edges[:, k][None, :] for k in range(4))
    X = cx[:, None]
    Y = cy[:, None]
    overlap = (
        (np.minimum(x0, x1) < X + half)
        & (np.maximum(x0, x1) > X - half)
        & (np.minimum(y0, y1) < Y + half)
        & (np.maximum(y0, y1) > Y - half)
    )
    nx = y0 - y1
    ny = x1 - x0
    dist = nx * (X - x0) + ny * (Y - y0)
    radius = half * (np.abs(nx) + np.abs(ny))
    result: BoolArray = np.any(overlap & (np.abs(dist) < radius), axis=1)
    return result


def point_segment_distance(px: FloatArray, py: FloatArray, edges: FloatArray) -> FloatArray:
    """(N, E) distance from each point to each segment."""
    x0, y0, x1, y1 = (edges[:, k][None, :] for k in range(4))
    dx = x1 - x0
    dy = y1 - y0
    len2 = dx * dx + dy * dy
    t = ((px[:, None] - x0) * dx + (py[:, None] - y0) * dy) / np.where(len2 > 0.0, len2, 1.0)
    t = np.clip(t, 0.0, 1.0)
    ex = x0 + t * dx - px[:, None]
    ey = y0 + t * dy - py[:, None]
    result: FloatArray = np.hypot(ex, ey)
    return result


def segments_cross(a: FloatArray, b: FloatArray) -> BoolArray:
    """(A, B): do segments a[i] and b[j] cross properly (interiors intersect at a point)?"""

    def orient(
        px: FloatArray,
        py: FloatArray,
        qx: FloatArray,
        qy: FloatArray,
        rx: FloatArray,
        ry: FloatArray,
    ) -> FloatArray:
        result: FloatArray = np.sign((qx - px) * (ry - py) - (qy - py) * (rx - px))
        return result

    ax0, ay0, ax1, ay1 = (a[:, k][:, None] for k in range(4))
    bx0, by0, bx1, by1 = (b[:, k][None, :] for k in range(4))
    d1 = orient(ax0, ay0, ax1, ay1, bx0, by0)
    d2 = orient(ax0, ay0, ax1, ay1, bx1, by1)
    d3 = orient(bx0, by0, bx1, by1, ax0, ay0)
    d4 = orient(bx0, by0, bx1, by1, ax1, ay1)
    result: BoolArray = (d1 * d2 < 0) & (d3 * d4 < 0)
    return result
