"""Robot footprint against the world: a compiled polygon-vs-walls test and contact motion."""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.scene import Scene

__all__ = [
    "Obstacles",
    "any_near",
    "circle_polygon",
    "gather_near",
    "inner_radius",
    "polygon_hits",
    "polygon_hits_near",
]

F64 = NDArray[np.float64]


@numba.njit(cache=True, nogil=True)
def _cross(ax: float, ay: float, bx: float, by: float) -> float:
    return ax * by - ay * bx


@numba.njit(cache=True, nogil=True)
def _segments_intersect(
    p0x: float, p0y: float, p1x: float, p1y: float, q0x: float, q0y: float, q1x: float, q1y: float
) -> bool:
    rx, ry = p1x - p0x, p1y - p0y
    sx, sy = q1x - q0x, q1y - q0y
    den = _cross(rx, ry, sx, sy)
    qpx, qpy = q0x - p0x, q0y - p0y
    if abs(den) < 1e-15:
        # parallel: overlapping only if collinear and the projections overlap
        if abs(_cross(qpx, qpy, rx, ry)) > 1e-12:
            return False
        rr = rx * rx + ry * ry
        if rr < 1e-18:
            return False
        t0 = (qpx * rx + qpy * ry) / rr
        t1 = t0 + (sx * rx + sy * ry) / rr
        lo, hi = min(t0, t1), max(t0, t1)
        return hi >= 0.0 and lo <= 1.0
    t = _cross(qpx, qpy, sx, sy) / den
    u = _cross(qpx, qpy, rx, ry) / den
    return 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0


@numba.njit(cache=True, nogil=True)
def _inside(poly: np.ndarray, x: float, y: float) -> bool:
    n = poly.shape[0]
    inside = False
    j = n - 1
    for i in range(n):
        xi, yi = poly[i, 0], poly[i, 1]
        xj, yj = poly[j, 0], poly[j, 1]
        if (yi > y) != (yj > y):
            xc = xi + (y - yi) * (xj - xi) / (yj - yi)
            if x < xc:
                inside = not inside
        j = i
    return inside


