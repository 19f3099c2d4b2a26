"""Robot footprints as costmap_2d handles them (``costmap_2d/footprint.h``).

A footprint is an ``(N, 2)`` polygon in the robot frame (m). ``robot_radius`` gives a
16-gon; ``footprint_padding`` pushes every vertex away from both axes; the inscribed and
circumscribed radii are the smallest and largest distance from the robot centre to a
vertex or an edge.
"""

from __future__ import annotations

import ast
import math
from typing import Any

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.navigation.errors import NavigationParamsError

__all__ = [
    "footprint_from_param",
    "footprint_from_radius",
    "footprint_radii",
    "pad_footprint",
    "transform_footprint",
]

FloatArray = NDArray[np.float64]


def footprint_from_radius(radius: float) -> FloatArray:
    """costmap_2d's ``makeFootprintFromRadius``: 16 points on the circle, from angle 0."""
    a = np.arange(16) * (2.0 * math.pi / 16)
    return np.column_stack([np.cos(a) * radius, np.sin(a) * radius])


def footprint_from_param(value: Any, *, where: str = "footprint") -> FloatArray | None:
    """A footprint from a ``footprint`` parameter: a list of ``[x, y]`` pairs or the same
    as a string (``"[[0.1, 0.1], [-0.1, 0.1], ...]"``). ``""`` and ``"[]"`` give None
    (use ``robot_radius``).

    Raises:
        NavigationParamsError: not a list of at least three finite ``[x, y]`` pairs.
    """
    data = value
    if isinstance(value, str):
        text = value.strip()
        if text in ("", "[]"):
            return None
        try:
            data = ast.literal_eval(text)
        except (ValueError, SyntaxError) as err:
            raise NavigationParamsError(
                f"{where}: cannot read footprint {value!r} (expected [[x1, y1], [x2, y2], ...])"
            ) from err
    if isinstance(data, list | tuple) and len(data) == 0:
        return None
    try:
        pts = np.asarray(data, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise NavigationParamsError(
            f"{where}: footprint must be a list of [x, y] points, got {value!r}"
        ) from err
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise NavigationParamsError(
            f"{where}: footprint must be a list of [x, y] points, got {value!r}"
        )
    if len(pts) < 3:
        raise NavigationParamsError(
            f"{where}: you must specify at least three points for the robot footprint"
        )
    if not np.isfinite(pts).all():
        raise NavigationParamsError(f"{where}: footprint points must be finite")
    return pts


def pad_footprint(footprint: ArrayLike, padding: float) -> FloatArray:
    """costmap_2d's ``padFootprint``: each coordinate moves ``padding`` away from 0."""
    pts = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    return pts + np.sign(pts) * padding


def _point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom == 0.0 else min(1.0, max(0.0, float((p - a) @ ab) / denom))
    return float(np.hypot(*(a + t * ab - p)))


def footprint_radii(footprint: ArrayLike) -> tuple[float, float]:
    """``(inscribed, circumscribed)`` radius (costmap_2d's ``calculateMinAndMaxDistances``):
    min and max over the vertices and edges of the distance to the robot centre. A
    footprint of fewer than three points gives ``(0, 0)``."""
    pts = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    if len(pts) < 3:
        return 0.0, 0.0
    origin = np.zeros(2)
    lo, hi = math.inf, 0.0
    for k in range(len(pts)):
        a, b = pts[k], pts[(k + 1) % len(pts)]
        v = float(np.hypot(*a))
        e = _point_segment_distance(origin, a, b)
        lo = min(lo, v, e)
        hi = max(hi, v, e)
    return lo, hi


def transform_footprint(x: float, y: float, yaw: float, footprint: ArrayLike) -> FloatArray:
    """The footprint placed at robot pose ``(x, y, yaw)`` in the global frame."""
    pts = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    return _place(pts, float(x), float(y), math.cos(yaw), math.sin(yaw))


@numba.njit(cache=True, nogil=True)
def _place(pts: FloatArray, x: float, y: float, c: float, s: float) -> FloatArray:
    """``x + px c - py s``, ``y + px s + py c`` of each point, in numpy's order of the
    operations (the same values; one compiled call instead of six array operations)."""
    out = np.empty((pts.shape[0], 2))
    for k in range(pts.shape[0]):
        out[k, 0] = x + pts[k, 0] * c - pts[k, 1] * s
        out[k, 1] = y + pts[k, 0] * s + pts[k, 1] * c
    return out
