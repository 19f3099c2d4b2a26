"""The obstacle layer's compiled passes (a scan's projection, ray clearing, marking)
against the plain numpy versions they replaced: the same cells, bounds and points, bit
for bit, so a speed-up changes no costmap."""

from __future__ import annotations

import numpy as np
import pytest

from roverlab.geometry import Transform3, quat_from_rpy
from roverlab.navigation.costmap.kernels import (
    clear_rays,
    combine_max,
    height_filter,
    mark_observation,
    raytrace_freespace,
    scan_points,
)
from roverlab.navigation.costmap.obstacle_layer import project_scan


def _numpy_raytrace(
    grid: np.ndarray, pts: np.ndarray, ox: float, oy: float, x0: float, y0: float,
    res: float, rng_m: float,
) -> tuple[float, float, float, float] | None:  # fmt: skip
    """The numpy clipping, clear_rays and updateRaytraceBounds of the layer before."""
    h, w = grid.shape
    x1, y1 = x0 + w * res, y0 + h * res
    wx, wy = pts[:, 0].copy(), pts[:, 1].copy()
    a, b = wx - ox, wy - oy
    with np.errstate(divide="ignore", invalid="ignore"):
        m = wx < x0
        t = (x0 - ox) / a
        wx, wy = np.where(m, x0, wx), np.where(m, oy + b * t, wy)
        m = wy < y0
        t = (y0 - oy) / b
        wx, wy = np.where(m, ox + a * t, wx), np.where(m, y0, wy)
        m = wx > x1
        t = (x1 - ox) / a
        wx, wy = np.where(m, x1 - 0.001, wx), np.where(m, oy + b * t, wy)
        m = wy > y1
        t = (y1 - oy) / b
        wx, wy = np.where(m, ox + a * t, wx), np.where(m, y1 - 0.001, wy)
    ok = np.isfinite(wx) & np.isfinite(wy) & (wx >= x0) & (wy >= y0) & (wx < x1) & (wy < y1)
    wx, wy = wx[ok], wy[ok]
    if len(wx) == 0:
        return None
    ends = np.column_stack([(wx - x0) / res, (wy - y0) / res])
    buf = np.empty(w + h + 4, dtype=np.int64)
    clear_rays(grid, (ox - x0) / res, (oy - y0) / res, ends, rng_m / res, 0, buf)
    dx, dy = wx - ox, wy - oy
    full = np.hypot(dx, dy)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = np.where(full > 0, np.minimum(1.0, rng_m / full), 1.0)
    ex, ey = ox + dx * scale, oy + dy * scale
    return float(ex.min()), float(ey.min()), float(ex.max()), float(ey.max())


def _numpy_mark(
    grid: np.ndarray, pts: np.ndarray, origin: np.ndarray, max_h: float, rng_m: float,
    gx: float, gy: float, res: float,
) -> tuple[float, float, float, float] | None:  # fmt: skip
    h, w = grid.shape
    d2 = np.sum((pts - origin) ** 2, axis=1)
    keep = (pts[:, 2] <= max_h) & (d2 < rng_m * rng_m) & (pts[:, 0] >= gx) & (pts[:, 1] >= gy)
    p = pts[keep]
    mx = ((p[:, 0] - gx) / res).astype(np.int64)
    my = ((p[:, 1] - gy) / res).astype(np.int64)
    inside = (mx < w) & (my < h)
    if not inside.any():
        return None
    grid[my[inside], mx[inside]] = 254
    p = p[inside]
    return float(p[:, 0].min()), float(p[:, 1].min()), float(p[:, 0].max()), float(p[:, 1].max())


