"""The uniform grid: conservative cell lists, caching on the Scene, primitive tests."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.raycast import Grid, RaycastInputError, Scene, build_grid, scene_grid
from roverlab.raycast.accel import circle_hit, segment_distance, segment_hit
from tests.raycast.helpers import random_scene


def _cell_items(grid: Grid, px: float, py: float) -> set[int]:
    ix = math.floor((px - grid.x0) / grid.cell)
    iy = math.floor((py - grid.y0) / grid.cell)
    c = iy * grid.nx + ix
    a, b = grid.cell_start[c], grid.cell_start[c + 1]
    return set(grid.items[a:b].tolist())


@pytest.mark.parametrize("cell_m", [None, 0.1, 0.7])
def test_every_point_of_a_primitive_is_listed_in_its_cell(cell_m: float | None) -> None:
    rng = np.random.default_rng(5)
    scene = random_scene(rng, n_seg=30, n_circ=6)
    grid = build_grid(scene, cell_m=cell_m)
    assert grid.cell_start.shape == (grid.nx * grid.ny + 1,)
    assert grid.cell_start[-1] == len(grid.items)
    assert grid.cell_start.dtype == np.int32 and grid.items.dtype == np.int32
    xmin, ymin, xmax, ymax = scene.bounds
    assert grid.x0 < xmin and grid.y0 < ymin
    assert grid.x0 + grid.nx * grid.cell > xmax and grid.y0 + grid.ny * grid.cell > ymax
    s = np.linspace(0, 1, 200)
    for k, (x0, y0, x1, y1) in enumerate(scene.segments):
        for px, py in zip(x0 + s * (x1 - x0), y0 + s * (y1 - y0), strict=True):
            assert k in _cell_items(grid, px, py)
    for j, (cx, cy, r) in enumerate(scene.circles):
        item = len(scene.segments) + j
        for px, py in rng.uniform(-1, 1, (200, 2)):
            if px * px + py * py <= 1.0:
                assert item in _cell_items(grid, cx + px * r, cy + py * r)


def test_cells_do_not_list_far_primitives() -> None:
    scene = Scene(segments=[[0, 0, 10, 10]])  # a diagonal: its bounding box is 10 x 10
    grid = build_grid(scene, cell_m=1.0)
    per_cell = np.diff(grid.cell_start)
    # the diagonal crosses about 1 + 3 per cell along it, far fewer than the 100 box cells
    assert 10 <= per_cell.sum() <= 40


def test_scene_grid_is_cached_and_rebuilt_when_geometry_is_replaced() -> None:
    scene = Scene(segments=[[0, 0, 1, 0]], circles=[[3, 3, 1]])
    g1 = scene_grid(scene)
    assert scene_grid(scene) is g1
    g2 = scene_grid(scene, cell_m=0.25)
    assert g2 is not g1 and g2.cell == 0.25
    assert scene_grid(scene) is g2  # an explicit size sticks
    scene.segments = np.array([[0.0, 0.0, 8.0, 0.0]])
    g3 = scene_grid(scene)
    assert g3 is not g2 and g3.x0 + g3.nx * g3.cell > 8.0


def test_empty_and_degenerate_scenes() -> None:
    g = build_grid(Scene())
    assert g.nx == g.ny == 1 and len(g.items) == 0
    g = build_grid(Scene(segments=[[0, 0, 5, 0]]))  # zero height bounds
    assert g.ny >= 1 and len(g.items) >= g.nx
    with pytest.raises(RaycastInputError):
        build_grid(Scene(), cell_m=0.0)


def test_cell_count_stays_bounded() -> None:
    rng = np.random.default_rng(0)
    scene = Scene(segments=rng.uniform(-1000, 1000, (5000, 4)))
    g = build_grid(scene)
    assert g.nx <= 1024 and g.ny <= 1024


def test_primitive_tests() -> None:
    t, s = segment_hit(0.0, 0.0, 1.0, 0.0, 2.0, -1.0, 2.0, 3.0)
    assert t == 2.0 and s == pytest.approx(0.25)
    assert math.isinf(segment_hit(0.0, 0.0, -1.0, 0.0, 2.0, -1.0, 2.0, 3.0)[0])
    t_in, t_out = circle_hit(0.0, 0.0, 1.0, 0.0, 5.0, 0.0, 1.0)
    assert (t_in, t_out) == (4.0, 6.0)
    t_in, t_out = circle_hit(5.0, 0.0, 1.0, 0.0, 5.0, 0.0, 1.0)
    assert (t_in, t_out) == (0.0, 1.0)
    assert math.isinf(circle_hit(0.0, 0.0, 0.0, 1.0, 5.0, 0.0, 1.0)[0])


def test_segment_distance_matches_segment_hit() -> None:
    rng = np.random.default_rng(11)
    n_hit = 0
    for _ in range(3000):
        ox, oy, x0, y0, x1, y1 = rng.uniform(-3, 3, 6)
        a = rng.uniform(-4, 4)
        dx, dy = math.cos(a), math.sin(a)
        t, _ = segment_hit(ox, oy, dx, dy, x0, y0, x1, y1)
        assert segment_distance(ox, oy, dx, dy, x0, y0, x1, y1, math.inf) == t
        if math.isfinite(t):
            n_hit += 1
            far = t * (1 - 1e-9)
            assert segment_distance(ox, oy, dx, dy, x0, y0, x1, y1, far) == math.inf  # not closer
            assert segment_distance(ox, oy, dx, dy, x0, y0, x1, y1, t * 1.01 + 1e-9) == t
    assert n_hit > 300
    # collinear (zero determinant): the nearest end
    assert segment_distance(0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 2.0, 0.0, math.inf) == 2.0
    assert segment_distance(0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 2.0, 0.0, 1.5) == math.inf
