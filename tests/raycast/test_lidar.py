"""Planar ray casts: exactness against brute force, known geometry, occupancy grids."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.raycast import (
    RaycastInputError,
    Scene,
    cast_2d,
    cast_2d_many,
    cast_grid,
    cast_grid_many,
    scene_grid,
)
from tests.raycast.helpers import box_segments, brute_cast, cells_scene, random_scene

ROOM = Scene(segments=box_segments(-1, -1, 1, 1))
AXES = np.array([0.0, math.pi / 2, math.pi, -math.pi / 2])


# ---- exactness ------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_cast_2d_equals_brute_force_on_random_scenes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    scene = random_scene(rng)
    angles = np.concatenate([rng.uniform(-4, 4, 300), AXES])
    n_hits = 0
    for _ in range(15):
        # mostly inside the scene bounds, some far outside (the ray enters the grid)
        x, y = rng.uniform(-8, 8, 2) if rng.random() < 0.8 else rng.uniform(-40, 40, 2)
        z = float(rng.uniform(0, 1.5))
        rmax = float(rng.choice([3.0, 12.0, np.inf]))
        got = cast_2d(scene, x, y, z, angles, rmax)
        want = brute_cast(scene, x, y, z, angles, rmax)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
        n_hits += int(np.isfinite(got).sum())
    assert n_hits > 400  # the comparison is not vacuous


@pytest.mark.parametrize("cell_m", [0.05, 0.37, 50.0])
def test_exact_for_any_cell_size(cell_m: float) -> None:
    rng = np.random.default_rng(42)
    scene = random_scene(rng, n_seg=40, n_circ=8)
    assert scene_grid(scene, cell_m=cell_m).cell == cell_m
    angles = rng.uniform(-4, 4, 200)
    for _ in range(10):
        x, y = rng.uniform(-6, 6, 2)
        got = cast_2d(scene, x, y, 0.5, angles, 20.0)
        np.testing.assert_allclose(got, brute_cast(scene, x, y, 0.5, angles, 20.0), atol=1e-9)


def test_cast_2d_many_equals_cast_2d_per_pose() -> None:
    rng = np.random.default_rng(7)
    scene = random_scene(rng)
    poses = np.column_stack([rng.uniform(-5, 5, (20, 2)), rng.uniform(-4, 4, 20)])
    rel = np.linspace(-2.0, 2.0, 181)
    many = cast_2d_many(scene, poses, 0.4, rel, 10.0)
    assert many.shape == (20, 181)
    for p, row in zip(poses, many, strict=True):
        want = brute_cast(scene, p[0], p[1], 0.4, rel + p[2], 10.0)
        np.testing.assert_allclose(row, want, atol=1e-9)
    assert np.isfinite(many).sum() > 500


@pytest.mark.parametrize("seed", range(4))
def test_uniform_fans_take_the_angular_sweep_with_the_grid_walks_ranges(seed: int) -> None:
    """A uniform fan in a small scene is cast by the angular sweep (raycast.sweep); the
    same beams in shuffled order walk the grid; both equal brute force, and each other to
    the bit, also from poses on segment ends and lines and inside circles."""
    rng = np.random.default_rng(100 + seed)
    scene = random_scene(rng, n_seg=30, n_circ=8)
    n = 360
    rel = rng.uniform(-1, 1) + (2 * math.pi / n) * np.arange(n)
    perm = rng.permutation(n)
    segs = scene.segments
    n_hits = 0
    for i in range(40):
        if i < 10:  # on a segment end, or along a segment
            sx0, sy0, sx1, sy1 = segs[rng.integers(len(segs))]
            f = (0.0, 1.0, 0.5, float(rng.uniform()))[i % 4]
            x, y = sx0 + f * (sx1 - sx0), sy0 + f * (sy1 - sy0)
        elif i < 14:  # inside a circle
            cx, cy, r = scene.circles[rng.integers(len(scene.circles))]
            x, y = cx + 0.5 * r, cy
        else:
            x, y = rng.uniform(-8, 8, 2)
        yaw = float(rng.uniform(-4, 4))
        z = float(rng.uniform(0, 1.5))
        rmax = float(rng.choice([3.0, 12.0]))
        sweep = cast_2d(scene, x, y, z, rel + yaw, rmax)
        grid = np.empty(n)
        grid[perm] = cast_2d(scene, x, y, z, (rel + yaw)[perm], rmax)
        np.testing.assert_array_equal(sweep, grid)
        np.testing.assert_allclose(sweep, brute_cast(scene, x, y, z, rel + yaw, rmax), atol=1e-9)
        many = cast_2d_many(scene, np.array([[x, y, yaw]]), z, rel, rmax)[0]
        np.testing.assert_allclose(many, sweep, atol=1e-9)
        n_hits += int(np.isfinite(sweep).sum())
    assert n_hits > 2000


# ---- known geometry -------------------------------------------------------------------


def test_square_room_from_centre_is_one_over_cos() -> None:
    angles = np.linspace(-math.pi, math.pi, 721)
    got = cast_2d(ROOM, 0.0, 0.0, 0.5, angles, 10.0)
    # distance to the square |x|, |y| <= 1: 1 / max(|cos|, |sin|)
    want = 1.0 / np.maximum(np.abs(np.cos(angles)), np.abs(np.sin(angles)))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_room_corners_do_not_leak() -> None:
    corners = np.array([1, 3, 5, 7]) * math.pi / 4
    got = cast_2d(ROOM, 0.0, 0.0, 0.5, corners, 10.0)
    np.testing.assert_allclose(got, math.sqrt(2), atol=1e-12)
    # off-centre, through the corner (1, 1) exactly along the diagonal of slope 1
    got = cast_2d(ROOM, -0.5, -0.5, 0.5, [math.pi / 4], 10.0)
    assert got[0] == pytest.approx(1.5 * math.sqrt(2), abs=1e-12)


def test_range_max_gives_inf() -> None:
    got = cast_2d(ROOM, 0.0, 0.0, 0.5, AXES, 0.99)
    assert np.all(np.isinf(got))
    assert np.all(cast_2d(ROOM, 0.0, 0.0, 0.5, AXES, 1.0) == 1.0)  # range_max inclusive


def test_empty_scene_and_open_directions_give_inf() -> None:
    assert np.all(np.isinf(cast_2d(Scene(), 0.0, 0.0, 0.0, AXES, 100.0)))
    wall = Scene(segments=[[2, -1, 2, 1]])
    got = cast_2d(wall, 0.0, 0.0, 0.5, AXES, 100.0)
    assert got[0] == 2.0
    assert np.all(np.isinf(got[1:]))


def test_circle_distances() -> None:
    scene = Scene(circles=[[3.0, 0.0, 0.5]])
    got = cast_2d(scene, 0.0, 0.0, 0.5, [0.0, math.pi, math.atan2(0.5, 3.0) * 0.999], 10.0)
    assert got[0] == pytest.approx(2.5, abs=1e-12)
    assert math.isinf(got[1])  # the circle is behind
    assert 2.5 < got[2] < 3.0  # grazing the top of the circle
    # tangent ray (distance from centre = r exactly) touches at sqrt(d^2 - r^2)
    tangent = math.asin(0.5 / 3.0)
    t = cast_2d(scene, 0.0, 0.0, 0.5, [tangent + 1e-9, tangent - 1e-9], 10.0)
    assert math.isinf(t[0])
    assert t[1] == pytest.approx(math.sqrt(9 - 0.25), abs=1e-3)


def test_origin_inside_circle_or_on_segment_is_zero() -> None:
    scene = Scene(segments=[[0, -1, 0, 1]], circles=[[5.0, 5.0, 1.0]])
    angles = np.linspace(-3, 3, 13)
    assert np.all(cast_2d(scene, 5.2, 4.9, 0.5, angles, 10.0) == 0.0)
    assert np.all(cast_2d(scene, 0.0, 0.3, 0.5, angles, 10.0) == 0.0)
    # but not at a laser height outside the circle's z-range
    assert np.all(cast_2d(scene, 5.2, 4.9, 1.5, angles, 10.0) > 0.0)


def test_z_range_filtering() -> None:
    low_box = box_segments(1, -0.5, 2, 0.5)
    tall_wall = [[3, -5, 3, 5]]
    scene = Scene(
        segments=low_box + tall_wall,
        segment_z=[[0.0, 0.3]] * 4 + [[0.0, 2.0]],
        circles=[[0.0, 2.0, 0.2]],
        circle_z=[[0.5, 0.8]],
    )
    angles = np.array([0.0, math.pi / 2])
    low = cast_2d(scene, 0.0, 0.0, 0.2, angles, 10.0)
    high = cast_2d(scene, 0.0, 0.0, 1.0, angles, 10.0)
    mid = cast_2d(scene, 0.0, 0.0, 0.6, angles, 10.0)
    assert low[0] == 1.0 and math.isinf(low[1])  # the box; under the floating pillar
    assert high[0] == 3.0 and math.isinf(high[1])  # over the box, over the pillar
    assert mid[1] == pytest.approx(1.8)  # the pillar at its height
    # the z-range is inclusive
    assert cast_2d(scene, 0.0, 0.0, 0.3, [0.0], 10.0)[0] == 1.0


def test_ray_through_segment_endpoint_and_grazing() -> None:
    scene = Scene(segments=[[2, 0, 2, 1], [1, 3, 2, 3]])
    # exactly through the endpoint (2, 0) along the x axis
    assert cast_2d(scene, 0.0, 0.0, 0.5, [0.0], 10.0)[0] == 2.0
    # through the endpoint (2, 1) of the first segment
    got = cast_2d(scene, 0.0, 0.0, 0.5, [math.atan2(1.0, 2.0)], 10.0)[0]
    assert got == pytest.approx(math.sqrt(5), abs=1e-12)
    # just past the endpoint: miss
    assert math.isinf(cast_2d(scene, 0.0, 0.0, 0.5, [-1e-9], 10.0)[0])
    # along the line of the second segment (collinear): its nearest end, either way round
    assert cast_2d(scene, -1.0, 3.0, 0.5, [0.0], 10.0)[0] == 2.0
    reverse = Scene(segments=[[2, 3, 1, 3]])
    assert cast_2d(reverse, -1.0, 3.0, 0.5, [0.0], 10.0)[0] == 2.0
    assert cast_2d(reverse, 1.5, 3.0, 0.5, [0.0], 10.0)[0] == 0.0  # origin on it
    # parallel to it, 1e-9 off: miss
    assert math.isinf(cast_2d(scene, -1.0, 3.0 + 1e-9, 0.5, [0.0], 10.0)[0])


def test_origin_outside_the_grid() -> None:
    got = cast_2d(ROOM, -30.0, 0.0, 0.5, [0.0, math.pi], 100.0)
    assert got[0] == pytest.approx(29.0, abs=1e-12)
    assert math.isinf(got[1])
    assert math.isinf(cast_2d(ROOM, -30.0, 0.0, 0.5, [0.0], 20.0)[0])


def test_input_validation() -> None:
    with pytest.raises(RaycastInputError):
        cast_2d(ROOM, math.nan, 0.0, 0.5, AXES, 10.0)
    with pytest.raises(RaycastInputError):
        cast_2d(ROOM, 0.0, 0.0, 0.5, AXES, 0.0)
    with pytest.raises(RaycastInputError):
        cast_2d(ROOM, 0.0, 0.0, 0.5, np.zeros((2, 2)), 10.0)
    with pytest.raises(RaycastInputError):
        cast_2d(ROOM, 0.0, 0.0, 0.5, [math.inf], 10.0)
    with pytest.raises(RaycastInputError):
        cast_2d_many(ROOM, np.zeros((3, 2)), 0.5, AXES, 10.0)
    with pytest.raises(ValueError):  # RaycastInputError is a ValueError
        cast_2d(ROOM, 0.0, 0.0, 0.5, AXES, -1.0)


# ---- occupancy grids ------------------------------------------------------------------

# 5 x 5, row index = y: '#' = occupied
HAND = np.array(
    [
        [0, 0, 0, 0, 0],  # row 0 (y in [0, 1))
        [0, 0, 0, 0, 0],
        [0, 0, 0, 0, 100],  # row 2
        [0, 0, 100, 0, 0],  # row 3
        [0, 0, 0, 0, 0],
    ],
    dtype=np.uint8,
)


def test_cast_grid_hand_made() -> None:
    # along +x in row 2 from (0.5, 2.5): the occupied cell (2, 4) starts at x = 4
    assert cast_grid(HAND, 1.0, (0, 0), 0.5, 2.5, [0.0], 10.0)[0] == 3.5
    # along +y in column 2 from (2.5, 0.5): cell (3, 2) starts at y = 3
    assert cast_grid(HAND, 1.0, (0, 0), 2.5, 0.5, [math.pi / 2], 10.0)[0] == 2.5
    # the other ways: nothing, leaves the grid
    got = cast_grid(HAND, 1.0, (0, 0), 2.5, 0.5, [math.pi, -math.pi / 2, 0.0], 10.0)
    assert np.all(np.isinf(got))
    # diagonal y = x + 0.5 from (0.25, 0.75): first occupied cell (3, 2), entered at y = 3
    d = cast_grid(HAND, 1.0, (0, 0), 0.25, 0.75, [math.pi / 4], 10.0)[0]
    assert d == pytest.approx(math.sqrt(2) * 2.25, abs=1e-12)
    # origin in an occupied cell
    assert cast_grid(HAND, 1.0, (0, 0), 4.5, 2.5, AXES, 10.0).tolist() == [0.0] * 4
    # from outside the grid
    assert cast_grid(HAND, 1.0, (0, 0), -3.0, 2.5, [0.0], 10.0)[0] == 7.0
    # range limit
    assert math.isinf(cast_grid(HAND, 1.0, (0, 0), 0.5, 2.5, [0.0], 3.4)[0])


def test_cast_grid_resolution_and_origin_scale() -> None:
    got = cast_grid(HAND, 0.1, (-1.0, 2.0), -1.0 + 0.05, 2.0 + 0.25, [0.0], 10.0)[0]
    assert got == pytest.approx(0.35, abs=1e-12)


def test_cast_grid_corner_does_not_leak() -> None:
    g = np.zeros((4, 4), dtype=bool)
    g[1, 2] = g[2, 1] = True  # diagonal neighbours; the ray passes their common corner
    d = cast_grid(g, 1.0, (0, 0), 1.5, 1.5, [math.pi / 4], 10.0)[0]
    assert d == pytest.approx(math.sqrt(2) / 2, abs=1e-9)
    g2 = np.zeros((4, 4), dtype=bool)
    g2[3, 3] = True
    d2 = cast_grid(g2, 1.0, (0, 0), 1.5, 1.5, [math.pi / 4], 10.0)[0]
    assert d2 == pytest.approx(math.sqrt(2) * 1.5, abs=1e-9)


def test_cast_grid_dtypes_and_occupied_value() -> None:
    occ = np.where(HAND == 100, 100, 0).astype(np.int8)
    occ[0, 4] = -1  # unknown: free unless asked for
    got_i8 = cast_grid(occ, 1.0, (0, 0), 0.5, 2.5, [0.0], 10.0)[0]
    got_bool = cast_grid(HAND == 100, 1.0, (0, 0), 0.5, 2.5, [0.0], 10.0)[0]
    assert got_i8 == got_bool == 3.5
    unknown = cast_grid(occ, 1.0, (0, 0), 0.5, 0.5, [0.0], 10.0, occupied_value=-1)[0]
    assert unknown == 3.5
    with pytest.raises(RaycastInputError):
        cast_grid(HAND.astype(np.float32), 1.0, (0, 0), 0.5, 2.5, [0.0], 10.0)
    with pytest.raises(RaycastInputError):
        cast_grid(HAND, 0.0, (0, 0), 0.5, 2.5, [0.0], 10.0)


def test_cast_grid_equals_scene_of_cell_faces() -> None:
    rng = np.random.default_rng(3)
    g = rng.random((30, 40)) < 0.12
    res, origin = 0.25, (-2.0, 1.0)
    scene = cells_scene(g, res, origin)
    free = np.argwhere(~g)
    angles = rng.uniform(-4, 4, 200)
    n_hits = 0
    for r, c in free[rng.integers(0, len(free), 15)]:
        x = origin[0] + (c + rng.uniform(0.1, 0.9)) * res
        y = origin[1] + (r + rng.uniform(0.1, 0.9)) * res
        got = cast_grid(g, res, origin, x, y, angles, 6.0)
        np.testing.assert_allclose(got, cast_2d(scene, x, y, 0.5, angles, 6.0), atol=1e-9)
        n_hits += int(np.isfinite(got).sum())
    assert n_hits > 1000


def test_cast_grid_many() -> None:
    poses = np.array([[0.5, 2.5, 0.0], [2.5, 0.5, math.pi / 2], [0.5, 2.5, math.pi]])
    got = cast_grid_many(HAND, 1.0, (0, 0), poses, [0.0], 10.0)
    assert got.shape == (3, 1)
    assert got[0, 0] == 3.5 and got[1, 0] == 2.5 and math.isinf(got[2, 0])