@pytest.mark.parametrize("seed", range(4))
def test_clearing_and_marking_match_the_numpy_passes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    res, x0, y0 = 0.05, -2.0, -1.5
    base = rng.choice(np.array([0, 254, 255], dtype=np.uint8), size=(80, 90))
    ox, oy = float(rng.uniform(-1.5, 2.0)), float(rng.uniform(-1.0, 2.0))
    ang = rng.uniform(-np.pi, np.pi, 400)
    dist = rng.uniform(0.0, 6.0, 400)
    pts = np.column_stack(
        [ox + dist * np.cos(ang), oy + dist * np.sin(ang), rng.uniform(-1, 3, 400)]
    )
    pts[:4, :2] = [[ox, oy], [ox + 9.0, oy], [ox, oy - 7.0], [-50.0, -50.0]]  # on the origin, far
    origin = np.array([ox, oy, 0.3])
    a, b = base.copy(), base.copy()
    box = np.zeros(4)
    buf = np.empty(500, dtype=np.int64)
    x1, y1 = x0 + 90 * res, y0 + 80 * res
    n = raytrace_freespace(a, pts, ox, oy, x0, y0, x1, y1, res, 3.0, 0, buf, box)
    want = _numpy_raytrace(b, pts, ox, oy, x0, y0, res, 3.0)
    assert n > 300 and want is not None and tuple(box) == want
    np.testing.assert_array_equal(a, b)
    n = mark_observation(a, pts, origin, 2.0, 2.5, x0, y0, res, 254, box)
    want = _numpy_mark(b, pts, origin, 2.0, 2.5, x0, y0, res)
    assert n > 50 and want is not None and tuple(box) == want
    np.testing.assert_array_equal(a, b)
    # nothing on the grid: no bounds
    assert mark_observation(a, pts + 100.0, origin, 2.0, 500.0, x0, y0, res, 254, box) == 0


def test_scan_points_are_the_projection_then_the_transform() -> None:
    rng = np.random.default_rng(7)
    ranges = rng.uniform(0.0, 12.0, 720).astype(np.float32)
    ranges[::7] = np.inf
    ranges[3::11] = np.nan
    ranges[5::13] = -np.inf
    angle_min, inc = -2.356194490192345, 0.006554075
    angles = angle_min + np.arange(720, dtype=np.float64) * inc
    tf = Transform3((1.25, -3.5, 0.42), tuple(quat_from_rpy(0.01, -0.02, 2.7)))
    for inf_is_valid in (False, True):
        got = scan_points(
            ranges, np.cos(angles), np.sin(angles), 0.1, 10.0, inf_is_valid,
            np.asarray(tf.rotation), np.asarray(tf.translation),
        )  # fmt: skip
        want = tf.apply(project_scan(ranges, angles, 0.1, 10.0, inf_is_valid=inf_is_valid))
        assert got.shape == want.shape and len(got) > 400
        np.testing.assert_array_equal(got, want)


def test_combine_max_is_update_with_max() -> None:
    """CostmapLayer::updateWithMax: the layer's known cost where the master cell is unknown
    or lower, in the window only."""
    rng = np.random.default_rng(8)
    values = np.array([0, 1, 100, 253, 254, 255], dtype=np.uint8)
    for _ in range(30):
        master = rng.choice(values, size=(23, 31))
        own = rng.choice(values, size=(23, 31))
        x0, xn = sorted(int(v) for v in rng.integers(0, 35, 2))
        y0, yn = sorted(int(v) for v in rng.integers(0, 26, 2))
        want = master.copy()
        m, o = want[y0:yn, x0:xn], own[y0:yn, x0:xn]
        take = (o != 255) & ((m == 255) | (m < o))
        m[take] = o[take]
        combine_max(master, own, x0, y0, xn, yn)
        np.testing.assert_array_equal(master, want)


def test_height_filter_is_the_numpy_mask() -> None:
    rng = np.random.default_rng(9)
    pts = rng.uniform(-3, 3, size=(500, 3))
    pts[rng.integers(0, 500, 60), rng.integers(0, 3, 60)] = np.nan
    pts[rng.integers(0, 500, 30), rng.integers(0, 3, 30)] = np.inf
    pts[rng.integers(0, 500, 30), 2] = -1.0  # on the lower limit: kept
    for lo, hi in ((-1.0, 2.0), (-np.inf, np.inf), (0.5, 0.5), (1.0, -1.0)):
        z = pts[:, 2]
        with np.errstate(invalid="ignore"):
            keep = (z <= hi) & (z >= lo) & np.isfinite(pts).all(axis=1)
        got = height_filter(pts, lo, hi)
        assert got.shape == (int(keep.sum()), 3)
        np.testing.assert_array_equal(got, pts[keep])
