"""The 2.5-D pinhole camera: projection, colours, depth, textures, point clouds."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from PIL import Image

from roverlab.raycast import (
    RaycastInputError,
    Scene,
    body_to_optical,
    camera_intrinsics,
    depth_to_points,
    optical_to_body,
    render,
    render_rgb,
)
from tests.raycast.helpers import box_segments, random_scene

W, H, HFOV = 161, 121, 1.2  # odd sizes: pixel (60, 80) is exactly on the optical axis
INTR = camera_intrinsics(W, H, HFOV)
CAM = {"hfov": HFOV, "width": W, "height": H, "near": 0.05, "far": 30.0}
RED = (255, 0, 0)
GREEN = (0, 255, 0)
BLUE = (0, 0, 255)
YELLOW = (255, 255, 0)


def wall_scene(zmin: float = 0.5, zmax: float = 1.7, rgb: tuple[int, int, int] = RED) -> Scene:
    """A 10 m wall across the x axis at x = 2, from zmin to zmax."""
    return Scene(segments=[[2, 5, 2, -5]], segment_z=[[zmin, zmax]], segment_rgb=[rgb])


def save(tmp_path: Path, name: str, rgb: NDArray[np.uint8]) -> Path:
    path = tmp_path / f"{name}.png"
    Image.fromarray(rgb).save(path)
    assert Image.open(path).size == (rgb.shape[1], rgb.shape[0])
    return path


def is_red(px: NDArray[np.uint8]) -> bool:
    return bool(px[0] > 150 and px[1] < 40 and px[2] < 40)


def is_floor(px: NDArray[np.uint8], scene: Scene) -> bool:
    grey = int(px[0])
    return bool(px[0] == px[1] == px[2] and 0.8 * scene.floor_rgb[0] <= grey <= scene.floor_rgb[0])


def row_b(v: int | NDArray[np.int64]) -> NDArray[np.float64]:
    return np.asarray((INTR.cy - v) / INTR.fy, dtype=np.float64)


def test_intrinsics() -> None:
    assert INTR.fx == INTR.fy == pytest.approx((W / 2) / math.tan(HFOV / 2))
    assert (INTR.cx, INTR.cy) == (80.0, 60.0)
    np.testing.assert_allclose(INTR.k, [[INTR.fx, 0, 80], [0, INTR.fy, 60], [0, 0, 1]])
    assert INTR.vfov == pytest.approx(2 * math.atan((H / 2) / INTR.fy))


def test_wall_ahead_fills_the_projected_rows(tmp_path: Path) -> None:
    scene = wall_scene()
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    save(tmp_path, "wall", rgb)
    assert rgb.shape == (H, W, 3) and rgb.dtype == np.uint8
    assert depth.shape == (H, W) and depth.dtype == np.float32
    # pinhole: row v sees height 1 + 2 * (cy - v) / fy on the wall at 2 m
    heights = 1.0 + 2.0 * row_b(np.arange(H))
    assert np.min(np.abs(heights - 0.5)) > 1e-3 and np.min(np.abs(heights - 1.7)) > 1e-3
    expected = (heights >= 0.5) & (heights <= 1.7)
    seen = np.array([is_red(rgb[v, 80]) for v in range(H)])
    np.testing.assert_array_equal(seen, expected)
    top, bottom = np.flatnonzero(expected)[[0, -1]]
    assert top == math.ceil(60 - 0.7 * INTR.fy / 2) and bottom == math.floor(60 + 0.5 * INTR.fy / 2)
    # the same rows in every column (the wall is fronto-parallel), z-depth 2 everywhere
    for u in (0, 40, 120, W - 1):
        assert [is_red(rgb[v, u]) for v in range(H)] == seen.tolist()
    assert depth[60, 80] == 2.0
    np.testing.assert_allclose(depth[expected], 2.0, rtol=0, atol=1e-5)
    # sky above (exact sky colour, no depth), floor below (seen under the floating wall)
    assert np.all(rgb[:top, :] == scene.sky_rgb)
    assert np.all(np.isnan(depth[:top, :]))
    for v in range(bottom + 1, H):
        assert is_floor(rgb[v, 80], scene)
        assert depth[v, 80] == pytest.approx(1.0 / -row_b(v), rel=1e-5)  # z / |b|


def test_red_wall_renders_red_and_shading_is_deterministic(tmp_path: Path) -> None:
    scene = wall_scene(0.0, 3.0)
    a, da = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    b, db = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    np.testing.assert_array_equal(a, b)
    assert np.array_equal(da, db, equal_nan=True)
    r, g, bl = a[60, 80].astype(int)
    assert r > 150 and g == 0 and bl == 0
    # nearer walls are brighter (distance falloff), same hue
    near_rgb, _ = render(scene, 1.0, 0.0, 1.0, 0.0, **CAM)
    assert near_rgb[60, 80, 0] > a[60, 80, 0]
    # a grey wall seen along two orientations gets two different shades (fixed light)
    grey = Scene(segments=box_segments(-3, -3, 3, 3), segment_rgb=[(200, 200, 200)] * 4)
    east, _ = render(grey, 0.0, 0.0, 0.5, 0.0, **CAM)
    north, _ = render(grey, 0.0, 0.0, 0.5, math.pi / 2, **CAM)
    save(tmp_path, "grey_east", east)
    assert east[60, 80, 0] != north[60, 80, 0]


def test_layers_near_to_far() -> None:
    low = [[1.5, 5, 1.5, -5]]
    tall = [[2, 5, 2, -5]]
    scene = Scene(segments=low + tall, segment_z=[[0, 0.6], [0, 2.5]], segment_rgb=[GREEN, RED])
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    col = rgb[:, 80]
    green_rows = 1.0 + 1.5 * row_b(np.arange(H)) <= 0.6
    assert green_rows.sum() > 10 and (~green_rows).sum() > 10
    for v in range(H):
        if green_rows[v]:
            assert col[v, 1] > 150 and col[v, 0] < 40
            assert depth[v, 80] == pytest.approx(1.5, abs=1e-5)
        else:
            assert is_red(col[v])
            assert depth[v, 80] == pytest.approx(2.0, abs=1e-5)


def test_wall_that_almost_covers_the_view_does_not_hide_what_is_behind() -> None:
    top_at_1_5 = 1.0 + 1.5 * float(row_b(0))  # height of the top row's ray 1.5 m ahead
    scene = Scene(
        segments=[[1.5, 5, 1.5, -5], [3, 5, 3, -5]],
        segment_z=[[0.0, top_at_1_5 - 0.05], [0.0, 5.0]],
        segment_rgb=[GREEN, RED],
    )
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    red_rows = [v for v in range(H) if is_red(rgb[v, 80])]
    n_expected = int(np.sum(1.0 + 1.5 * row_b(np.arange(H)) > top_at_1_5 - 0.05))
    assert n_expected >= 3
    assert red_rows == list(range(n_expected))
    assert np.all(depth[:n_expected, 80] == pytest.approx(3.0, abs=1e-5))
    assert rgb[H - 1, 80, 1] > 150  # the green wall below


def test_texture_quadrants(tmp_path: Path) -> None:
    tex = np.array([[RED, GREEN], [BLUE, YELLOW]], dtype=np.uint8)  # row 0 = top
    scene = Scene(
        segments=[[2, 1, 2, -1]],  # u = 0 at y = +1: the left of the image
        segment_z=[[0.5, 1.5]],
        segment_texture=[0],
        textures=[tex],
    )
    rgb, _ = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    save(tmp_path, "texture", rgb)
    Image.fromarray(rgb).resize((4 * W, 4 * H), Image.Resampling.NEAREST).save(
        tmp_path / "texture_big.png"
    )
    du = dv = 20  # well inside each quadrant (the wall spans |u - cx| < fx / 2)
    quads = {
        "top_left": rgb[60 - dv, 80 - du],
        "top_right": rgb[60 - dv, 80 + du],
        "bottom_left": rgb[60 + dv, 80 - du],
        "bottom_right": rgb[60 + dv, 80 + du],
    }
    for name, want in zip(quads, (RED, GREEN, BLUE, YELLOW), strict=True):
        got = quads[name].astype(int)
        on = np.array(want) > 0
        assert np.all(got[on] > 150) and np.all(got[~on] < 40), (name, got)
    # outside the textured wall: sky above, floor below
    assert np.all(rgb[0, 80] == scene.sky_rgb)
    assert is_floor(rgb[H - 1, 80], scene)


def test_empty_scene_is_sky_above_and_checkered_floor_below() -> None:
    scene = Scene()
    rgb, depth = render(scene, 0.3, 0.2, 0.5, 0.4, **{**CAM, "far": 100.0})
    assert np.all(rgb[:60] == scene.sky_rgb)  # rows 0..59 look up, row 60 is level
    assert np.all(rgb[60] == scene.sky_rgb)
    bottom = rgb[61:].reshape(-1, 3)
    colours = {tuple(int(c) for c in px) for px in bottom}
    assert len(colours) == 2  # the 1 m checker tiles
    assert all(c[0] == c[1] == c[2] for c in colours)
    np.testing.assert_allclose(depth[H - 1], 0.5 / -row_b(H - 1), rtol=1e-6)
    # floor beyond far is sky
    rgb_far, depth_far = render(scene, 0.0, 0.0, 0.5, 0.0, **{**CAM, "far": 5.0})
    limit = 0.5 / 5.0  # |b| below which the floor lies beyond 5 m
    v_far = int(math.floor(60 + limit * INTR.fy))
    assert np.all(rgb_far[v_far] == scene.sky_rgb) and np.all(np.isnan(depth_far[v_far]))
    assert np.all(np.isfinite(depth_far[v_far + 1]))


def test_near_and_far_clip_depth() -> None:
    scene = wall_scene(0.0, 3.0)
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **{**CAM, "far": 1.9})
    assert np.all(rgb[60, 80] == scene.sky_rgb) and math.isnan(depth[60, 80])
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **{**CAM, "near": 2.5})
    assert is_red(rgb[60, 80]) and math.isnan(depth[60, 80])


def test_cylinder_side_and_top_cap() -> None:
    scene = Scene(circles=[[3.0, 0.0, 0.5]], circle_z=[[0.0, 0.5]], circle_rgb=[BLUE])
    rgb, depth = render(scene, 0.0, 0.0, 1.5, 0.0, **CAM)
    # side: rows whose ray is below 0.5 m at the entry distance 2.5
    v_side = 110
    assert 1.5 + 2.5 * row_b(v_side) < 0.5
    assert rgb[v_side, 80, 2] > 150 and depth[v_side, 80] == pytest.approx(2.5, abs=1e-5)
    # top cap: the ray crosses z = 0.5 between entry (2.5) and exit (3.5)
    v_cap = 99
    b = float(row_b(v_cap))
    t_cap = (0.5 - 1.5) / b
    assert 2.5 < t_cap < 3.5
    assert rgb[v_cap, 80, 2] > 150 and rgb[v_cap, 80, 0] < 60
    assert depth[v_cap, 80] == pytest.approx(t_cap, rel=1e-5)
    # above the cap the floor behind the cylinder shows
    v_behind = 90
    assert (0.5 - 1.5) / float(row_b(v_behind)) > 3.5
    assert is_floor(rgb[v_behind, 80], scene)


def test_depth_to_points_back_projects() -> None:
    scene = wall_scene()
    _, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    organised = depth_to_points(depth, HFOV, keep_invalid=True)
    assert organised.shape == (H * W, 3) and organised.dtype == np.float32
    np.testing.assert_allclose(organised[60 * W + 80], [0.0, 0.0, 2.0], atol=1e-6)
    assert np.all(np.isnan(organised[0]))  # sky pixel
    pts = depth_to_points(depth, HFOV)
    assert len(pts) == np.isfinite(depth).sum()
    body = optical_to_body(pts)
    on_wall = np.abs(body[:, 0] - 2.0) < 1e-4
    on_floor = np.abs(body[:, 2] + 1.0) < 1e-4  # the floor is 1 m below the camera
    assert np.all(on_wall | on_floor) and on_wall.sum() > 1000 and on_floor.sum() > 100
    assert np.all((body[on_wall, 2] >= -0.5 - 1e-4) & (body[on_wall, 2] <= 0.7 + 1e-4))
    # wall points span the image width: y (left) from +2 * tan(hfov_edge) to -...
    assert body[on_wall, 1].max() > 1.3 and body[on_wall, 1].min() < -1.3
    np.testing.assert_allclose(body_to_optical(body), pts, atol=1e-6)
    np.testing.assert_array_equal(optical_to_body([[1.0, 2.0, 3.0]]), [[3.0, -1.0, -2.0]])


def _mixed_scene() -> Scene:
    tex = np.array([[RED, GREEN], [BLUE, YELLOW]], dtype=np.uint8)
    segs = box_segments(-6, -6, 6, 6) + box_segments(2, -1, 2.5, 1)
    n = len(segs)
    return Scene(
        segments=segs,
        segment_z=[[0, 2.5]] * 4 + [[0.2, 0.5]] * 4,
        segment_rgb=[(200, 180, 160)] * 4 + [(200, 40, 40)] * 4,
        segment_texture=[0, 0] + [-1] * (n - 2),
        textures=[tex],
        circles=[[3, 2, 0.3], [-2, -2, 0.5], [1.5, 0.5, 0.4]],
        circle_z=[[0, 1.5], [0, 0.3], [0.6, 1.2]],
        circle_rgb=[GREEN, BLUE, YELLOW],
    )


@pytest.mark.parametrize(("z", "yaw"), [(1.0, 0.3), (2.0, 0.0), (0.4, -2.3), (1.3, -1.6)])
def test_level_and_tilted_paths_agree_at_zero_pitch(z: float, yaw: float) -> None:
    scene = _mixed_scene()
    a, da = render(scene, 0.0, 0.0, z, yaw, **CAM)
    b, db = render(scene, 0.0, 0.0, z, yaw, **CAM, pitch=1e-12)
    assert len(np.unique(a.reshape(-1, 3), axis=0)) > 6  # not a trivial view
    differ = np.any(a != b, axis=2)
    assert differ.mean() < 0.002
    both = np.isfinite(da) & np.isfinite(db)
    assert np.array_equal(np.isfinite(da), np.isfinite(db))
    np.testing.assert_allclose(da[both], db[both], rtol=1e-5)


def test_pitch_down(tmp_path: Path) -> None:
    scene = wall_scene(0.0, 1.5)
    pitch = 0.3
    rgb, depth = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM, pitch=pitch)
    level, _ = render(scene, 0.0, 0.0, 1.0, 0.0, **CAM)
    save(tmp_path, "pitch_down", rgb)
    # the optical axis meets the wall 2 m ahead at 2 / cos(pitch) along the axis
    assert depth[60, 80] == pytest.approx(2.0 / math.cos(pitch), rel=1e-5)
    # looking down shows more floor and less sky
    floor_px = sum(is_floor(p, scene) for p in rgb.reshape(-1, 3))
    floor_level = sum(is_floor(p, scene) for p in level.reshape(-1, 3))
    assert floor_px > floor_level
    # back-projected and rotated by the pitch, every wall pixel lies on the plane x = 2
    # (to within the half-column azimuth sampling of the tilted renderer)
    pts = depth_to_points(depth, HFOV, keep_invalid=True).astype(np.float64)
    body = optical_to_body(pts)
    c, s = math.cos(pitch), math.sin(pitch)
    x_level = c * body[:, 0] + s * body[:, 2]
    z_level = -s * body[:, 0] + c * body[:, 2]
    wall = np.isfinite(x_level) & (z_level > -0.99)
    assert wall.sum() > 5000
    assert np.max(np.abs(x_level[wall] - 2.0)) < 0.02
    # the wall's top edge projects to a straight line (no keystone curvature)
    top_rows = [np.flatnonzero(~np.all(rgb[:, u] == scene.sky_rgb, axis=1))[0] for u in range(W)]
    assert max(top_rows) - min(top_rows) <= 1


def test_render_validation() -> None:
    scene = wall_scene()
    with pytest.raises(RaycastInputError):
        render(scene, 0.0, 0.0, 1.0, 0.0, **{**CAM, "hfov": math.pi})
    with pytest.raises(RaycastInputError):
        render(scene, 0.0, 0.0, 1.0, 0.0, **{**CAM, "near": 5.0, "far": 5.0})
    with pytest.raises(RaycastInputError):
        render(scene, 0.0, 0.0, 1.0, 0.0, **{**CAM, "width": 0})
    with pytest.raises(RaycastInputError):
        render(scene, math.nan, 0.0, 1.0, 0.0, **CAM)
    with pytest.raises(RaycastInputError):
        render(scene, 0.0, 0.0, 1.0, 0.0, **CAM, pitch=1.4)
    with pytest.raises(RaycastInputError):
        depth_to_points(np.zeros((2, 3, 4)), HFOV)


@pytest.mark.parametrize("pitch", [0.0, 0.15])
def test_render_rgb_is_renders_image_and_writes_every_pixel_of_out(pitch: float) -> None:
    rng = np.random.default_rng(5)
    scene = random_scene(rng)
    out = np.full((48, 64, 3), 123, dtype=np.uint8)
    for _ in range(6):
        x, y = rng.uniform(-4, 4, 2)
        yaw = float(rng.uniform(-3, 3))
        kw = {"hfov": 1.2, "width": 64, "height": 48, "near": 0.05, "far": 30.0, "pitch": pitch}
        rgb, _ = render(scene, x, y, 0.3, yaw, **kw)
        got = render_rgb(scene, x, y, 0.3, yaw, out=out, **kw)
        assert got is out
        np.testing.assert_array_equal(got, rgb)
    with pytest.raises(RaycastInputError, match="out must be"):
        render_rgb(scene, 0, 0, 0.3, 0, hfov=1.2, width=64, height=48, near=0.05, far=30.0,
                   out=np.zeros((48, 64, 4), dtype=np.uint8))  # fmt: skip