@numba.njit(cache=True, nogil=True)
def _point_segment_dist2(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    dx, dy = bx - ax, by - ay
    ll = dx * dx + dy * dy
    t = 0.0
    if ll > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / ll
        t = min(1.0, max(0.0, t))
    cx, cy = ax + t * dx - px, ay + t * dy - py
    return cx * cx + cy * cy


@numba.njit(cache=True, nogil=True)
def _touches_segment(
    poly: np.ndarray,
    box: tuple[float, float, float, float],
    ax: float,
    ay: float,
    bx: float,
    by: float,
) -> bool:
    xmin, ymin, xmax, ymax = box
    if max(ax, bx) < xmin or min(ax, bx) > xmax or max(ay, by) < ymin or min(ay, by) > ymax:
        return False
    if _inside(poly, ax, ay) or _inside(poly, bx, by):
        return True
    k = poly.shape[0]
    for e in range(k):
        f = (e + 1) % k
        if _segments_intersect(ax, ay, bx, by, poly[e, 0], poly[e, 1], poly[f, 0], poly[f, 1]):
            return True
    return False


@numba.njit(cache=True, nogil=True)
def _touches_circle(
    poly: np.ndarray, box: tuple[float, float, float, float], cx: float, cy: float, r: float
) -> bool:
    xmin, ymin, xmax, ymax = box
    if cx + r < xmin or cx - r > xmax or cy + r < ymin or cy - r > ymax:
        return False
    if _inside(poly, cx, cy):
        return True
    r2 = r * r
    k = poly.shape[0]
    for e in range(k):
        f = (e + 1) % k
        if _point_segment_dist2(cx, cy, poly[e, 0], poly[e, 1], poly[f, 0], poly[f, 1]) < r2:
            return True
    return False


@numba.njit(cache=True, nogil=True)
def _bounds(poly: np.ndarray) -> tuple[float, float, float, float]:
    xmin, ymin = poly[0, 0], poly[0, 1]
    xmax, ymax = xmin, ymin
    for i in range(1, poly.shape[0]):
        x, y = poly[i, 0], poly[i, 1]
        xmin, xmax = min(xmin, x), max(xmax, x)
        ymin, ymax = min(ymin, y), max(ymax, y)
    return xmin, ymin, xmax, ymax


@numba.njit(cache=True, nogil=True)
def polygon_hits(poly: np.ndarray, segments: np.ndarray, circles: np.ndarray) -> bool:
    """True if the closed polygon ``poly`` (K, 2) touches any segment or circle."""
    box = _bounds(poly)
    for i in range(segments.shape[0]):
        s = segments[i]
        if _touches_segment(poly, box, s[0], s[1], s[2], s[3]):
            return True
    for i in range(circles.shape[0]):
        c = circles[i]
        if _touches_circle(poly, box, c[0], c[1], c[2]):
            return True
    return False


@numba.njit(cache=True, nogil=True)
def polygon_hits_near(
    poly: np.ndarray,
    segments: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
    n_segments: int,
    n_circles: int,
) -> bool:
    """:func:`polygon_hits` over a subset: ``near[:n_segments]`` index ``segments``, the
    ``n_circles`` entries after them index ``circles`` (a broad phase's candidates)."""
    box = _bounds(poly)
    for j in range(n_segments):
        s = segments[near[j]]
        if _touches_segment(poly, box, s[0], s[1], s[2], s[3]):
            return True
    for j in range(n_segments, n_segments + n_circles):
        c = circles[near[j]]
        if _touches_circle(poly, box, c[0], c[1], c[2]):
            return True
    return False


@numba.njit(cache=True, nogil=True)
def _segment_within(x: float, y: float, r2: float, s: np.ndarray) -> bool:
    return _point_segment_dist2(x, y, s[0], s[1], s[2], s[3]) <= r2


@numba.njit(cache=True, nogil=True)
def _circle_within(x: float, y: float, radius: float, c: np.ndarray) -> bool:
    return math.hypot(c[0] - x, c[1] - y) - c[2] <= radius


@numba.njit(cache=True, nogil=True)
def any_near(
    x: float,
    y: float,
    radius: float,
    segments: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
    n_segments: int,
    n_circles: int,
) -> bool:
    """Whether any of the candidates (as :func:`polygon_hits_near`) comes within
    ``radius`` of ``(x, y)``: when none does, a body inside that disc touches nothing."""
    r2 = radius * radius
    for j in range(n_segments):
        if _segment_within(x, y, r2, segments[near[j]]):
            return True
    for j in range(n_segments, n_segments + n_circles):
        if _circle_within(x, y, radius, circles[near[j]]):
            return True
    return False


@numba.njit(cache=True, nogil=True)
def gather_near(
    x: float,
    y: float,
    reach: float,
    segments: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
) -> tuple[int, int]:
    """Write into ``near`` the indices of the segments, then of the circles, that come
    within ``reach`` of ``(x, y)``; returns how many of each. A body that stays inside
    the disc of radius ``reach`` around the point can touch no other obstacle."""
    r2 = reach * reach
    ns = 0
    for i in range(segments.shape[0]):
        if _segment_within(x, y, r2, segments[i]):
            near[ns] = i
            ns += 1
    nc = 0
    for i in range(circles.shape[0]):
        if _circle_within(x, y, reach, circles[i]):
            near[ns + nc] = i
            nc += 1
    return ns, nc


def circle_polygon(radius: float, sides: int = 24) -> F64:
    """A polygon circumscribing a circle (so the polygon test never misses a contact)."""
    r = radius / math.cos(math.pi / sides)
    a = np.arange(sides) * (2 * math.pi / sides)
    return np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


class Obstacles:
    """The parts of a scene that a robot of a given height band can bump into.

    Args:
        scene: the world's scene.
        z_min, z_max: the robot body's height band above the floor; walls entirely below
            ``z_min`` (a floor mat) or above ``z_max`` (a table top) do not block it.
    """

    def __init__(self, scene: Scene, *, z_min: float = 0.02, z_max: float = 2.0) -> None:
        seg_keep = (scene.segment_z[:, 1] > z_min) & (scene.segment_z[:, 0] < z_max)
        circ_keep = (scene.circle_z[:, 1] > z_min) & (scene.circle_z[:, 0] < z_max)
        self.segments = np.ascontiguousarray(scene.segments[seg_keep])
        self.circles = np.ascontiguousarray(scene.circles[circ_keep])

    def hits(self, footprint: F64, x: float, y: float, theta: float) -> bool:
        """True if the body-frame ``footprint`` polygon at pose (x, y, theta) touches."""
        c, s = math.cos(theta), math.sin(theta)
        world = footprint @ np.array([[c, s], [-s, c]]) + np.array([x, y])
        return bool(polygon_hits(np.ascontiguousarray(world), self.segments, self.circles))


def inner_radius(footprint: F64) -> float:
    """Distance from the body origin to the nearest footprint edge."""
    best = math.inf
    k = len(footprint)
    for i in range(k):
        a, b = footprint[i], footprint[(i + 1) % k]
        d = b - a
        ll = float(d @ d)
        t = 0.0 if ll == 0 else min(1.0, max(0.0, float(-a @ d) / ll))
        c = a + t * d
        best = min(best, math.hypot(float(c[0]), float(c[1])))
    return best
