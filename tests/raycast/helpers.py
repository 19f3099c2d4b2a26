"""Test helpers: a brute-force numpy ray caster and small scene builders."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roverlab.raycast import Scene
from roverlab.raycast.accel import SEGMENT_PARAM_EPS


def box_segments(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    """The four faces of an axis-aligned box."""
    return [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]]


def brute_cast(
    scene: Scene, x: float, y: float, z: float, angles: NDArray[np.float64], range_max: float
) -> NDArray[np.float64]:
    """Every beam against every primitive, vectorised with numpy (no acceleration)."""
    d = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (N, 2)
    best = np.full(len(angles), np.inf)
    segs = scene.segments[(scene.segment_z[:, 0] <= z) & (z <= scene.segment_z[:, 1])]
    if len(segs):
        p0 = segs[:, :2]
        e = segs[:, 2:] - p0
        w = p0 - np.array([x, y])
        den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (w[None, :, 0] * e[None, :, 1] - w[None, :, 1] * e[None, :, 0]) / den
            s = (w[None, :, 0] * d[:, None, 1] - w[None, :, 1] * d[:, None, 0]) / den
        ok = (den != 0) & (t >= 0) & (s >= -SEGMENT_PARAM_EPS) & (s <= 1 + SEGMENT_PARAM_EPS)
        best = np.minimum(best, np.where(ok, t, np.inf).min(axis=1))
    circ = scene.circles[(scene.circle_z[:, 0] <= z) & (z <= scene.circle_z[:, 1])]
    if len(circ):
        f = np.array([x, y]) - circ[:, :2]  # (C, 2)
        b = d @ f.T  # (N, C)
        c = (f**2).sum(axis=1) - circ[:, 2] ** 2
        disc = b**2 - c[None, :]
        with np.errstate(invalid="ignore"):
            t = -b - np.sqrt(disc)
        ok = (disc >= 0) & (b < 0)
        t = np.where(ok, t, np.inf)
        t = np.where(c[None, :] <= 0, 0.0, t)
        best = np.minimum(best, t.min(axis=1))
    return np.where(best <= range_max, best, np.inf)


def random_scene(rng: np.random.Generator, n_seg: int = 60, n_circ: int = 12) -> Scene:
    """Random segments (up to 3 m long) and circles in a 10 m square, random z-ranges."""
    p0 = rng.uniform(-5, 5, (n_seg, 2))
    ang = rng.uniform(-np.pi, np.pi, n_seg)
    length = rng.uniform(0.05, 3.0, n_seg)
    p1 = p0 + length[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=1)
    zlo = rng.uniform(0, 0.5, n_seg + n_circ)
    zhi = zlo + rng.uniform(0.1, 1.5, n_seg + n_circ)
    return Scene(
        segments=np.hstack([p0, p1]),
        segment_z=np.stack([zlo[:n_seg], zhi[:n_seg]], axis=1),
        circles=np.column_stack([rng.uniform(-5, 5, (n_circ, 2)), rng.uniform(0.05, 1, n_circ)]),
        circle_z=np.stack([zlo[n_seg:], zhi[n_seg:]], axis=1),
    )


def cells_scene(grid: NDArray[np.bool_], resolution: float, origin: tuple[float, float]) -> Scene:
    """The faces of every occupied cell of ``grid`` (row = y index) as a Scene."""
    segs: list[list[float]] = []
    for r, c in np.argwhere(grid):
        x0 = origin[0] + c * resolution
        y0 = origin[1] + r * resolution
        segs += box_segments(x0, y0, x0 + resolution, y0 + resolution)
    return Scene(segments=np.array(segs))
