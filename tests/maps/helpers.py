"""Pure-numpy references and fixtures for the map tests."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.lidar import cast_grid


def ref_trace(
    g0: tuple[float, float], g1: tuple[float, float], w: int, h: int
) -> list[tuple[int, int]]:
    """Cells ``(ix, iy)`` of ``[0, w) x [0, h)`` crossed by segment ``g0 -> g1`` (cell units).

    Built from all boundary crossings at once: every crossing parameter ``t`` of a vertical
    and a horizontal cell boundary in ``(0, 1)``, sorted (x before y on a tie), stepped from
    the start cell with a cumulative sum; cells outside the grid dropped.
    """
    p0 = np.array(g0, dtype=np.float64)
    p1 = np.array(g1, dtype=np.float64)
    d = p1 - p0
    ts: list[NDArray[np.float64]] = []
    axes: list[NDArray[np.int64]] = []
    steps: list[NDArray[np.int64]] = []
    for axis in (0, 1):
        if d[axis] == 0.0:
            continue
        lo, hi = sorted((math.floor(p0[axis]), math.floor(p1[axis])))
        k = np.arange(lo, hi + 2, dtype=np.float64)
        t = (k - p0[axis]) / d[axis]
        keep = (t > 0.0) & (t < 1.0)
        ts.append(t[keep])
        axes.append(np.full(int(keep.sum()), axis))
        steps.append(np.full(int(keep.sum()), 1 if d[axis] > 0 else -1))
    start = np.floor(p0).astype(np.int64)
    if ts:
        t_all = np.concatenate(ts)
        ax_all = np.concatenate(axes)
        st_all = np.concatenate(steps)
        order = np.lexsort((ax_all, t_all))
        dx = np.where(ax_all[order] == 0, st_all[order], 0)
        dy = np.where(ax_all[order] == 1, st_all[order], 0)
        ix = np.concatenate([[start[0]], start[0] + np.cumsum(dx)])
        iy = np.concatenate([[start[1]], start[1] + np.cumsum(dy)])
    else:
        ix, iy = np.array([start[0]]), np.array([start[1]])
    inside = (ix >= 0) & (ix < w) & (iy >= 0) & (iy < h)
    return list(zip(ix[inside].tolist(), iy[inside].tolist(), strict=True))


def ref_beams(
    pose: tuple[float, float, float],
    ranges: NDArray[np.float64],
    angles: NDArray[np.float64],
    range_max: float,
    usable: float,
    origin: tuple[float, float],
    res: float,
) -> tuple[tuple[float, float], list[tuple[float, float, bool]]]:
    """Laser position and beam ends ``(gx, gy, hit)`` in cell units, per the documented
    beam rules (written out again, independently of ScanRays)."""
    x, y, th = pose
    out = []
    for r, a in zip(ranges.tolist(), angles.tolist(), strict=True):
        if math.isnan(r) or r <= 0.0:
            continue
        length = min(r, usable)
        hit = r < usable
        ex = x + length * np.cos(np.float64(th) + np.float64(a))
        ey = y + length * np.sin(np.float64(th) + np.float64(a))
        out.append(((ex - origin[0]) / res, (ey - origin[1]) / res, hit))
    return ((x - origin[0]) / res, (y - origin[1]) / res), out


def ref_log_odds(
    lo: NDArray[np.float32],
    g0: tuple[float, float],
    beams: list[tuple[float, float, bool]],
    l_occ: float,
    l_free: float,
    l_min: float,
    l_max: float,
) -> NDArray[np.float32]:
    """One scan on a log-odds array: each hit cell +l_occ once, each other crossed cell
    +l_free once, clamped."""
    h, w = lo.shape
    hits: set[tuple[int, int]] = set()
    for gx, gy, hit in beams:
        ix, iy = math.floor(gx), math.floor(gy)
        if hit and 0 <= ix < w and 0 <= iy < h:
            hits.add((ix, iy))
    free: set[tuple[int, int]] = set()
    for gx, gy, _ in beams:
        free.update(ref_trace(g0, (gx, gy), w, h))
    free -= hits
    out = lo.astype(np.float64)
    for cells, delta in ((hits, l_occ), (free, l_free)):
        if cells:
            ix, iy = np.array(sorted(cells)).T
            out[iy, ix] = np.clip(out[iy, ix] + delta, l_min, l_max)
    return out.astype(np.float32)


def ref_counts(
    hits: NDArray[np.int32],
    visits: NDArray[np.int32],
    g0: tuple[float, float],
    beams: list[tuple[float, float, bool]],
) -> None:
    """One scan on hit / visit counts (in place): per beam, visit every crossed cell and
    hit + visit the end cell once."""
    h, w = hits.shape
    for gx, gy, hit in beams:
        end = (math.floor(gx), math.floor(gy))
        has_end = hit and 0 <= end[0] < w and 0 <= end[1] < h
        if has_end:
            hits[end[1], end[0]] += 1
            visits[end[1], end[0]] += 1
        for c in ref_trace(g0, (gx, gy), w, h):
            if not (has_end and c == end):
                visits[c[1], c[0]] += 1


def square_room(
    *, size_m: float = 6.0, res: float = 0.05, half_inner_m: float = 2.0, wall_cells: int = 3
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], tuple[float, float]]:
    """Ground truth of a square room centred on (0, 0): ``(walls, interior, origin)``,
    rasterised from cell centres."""
    n = round(size_m / res)
    origin = (-size_m / 2, -size_m / 2)
    centres = origin[0] + (np.arange(n) + 0.5) * res
    cx, cy = np.meshgrid(centres, centres)
    cheb = np.maximum(np.abs(cx), np.abs(cy))
    interior = cheb < half_inner_m
    walls = (cheb > half_inner_m) & (cheb < half_inner_m + wall_cells * res)
    return walls, interior, origin


def simulate_scan(
    walls: NDArray[np.bool_],
    origin: tuple[float, float],
    res: float,
    pose: tuple[float, float, float],
    angles: NDArray[np.float64],
    range_max: float,
) -> NDArray[np.float64]:
    """Exact ranges to the first wall cell (inf beyond ``range_max``), ended a hair inside
    the wall so the end point lies in the wall cell rather than on its face."""
    r = cast_grid(walls, res, origin, pose[0], pose[1], pose[2] + angles, range_max)
    return np.where(np.isfinite(r), r + 1e-7, np.inf)
