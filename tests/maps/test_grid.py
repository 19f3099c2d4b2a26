"""Occupancy grids: scans in a known room, max-range beams, growth, compiled vs reference."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from roverlab.maps import (
    CountGrid,
    GridError,
    LogOddsGrid,
    ScanRays,
    save_map,
    trace_cells,
)
from roverlab.maps.raytrace import trace_segment_cells
from roverlab.msgs import occupancy_grid_to_array, xytheta_from_pose
from tests.maps.helpers import (
    ref_beams,
    ref_counts,
    ref_log_odds,
    ref_trace,
    simulate_scan,
    square_room,
)

RES = 0.05
ANGLES = np.linspace(-math.pi, math.pi, 720, endpoint=False)
POSES = [(0.013, 0.027, 0.0), (0.41, -0.33, 0.7), (-0.52, 0.46, -1.2), (0.2, 0.61, 2.5)]


def _room_grid(tmp_path: Path, grid: LogOddsGrid | CountGrid, name: str) -> np.ndarray:
    walls, _, origin = square_room(res=RES)
    for pose in POSES:
        ranges = simulate_scan(walls, origin, RES, pose, ANGLES, 12.0)
        grid.update_scan(pose, ranges, ANGLES, 12.0)
    occ = grid.to_occupancy()
    save_map(tmp_path / name, occ, resolution=RES, origin=(*origin, 0.0), image_format="png")
    return occ


def test_scan_in_square_room_matches_ground_truth(tmp_path: Path) -> None:
    walls, interior, origin = square_room(res=RES)
    grid = LogOddsGrid(120, 120, RES, origin)
    occ = _room_grid(tmp_path, grid, "room_log_odds")
    inner_layer = walls & ~np.pad(walls, 1)[2:, 1:-1] | walls & ~np.pad(walls, 1)[:-2, 1:-1]
    inner_layer |= walls & ~np.pad(walls, 1)[1:-1, 2:] | walls & ~np.pad(walls, 1)[1:-1, :-2]
    inner_layer &= ~np.pad(interior, 1)[1:-1, 1:-1] & (
        np.pad(interior, 1)[2:, 1:-1]
        | np.pad(interior, 1)[:-2, 1:-1]
        | np.pad(interior, 1)[1:-1, 2:]
        | np.pad(interior, 1)[1:-1, :-2]
    )
    assert inner_layer.sum() == 4 * 80  # the wall cells facing the room, corners excepted
    # walls exactly where the room's walls are; the whole inner face seen
    assert np.all(walls[occ == 100])
    assert np.all(occ[inner_layer] == 100)
    # every cell of the room crossed by beams and free; nothing free outside it
    assert np.all(occ[interior] == 0)
    assert not np.any((occ == 0) & ~interior)
    # beyond the walls nothing was seen
    outside = ~interior & ~walls
    assert np.all(occ[outside] == -1)
    assert (tmp_path / "room_log_odds.png").exists()


def test_cells_along_one_beam_are_free_and_its_end_occupied() -> None:
    walls, _, origin = square_room(res=RES)
    grid = LogOddsGrid(120, 120, RES, origin)
    pose = (0.013, 0.027, 0.3)
    angle = np.array([0.0])
    r = simulate_scan(walls, origin, RES, pose, angle, 12.0)
    grid.update_scan(pose, r, angle, 12.0)
    end = (pose[0] + r[0] * math.cos(0.3), pose[1] + r[0] * math.sin(0.3))
    cells = trace_cells(pose[:2], end, resolution=RES, origin_xy=origin, width=120, height=120)
    lo = grid.log_odds
    assert len(cells) > 40
    ex, ey = grid.world_to_cell(*end)
    assert (cells[-1] == (ex, ey)).all()
    assert walls[ey, ex]
    assert lo[ey, ex] == pytest.approx(grid.l_occ)
    for ix, iy in cells[:-1]:
        assert lo[iy, ix] == pytest.approx(grid.l_free)
    assert np.count_nonzero(lo) == len(cells)


def test_count_grid_in_square_room(tmp_path: Path) -> None:
    walls, interior, origin = square_room(res=RES)
    grid = CountGrid(120, 120, RES, origin)
    occ = _room_grid(tmp_path, grid, "room_counts")
    assert np.all(walls[occ == 100])
    assert np.all(occ[interior] == 0)
    assert np.all(occ[~interior & ~walls] == -1)
    assert grid.visits[interior].min() >= 1
    assert grid.hits[interior].sum() == 0
    assert grid.hits.sum() == 720 * len(POSES)  # one hit per beam
    p = grid.probabilities()
    assert np.isnan(p[~interior & ~walls]).all()
    # with a free threshold the rule becomes trinary
    tri = grid.to_occupancy(occupied_thresh=0.25, free_thresh=0.1)
    assert set(np.unique(tri)) <= {-1, 0, 100}


def test_max_range_beams_free_up_to_range_and_leave_no_end_point() -> None:
    origin = (-5.0, -5.0)
    pose = (0.013, 0.027, 0.0)
    grid = LogOddsGrid(200, 200, RES, origin)
    ranges = np.full(720, np.inf)
    ranges[::7] = 3.0  # exactly range_max: a max-range reading too
    for _ in range(4):
        grid.update_scan(pose, ranges, ANGLES, 3.0)
    occ = grid.to_occupancy()
    centres = origin[0] + (np.arange(200) + 0.5) * RES
    cx, cy = np.meshgrid(centres, centres)
    dist = np.hypot(cx - pose[0], cy - pose[1])
    assert not np.any(occ == 100)
    assert np.all(occ[dist < 3.0 - RES] == 0)
    assert np.all(occ[dist > 3.0 + RES] == -1)


def test_usable_range_truncates_beams_without_end_point() -> None:
    origin = (-5.0, -5.0)
    pose = (0.013, 0.027, 0.0)
    grid = LogOddsGrid(200, 200, RES, origin)
    ranges = np.where(np.arange(720) % 2 == 0, 2.5, 1.5)  # 2.5 m: beyond usable_range
    for _ in range(4):
        grid.update_scan(pose, ranges, ANGLES, 4.0, usable_range=2.0)
    occ = grid.to_occupancy()
    centres = origin[0] + (np.arange(200) + 0.5) * RES
    cx, cy = np.meshgrid(centres, centres)
    dist = np.hypot(cx - pose[0], cy - pose[1])
    ring = np.abs(dist - 1.5) < 0.75 * RES
    assert np.all(np.abs(dist[occ == 100] - 1.5) < RES)  # only the 1.5 m readings end
    assert np.count_nonzero(occ[ring] == 100) > 0.5 * np.count_nonzero(ring)
    assert np.all(occ[dist > 2.0 + RES] == -1)  # nothing beyond usable_range


def test_clear_max_range_false_skips_max_range_readings() -> None:
    grid = LogOddsGrid(100, 100, RES, (-2.5, -2.5))
    grid.update_scan((0.0, 0.0, 0.0), np.full(720, np.inf), ANGLES, 2.0, clear_max_range=False)
    assert not np.any(grid.log_odds)
    grid.update_scan((0.0, 0.0, 0.0), np.full(720, np.inf), ANGLES, 2.0)
    assert np.all(grid.log_odds <= 0) and np.any(grid.log_odds < 0)


def test_invalid_readings_are_skipped() -> None:
    grid = LogOddsGrid(100, 100, RES, (-2.5, -2.5))
    ranges = np.array([np.nan, 0.0, -1.0, 0.05])
    angles = np.array([0.0, 0.5, 1.0, 1.5])
    changed = grid.update_scan((0.0, 0.0, 0.0), ranges, angles, 2.0, range_min=0.1)
    assert changed == 0
    assert not np.any(grid.log_odds)


def test_log_odds_are_clamped() -> None:
    grid = LogOddsGrid(40, 40, RES, (-1.0, -1.0), l_occ=1.0, l_free=-0.5, l_min=-2.0, l_max=3.0)
    for _ in range(10):
        grid.update_scan((0.01, 0.02, 0.0), [0.5], [0.0], 2.0)
    ex, ey = grid.world_to_cell(0.51, 0.02)
    assert grid.log_odds[ey, ex] == pytest.approx(3.0)
    assert grid.log_odds.min() == pytest.approx(-2.0)
    p = grid.probabilities()
    assert p[ey, ex] == pytest.approx(1 / (1 + math.exp(-3.0)))


def test_growth_preserves_content_and_alignment() -> None:
    grid = LogOddsGrid(40, 30, RES, (-1.0, -0.75))
    grid.update_scan((0.013, 0.027, 0.0), [0.6, 0.7], [0.0, 1.6], 4.0)
    before = grid.log_odds.copy()
    changed = [grid.cell_to_world(ix, iy) for iy, ix in zip(*np.nonzero(before), strict=True)]
    assert grid.ensure_contains(3.3, -2.9)
    assert grid.contains(3.3, -2.9)
    assert not grid.ensure_contains(0.0, 0.0)
    shift = np.subtract(grid.origin_xy, (-1.0, -0.75)) / RES
    assert np.allclose(shift, np.round(shift)) and shift.max() <= 0  # whole cells
    after = grid.log_odds
    assert np.count_nonzero(after) == np.count_nonzero(before)
    for (x, y), value in zip(changed, before[np.nonzero(before)], strict=True):
        ix, iy = grid.world_to_cell(x, y)
        assert after[iy, ix] == value
    assert grid.width > 40 and grid.height > 30


def test_grow_on_update_equals_a_big_grid() -> None:
    walls, _, origin = square_room(res=RES)
    poses = [(0.013, 0.027, 0.0), (1.1, -0.9, 0.4)]
    small = LogOddsGrid(20, 20, RES, (-0.5, -0.5))
    big = LogOddsGrid(120, 120, RES, origin)
    for pose in poses:
        r = simulate_scan(walls, origin, RES, pose, ANGLES, 12.0)
        small.update_scan(pose, r, ANGLES, 12.0, grow=True)
        big.update_scan(pose, r, ANGLES, 12.0)
    # offsets of the small grid's cell [0, 0] in the big grid: whole cells
    ox = round((small.origin_xy[0] - origin[0]) / RES)
    oy = round((small.origin_xy[1] - origin[1]) / RES)
    assert small.origin_xy[0] == pytest.approx(origin[0] + ox * RES)
    x0, y0 = max(ox, 0), max(oy, 0)
    x1, y1 = min(ox + small.width, big.width), min(oy + small.height, big.height)
    window_big = big.log_odds[y0:y1, x0:x1]
    window_small = small.log_odds[y0 - oy : y1 - oy, x0 - ox : x1 - ox]
    assert np.count_nonzero(window_big) == np.count_nonzero(big.log_odds)  # all seen cells
    assert np.count_nonzero(window_small) == np.count_nonzero(small.log_odds)
    assert np.array_equal(window_small, window_big)
    assert np.count_nonzero(small.log_odds) > 1000


@pytest.mark.parametrize("seed", range(12))
def test_compiled_matches_numpy_reference(seed: int) -> None:
    rng = np.random.default_rng(seed)
    w, h = int(rng.integers(3, 30)), int(rng.integers(3, 30))
    res = float(rng.uniform(0.03, 0.3))
    origin = (float(rng.uniform(-2, 2)), float(rng.uniform(-2, 2)))
    l_occ, l_free = float(rng.uniform(0.2, 1.5)), float(rng.uniform(-1.5, -0.1))
    l_min, l_max = -2.0, 2.5
    log_odds = LogOddsGrid(w, h, res, origin, l_occ=l_occ, l_free=l_free, l_min=l_min, l_max=l_max)
    counts = CountGrid(w, h, res, origin)
    ref_lo = np.zeros((h, w), dtype=np.float32)
    ref_hits = np.zeros((h, w), dtype=np.int32)
    ref_visits = np.zeros((h, w), dtype=np.int32)
    span = max(w, h) * res
    for _ in range(4):
        # the laser inside or (sometimes) outside the grid
        pose = (
            origin[0] + float(rng.uniform(-0.3, 1.3)) * w * res,
            origin[1] + float(rng.uniform(-0.3, 1.3)) * h * res,
            float(rng.uniform(-math.pi, math.pi)),
        )
        n = int(rng.integers(1, 40))
        angles = np.sort(rng.uniform(-math.pi, math.pi, n))
        ranges = rng.uniform(0.0, 1.5 * span, n)
        ranges[rng.random(n) < 0.15] = np.inf
        ranges[rng.random(n) < 0.05] = np.nan
        range_max = float(rng.uniform(0.5, 1.2) * span)
        usable = float(rng.uniform(0.3, 1.0) * range_max)
        log_odds.update_scan(pose, ranges, angles, range_max, usable_range=usable)
        counts.update_scan(pose, ranges, angles, range_max, usable_range=usable)
        g0, beams = ref_beams(pose, ranges, angles, range_max, usable, origin, res)
        ref_lo = ref_log_odds(ref_lo, g0, beams, l_occ, l_free, l_min, l_max)
        ref_counts(ref_hits, ref_visits, g0, beams)
    assert np.array_equal(log_odds.log_odds, ref_lo)
    assert np.array_equal(counts.hits, ref_hits)
    assert np.array_equal(counts.visits, ref_visits)
    assert np.count_nonzero(ref_visits) > 0


@pytest.mark.parametrize("seed", range(30))
def test_trace_matches_reference(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    w, h = int(rng.integers(1, 25)), int(rng.integers(1, 25))
    start = (float(rng.uniform(-5, w + 5)), float(rng.uniform(-5, h + 5)))
    end = (float(rng.uniform(-5, w + 5)), float(rng.uniform(-5, h + 5)))
    if seed % 5 == 0:
        end = (end[0], start[1])  # axis-parallel segments too
    got = trace_cells(start, end, resolution=1.0, origin_xy=(0.0, 0.0), width=w, height=h)
    assert [tuple(c) for c in got.tolist()] == ref_trace(start, end, w, h)


def test_trace_known_cells() -> None:
    cells = trace_cells((0.5, 0.5), (3.5, 1.5), resolution=1.0, origin_xy=(0, 0), width=5, height=5)
    # through the corner (2, 1): the side cell along x comes first
    assert cells.tolist() == [[0, 0], [1, 0], [2, 0], [2, 1], [3, 1]]
    cells = trace_cells((0.5, 0.5), (3.5, 1.6), resolution=1.0, origin_xy=(0, 0), width=5, height=5)
    assert cells.tolist() == [[0, 0], [1, 0], [1, 1], [2, 1], [3, 1]]
    # a segment entering from outside the grid is clipped to it
    cells = trace_cells(
        (-3.5, 2.5), (1.5, 2.5), resolution=1.0, origin_xy=(0, 0), width=5, height=5
    )
    assert cells.tolist() == [[0, 2], [1, 2]]
    assert (
        len(trace_cells((9, 9), (8, 9.5), resolution=1.0, origin_xy=(0, 0), width=5, height=5)) == 0
    )


def test_world_cell_conversions_and_message() -> None:
    grid = LogOddsGrid(10, 8, 0.5, (-1.0, 2.0))
    assert grid.world_to_cell(-1.0, 2.0) == (0, 0)
    assert grid.world_to_cell(-0.01, 2.6) == (1, 1)
    assert grid.world_to_cell(-1.01, 1.99) == (-1, -1)
    assert grid.cell_to_world(1, 1) == (-0.25, 2.75)
    assert grid.world_to_cells([[-1.0, 2.0], [3.9, 5.9]]).tolist() == [[0, 0], [9, 7]]
    assert grid.contains(3.9, 5.9) and not grid.contains(4.0, 2.0)
    assert grid.bounds == (-1.0, 2.0, 4.0, 6.0)
    grid.log_odds[1, 2] = 3.0
    grid.log_odds[0, 0] = -3.0
    msg = grid.to_msg(frame_id="odom")
    cells = occupancy_grid_to_array(msg)
    assert msg.header.frame_id == "odom" and msg.info.width == 10 and msg.info.height == 8
    assert cells[1, 2] == 100 and cells[0, 0] == 0 and cells[5, 5] == -1
    assert xytheta_from_pose(msg.info.origin) == pytest.approx((-1.0, 2.0, 0.0))


@pytest.mark.parametrize(
    "kwargs",
    [
        {"width": 0},
        {"height": -3},
        {"resolution": 0.0},
        {"resolution": math.nan},
        {"origin_xy": (math.inf, 0.0)},
        {"l_occ": -1.0},
        {"l_free": 0.5},
        {"l_min": 1.0},
    ],
)
def test_bad_grid_settings(kwargs: dict[str, object]) -> None:
    args: dict[str, object] = {"width": 10, "height": 10, "resolution": 0.1, "origin_xy": (0, 0)}
    args.update(kwargs)
    with pytest.raises(GridError):
        LogOddsGrid(**args)  # type: ignore[arg-type]


def test_bad_scans() -> None:
    grid = LogOddsGrid(10, 10, 0.1)
    with pytest.raises(GridError, match="ranges but"):
        grid.update_scan((0, 0, 0), [1.0, 2.0], [0.0], 5.0)
    with pytest.raises(GridError, match="pose"):
        grid.update_scan((0, math.nan, 0), [1.0], [0.0], 5.0)
    with pytest.raises(GridError, match="range_max"):
        grid.update_scan((0, 0, 0), [1.0], [0.0], math.inf)
    with pytest.raises(GridError, match="usable_range"):
        grid.update_scan((0, 0, 0), [1.0], [0.0], 5.0, usable_range=0.0)
    with pytest.raises(GridError, match="thresholds"):
        grid.to_occupancy(occupied_thresh=0.2, free_thresh=0.5)
    with pytest.raises(GridError, match="non-finite"):
        grid.ensure_contains(math.inf, 0.0)


def test_scan_rays_rules() -> None:
    rays = ScanRays(
        (1.0, 2.0, math.pi / 2),
        [1.0, np.inf, 3.0, 5.0, np.nan],
        [0.0, 0.0, 0.0, 0.0, 0.0],
        4.0,
        usable_range=2.0,
    )
    assert rays.hit.tolist() == [True, False, False, False]
    assert np.allclose(rays.ends, [[1.0, 3.0], [1.0, 4.0], [1.0, 4.0], [1.0, 4.0]])
    assert rays.bounds() == pytest.approx((1.0, 2.0, 1.0, 4.0))


def _trace_each_step(gx0: float, gy0: float, gx1: float, gy1: float, w: int, h: int) -> list[int]:
    """The tracer's loop as it was, both border parameters recomputed at every step."""
    dx, dy = gx1 - gx0, gy1 - gy0
    t0, t1 = 0.0, 1.0
    for p, q in ((-dx, gx0), (dx, w - gx0), (-dy, gy0), (dy, h - gy0)):
        if p == 0.0:
            if q < 0.0:
                t0, t1 = 1.0, 0.0
            continue
        r = q / p
        if p < 0.0:
            t0 = max(t0, r)
        else:
            t1 = min(t1, r)
    if t0 > t1:
        return []
    ix = min(max(math.floor(gx0 + t0 * dx), 0), w - 1)
    iy = min(max(math.floor(gy0 + t0 * dy), 0), h - 1)
    sx = 1 if dx > 0 else (-1 if dx < 0 else 0)
    sy = 1 if dy > 0 else (-1 if dy < 0 else 0)
    ox, oy = int(dx > 0), int(dy > 0)
    out = []
    while len(out) < w + h + 4:
        out.append(iy * w + ix)
        tx = (ix + ox - gx0) / dx if sx else math.inf
        ty = (iy + oy - gy0) / dy if sy else math.inf
        if tx <= ty:
            if tx >= t1:
                break
            ix += sx
            if not 0 <= ix < w:
                break
        else:
            if ty >= t1:
                break
            iy += sy
            if not 0 <= iy < h:
                break
    return out


def test_trace_recomputes_a_border_only_when_its_cell_changes() -> None:
    """The same cells, bit for bit, as computing both borders at every step (also for
    segments through cell corners, where x and y borders tie)."""
    rng = np.random.default_rng(7)
    buf = np.empty(64, dtype=np.int64)
    for k in range(3000):
        w, h = int(rng.integers(1, 25)), int(rng.integers(1, 25))
        pts = rng.uniform(-3, 28, 4)
        if k % 3 == 0:
            pts = np.round(pts * 2) / 2  # on cell borders and corners
        n = trace_segment_cells(*pts, w, h, buf)
        assert buf[:n].tolist() == _trace_each_step(*pts, w, h), k
