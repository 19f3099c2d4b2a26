"""World model: shapes -> Scene, occupancy rasterisation, footprint collisions."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image
from scipy import ndimage

from roverlab.geometry import Transform3, quat_from_rpy
from roverlab.world import (
    BoxShape,
    CylinderShape,
    PolylineShape,
    PosterShape,
    SphereShape,
    World,
    WorldError,
)
from roverlab.world._geom import signed_area


def _segment_set(segments: np.ndarray) -> set[tuple[float, ...]]:
    return {tuple(np.round(s, 6).tolist()) for s in segments}


def test_box_with_yaw_becomes_four_faces_in_world_coordinates() -> None:
    box = BoxShape(
        pose=(2.0, 1.0, 0.5, 0.0, 0.0, math.pi / 2), size=(2.0, 1.0, 1.0), rgb=(10, 20, 30)
    )
    scene = World(shapes=(box,)).to_scene()
    assert scene.segments.shape == (4, 4)
    corners = {tuple(np.round(p, 6).tolist()) for p in scene.segments[:, :2]}
    assert corners == {(1.5, 0.0), (2.5, 0.0), (2.5, 2.0), (1.5, 2.0)}
    # faces chain head to tail, counter-clockwise seen from above
    assert np.allclose(scene.segments[:, 2:], np.roll(scene.segments[:, :2], -1, axis=0))
    assert signed_area(scene.segments[:, :2]) > 0
    assert np.allclose(scene.segment_z, [[0.0, 1.0]] * 4)
    assert (scene.segment_rgb == [10, 20, 30]).all()
    assert (scene.segment_texture == -1).all()


def test_pose_accepts_transform3() -> None:
    tf = Transform3.from_arrays((1.0, 0.0, 0.5), quat_from_rpy(0.0, 0.0, 0.0))
    a = BoxShape(pose=tf, size=(1.0, 1.0, 1.0))
    b = BoxShape(pose=(1.0, 0.0, 0.5, 0.0, 0.0, 0.0), size=(1.0, 1.0, 1.0))
    assert a == b
    assert World(shapes=(a,)).bounds == pytest.approx((0.5, -0.5, 1.5, 0.5))


def test_textured_box_textures_every_face(tmp_path: Path) -> None:
    img = np.zeros((4, 6, 3), np.uint8)
    img[:, :3] = (255, 0, 0)
    Image.fromarray(img).save(tmp_path / "tex.png")
    box = BoxShape(pose=(0, 0, 0.5, 0, 0, 0), size=(1, 1, 1), texture=tmp_path / "tex.png")
    plain = BoxShape(pose=(3, 0, 0.5, 0, 0, 0), size=(1, 1, 1))
    scene = World(shapes=(box, plain)).to_scene()
    assert scene.segment_texture.tolist() == [0, 0, 0, 0, -1, -1, -1, -1]
    assert len(scene.textures) == 1
    assert np.array_equal(scene.textures[0], img)


def test_missing_texture_fails_at_scene_time(tmp_path: Path) -> None:
    box = BoxShape(pose=(0, 0, 0.5, 0, 0, 0), size=(1, 1, 1), texture=tmp_path / "none.png")
    with pytest.raises(WorldError, match=r"none\.png"):
        World(shapes=(box,)).to_scene()


def test_cylinder_and_sphere_become_circles() -> None:
    w = World(
        shapes=(
            CylinderShape(pose=(1, 2, 0.75, 0, 0, 0), radius=0.3, length=1.5, rgb=(1, 2, 3)),
            SphereShape(pose=(-1, 0, 2.0, 0, 0, 0), radius=0.5),
        )
    )
    scene = w.to_scene()
    assert scene.circles.tolist() == [[1.0, 2.0, 0.3], [-1.0, 0.0, 0.5]]
    assert scene.circle_z.tolist() == [[0.0, 1.5], [1.5, 2.5]]
    assert scene.circle_rgb[0].tolist() == [1, 2, 3]
    assert len(scene.segments) == 0


def test_lying_cylinder_is_a_rectangle() -> None:
    cyl = CylinderShape(pose=(0, 0, 0.2, 0, math.pi / 2, 0), radius=0.2, length=2.0)
    scene = World(shapes=(cyl,)).to_scene()
    assert len(scene.circles) == 0
    assert {tuple(p) for p in scene.segments[:, :2].round(6).tolist()} == {
        (-1.0, -0.2),
        (1.0, -0.2),
        (1.0, 0.2),
        (-1.0, 0.2),
    }
    assert scene.segment_z[0].tolist() == pytest.approx([0.0, 0.4])


def test_polyline_is_a_closed_ccw_prism_on_its_pose() -> None:
    # clockwise outline on purpose: it is turned counter-clockwise
    pl = PolylineShape(pose=(10, 0, 0.1, 0, 0, 0), points=((0, 0), (0, 1), (1, 0)), height=0.5)
    scene = World(shapes=(pl,)).to_scene()
    assert len(scene.segments) == 3
    assert signed_area(scene.segments[:, :2]) > 0
    assert {tuple(p) for p in scene.segments[:, :2].round(6).tolist()} == {
        (10.0, 0.0),
        (11.0, 0.0),
        (10.0, 1.0),
    }
    assert scene.segment_z[0].tolist() == pytest.approx([0.1, 0.6])


def test_box_turned_on_its_side_stays_exact() -> None:
    box = BoxShape(pose=(0, 0, 0.5, math.pi / 2, 0, 0), size=(2.0, 1.0, 3.0))
    scene = World(shapes=(box,)).to_scene()
    # roll 90 degrees: local y is vertical (height 1), local z lies along world y (3 m)
    assert scene.segment_z[0].tolist() == pytest.approx([0.0, 1.0])
    assert World(shapes=(box,)).bounds == pytest.approx((-1.0, -1.5, 1.0, 1.5))


def test_tilted_box_becomes_the_prism_that_contains_it() -> None:
    box = BoxShape(pose=(0, 0, 1.0, 0, math.pi / 4, 0), size=(1.0, 1.0, 1.0))
    w = World(shapes=(box,))
    h = math.sqrt(2) / 2
    assert w.bounds == pytest.approx((-h, -0.5, h, 0.5))
    assert w.to_scene().segment_z[0].tolist() == pytest.approx([1.0 - h, 1.0 + h])


def test_poster_is_one_textured_face_and_visual_only(tmp_path: Path) -> None:
    Image.new("RGB", (8, 8), (0, 255, 0)).save(tmp_path / "p.png")
    poster = PosterShape(start=(1, 1), end=(1, -1), z_range=(0.5, 1.5), image=tmp_path / "p.png")
    w = World(shapes=(poster,))
    scene = w.to_scene()
    assert scene.segments.tolist() == [[1.0, 1.0, 1.0, -1.0]]
    assert scene.segment_texture.tolist() == [0]
    assert scene.segment_z.tolist() == [[0.5, 1.5]]
    grid, _ = w.occupancy(0.1, bounds=(0, -2, 2, 2))
    assert not grid.any()
    assert not w.footprint_collides(1.0, 0.0, 0.0, 0.3)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: BoxShape(size=(1.0, 0.0, 1.0)), "size"),
        (lambda: BoxShape(size=(1.0, float("nan"), 1.0)), "size"),
        (lambda: CylinderShape(radius=-1.0, length=1.0), "radius"),
        (lambda: SphereShape(radius=float("inf")), "radius"),
        (lambda: PolylineShape(points=((0, 0), (1, 0), (0, 0)), height=1.0), "3 distinct"),
        (lambda: BoxShape(size=(1, 1, 1), pose=(0, 0, 0)), "pose"),
        (lambda: BoxShape(size=(1, 1, 1), rgb=(0, 0, 256)), "rgb"),
    ],
)
def test_bad_shapes_are_rejected(make: object, match: str) -> None:
    with pytest.raises(WorldError, match=match):
        make()  # type: ignore[operator]


# ----------------------------------------------------------------------- occupancy


def test_occupancy_marks_exactly_the_cells_of_a_grid_aligned_box() -> None:
    box = BoxShape(pose=(0.25, 0.15, 0.5, 0, 0, 0), size=(0.5, 0.3, 1.0))  # x 0..0.5, y 0..0.3
    grid, origin = World(shapes=(box,)).occupancy(0.1, bounds=(-0.2, -0.2, 0.8, 0.6))
    assert origin == (-0.2, -0.2)
    assert grid.shape == (8, 10)
    expected = np.zeros((8, 10), bool)
    expected[2:5, 2:7] = True
    assert np.array_equal(grid, expected)


def test_occupancy_closes_walls_thinner_than_a_cell() -> None:
    # a 2 cm wall at an angle, longer than the grid: it must split the free space in two
    wall = BoxShape(pose=(0.0, 0.0, 1.0, 0, 0, 0.3), size=(10.0, 0.02, 2.0))
    grid, _ = World(shapes=(wall,)).occupancy(0.1, bounds=(-2, -2, 2, 2))
    assert grid.sum() < 4 * 40  # thin: a few cells per column
    _, n = ndimage.label(~grid)  # 4-connected free space
    assert n == 2


def test_occupancy_height_band_filters_shapes() -> None:
    low = BoxShape(pose=(0, 0, 0.1, 0, 0, 0), size=(1, 1, 0.2))  # z 0..0.2
    shelf = BoxShape(pose=(3, 0, 1.5, 0, 0, 0), size=(1, 1, 0.2))  # z 1.4..1.6
    w = World(shapes=(low, shelf))
    grid, _ = w.occupancy(0.1, 0.3, 1.0, bounds=(-1, -1, 4, 1))
    assert not grid.any()
    grid, _ = w.occupancy(0.1, 0.0, 2.0, bounds=(-1, -1, 4, 1))
    assert grid[:, :20].any() and grid[:, 20:].any()
    # a single plane: lidar height 0.15 sees the low box only
    grid, _ = w.occupancy(0.1, 0.15, 0.15, bounds=(-1, -1, 4, 1))
    assert grid[:, :20].any() and not grid[:, 20:].any()


def test_occupancy_of_a_circle_and_default_bounds() -> None:
    cyl = CylinderShape(pose=(1.0, 1.0, 0.5, 0, 0, 0), radius=0.5, length=1.0)
    grid, (ox, oy) = World(shapes=(cyl,)).occupancy(0.05, padding=0.25)
    assert ox == pytest.approx(0.25) and oy == pytest.approx(0.25)
    assert grid.shape == (30, 30)
    area = grid.sum() * 0.05**2
    assert math.pi * 0.25 < area < math.pi * 0.25 * 1.35
    assert grid[15, 15] and not grid[0, 0]


def test_occupancy_of_a_rotated_polygon_matches_point_sampling() -> None:
    tri = PolylineShape(pose=(0, 0, 0, 0, 0, 0.4), points=((0, 0), (2, 0), (0, 1.5)), height=1)
    res = 0.05
    grid, (ox, oy) = World(shapes=(tri,)).occupancy(res)
    # every cell whose centre is inside is occupied; no cell far outside is
    ys, xs = np.mgrid[0 : grid.shape[0], 0 : grid.shape[1]]
    cx = ox + (xs + 0.5) * res
    cy = oy + (ys + 0.5) * res
    c, s = math.cos(-0.4), math.sin(-0.4)
    lx = c * cx - s * cy
    ly = s * cx + c * cy
    inside = (lx > 0) & (ly > 0) & (lx / 2 + ly / 1.5 < 1)
    assert grid[inside].all()
    far = (lx < -res) | (ly < -res) | (lx / 2 + ly / 1.5 > 1 + res)
    assert not grid[far].any()


# ---------------------------------------------------------------------- collisions


def _square(half: float) -> list[tuple[float, float]]:
    return [(-half, -half), (half, -half), (half, half), (-half, half)]


def test_circle_footprint_against_box_and_cylinder() -> None:
    w = World(
        shapes=(
            BoxShape(pose=(1.0, 0, 0.5, 0, 0, 0), size=(1.0, 1.0, 1.0)),  # x 0.5..1.5
            CylinderShape(pose=(-2.0, 0, 0.5, 0, 0, 0), radius=0.5, length=1.0),
        )
    )
    assert not w.footprint_collides(0.0, 0.0, 0.0, 0.2)
    assert w.footprint_collides(0.31, 0.0, 0.0, 0.2)
    assert not w.footprint_collides(0.29, 0.0, 0.0, 0.2)
    assert w.footprint_collides(1.0, 0.0, 0.0, 0.1)  # wholly inside the box
    assert w.footprint_collides(-1.31, 0.0, 0.0, 0.2)
    assert not w.footprint_collides(-1.29, 0.0, 0.0, 0.2)


def test_polygon_footprint_honours_yaw() -> None:
    w = World(shapes=(BoxShape(pose=(0, 1.0, 0.5, 0, 0, 0), size=(4.0, 0.2, 1.0)),))  # y 0.9..1.1
    long_robot = [(-1.0, -0.1), (1.0, -0.1), (1.0, 0.1), (-1.0, 0.1)]
    assert not w.footprint_collides(0, 0, 0.0, long_robot)
    assert w.footprint_collides(0, 0, math.pi / 2, long_robot)
    # a post inside the robot's outline, touching no edge
    post = World(shapes=(CylinderShape(pose=(0, 0, 0.5, 0, 0, 0), radius=0.05, length=1),))
    assert post.footprint_collides(0, 0, 0.3, _square(0.3))
    small_box = World(shapes=(BoxShape(pose=(0.1, 0, 0.5, 0, 0, 0.7), size=(0.1, 0.1, 1)),))
    assert small_box.footprint_collides(0, 0, 0.0, _square(0.3))
    assert not small_box.footprint_collides(2.0, 0, 0.0, _square(0.3))
    # robot wholly inside a big box
    big = World(shapes=(BoxShape(pose=(0, 0, 0.5, 0, 0, 0), size=(10, 10, 1)),))
    assert big.footprint_collides(0, 0, 0.0, _square(0.3))


def test_collisions_respect_the_height_band() -> None:
    w = World(shapes=(BoxShape(pose=(0, 0, 1.8, 0, 0, 0), size=(1, 1, 0.2)),))  # z 1.7..1.9
    assert w.footprint_collides(0, 0, 0, 0.2)
    assert not w.footprint_collides(0, 0, 0, 0.2, z_min=0.0, z_max=0.5)


def test_bad_footprint_is_rejected() -> None:
    w = World()
    with pytest.raises(WorldError):
        w.footprint_collides(0, 0, 0, [(0, 0), (1, 0)])
    with pytest.raises(WorldError):
        w.footprint_collides(0, 0, 0, -0.1)


def test_empty_world() -> None:
    w = World()
    assert w.bounds == (0.0, 0.0, 0.0, 0.0)
    grid, _ = w.occupancy(0.1)
    assert grid.shape == (10, 10) and not grid.any()
    assert not w.footprint_collides(0, 0, 0, 0.3)
    assert len(w.to_scene().segments) == 0
