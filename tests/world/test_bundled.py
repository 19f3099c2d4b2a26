"""The bundled worlds: they load cleanly, spawn free, are closed and drivable."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageDraw
from scipy import ndimage

from roverlab.world import (
    BUNDLED_WORLDS,
    BUNDLED_WORLDS_DIR,
    World,
    WorldError,
    bundled_world_path,
    load_sdf,
    load_world,
)

RES = 0.05
ROBOT_RADIUS = 0.125  # a 0.25 m robot

# Points that a robot starting at the origin must be able to reach (one per room).
ROOMS: dict[str, list[tuple[float, float]]] = {
    "maze": [(-4.0 + 1.6 * (c + 0.5), -4.0 + 1.6 * (r + 0.5)) for c in range(5) for r in range(5)],
    "maze_faces": [
        (-4.0 + 1.6 * (c + 0.5), -4.0 + 1.6 * (r + 0.5)) for c in range(5) for r in range(5)
    ],
    "office": [(-2.0, -2.0), (-2.0, 2.0), (6.0, -1.5), (4.5, 1.5), (6.6, 3.5), (8.3, 0.8)],
    "house": [(-2.5, 0.5), (4.5, -1.5), (-1.0, 3.0), (3.5, 3.0)],
    "empty": [(3.0, 3.0)],
    # held out from exploration tuning (tests/world/make_held_out_worlds.py)
    "warehouse": [(-1.0, 3.0), (5.0, -3.9), (5.0, -1.5), (5.5, 0.9), (9.0, 3.5), (11.5, -2.0)],
    "apartment": [(-1.5, -2.5), (4.3, -1.0), (2.0, 2.1), (-1.0, 3.2), (2.5, 4.0), (5.5, 3.5)],
}


def render(world: World, path: Path) -> tuple[np.ndarray, tuple[float, float]]:
    """Occupancy as a PNG (north up), spawn pose in red; returns (grid, origin)."""
    grid, (ox, oy) = world.occupancy(RES)
    img = Image.fromarray(np.where(np.flipud(grid), 0, 255).astype(np.uint8)).convert("RGB")
    draw = ImageDraw.Draw(img)
    sx = (world.spawn.x - ox) / RES
    sy = grid.shape[0] - (world.spawn.y - oy) / RES
    r = ROBOT_RADIUS / RES
    draw.ellipse((sx - r, sy - r, sx + r, sy + r), fill=(255, 0, 0))
    img.save(path)
    return grid, (ox, oy)


def reachable(grid: np.ndarray, origin: tuple[float, float], radius: float) -> np.ndarray:
    """Cells a disc robot of ``radius`` can reach from the spawn at (0, 0)."""
    r = int(np.ceil(radius / RES))
    yy, xx = np.mgrid[-r : r + 1, -r : r + 1]
    blocked = ndimage.binary_dilation(grid, structure=(xx**2 + yy**2) <= r * r)
    labels, _ = ndimage.label(~blocked)
    start = labels[int((0 - origin[1]) / RES), int((0 - origin[0]) / RES)]
    assert start != 0, "the spawn cell itself is blocked"
    result: np.ndarray = labels == start
    return result


@pytest.mark.parametrize("name", sorted(BUNDLED_WORLDS))
def test_bundled_world_loads_clean_with_free_spawn(name: str, tmp_path: Path) -> None:
    w = load_world(name)
    assert w.name == name
    assert w.warnings == ()  # no bundled world needs a documented warning
    assert w.source == bundled_world_path(name)
    assert w.spawn_poses == (w.spawn,) and (w.spawn.x, w.spawn.y, w.spawn.theta) == (0.0, 0.0, 0.0)
    assert not w.footprint_collides(0.0, 0.0, 0.0, 0.2)
    assert not w.footprint_collides(0.0, 0.0, 0.0, 0.5)  # 0.5 m clearance around the spawn
    assert "Spawn: x=0 y=0 yaw=0" in w.source.read_text()
    scene = w.to_scene()
    assert scene.floor_rgb == (178, 178, 178)
    grid, origin = render(w, tmp_path / f"{name}.png")
    assert (tmp_path / f"{name}.png").stat().st_size > 0
    if name == "empty":
        assert not grid.any() and len(scene.segments) == 0
        return
    assert grid.any() and len(scene.segments) > 0
    free = reachable(grid, origin, ROBOT_RADIUS + 0.05)
    for x, y in ROOMS[name]:
        assert free[int((y - origin[1]) / RES), int((x - origin[0]) / RES)], (
            f"{name}: ({x}, {y}) unreachable"
        )
    # closed: the free space around the spawn never reaches the edge of the map
    assert not (free[0].any() or free[-1].any() or free[:, 0].any() or free[:, -1].any())


def test_maze_is_closed_8_by_8_with_wide_corridors() -> None:
    w = load_world("maze")
    xmin, ymin, xmax, ymax = w.bounds
    assert xmax - xmin == pytest.approx(8.15, abs=1e-3) and ymax - ymin == pytest.approx(
        8.15, abs=1e-3
    )
    assert all(s.name.startswith("Wall_") for s in w.shapes)
    grid, origin = w.occupancy(RES)
    # without any robot radius the inside is still sealed from the outside
    labels, _ = ndimage.label(~grid)
    inside = labels == labels[int(-origin[1] / RES), int(-origin[0] / RES)]
    assert not (inside[0].any() or inside[-1].any() or inside[:, 0].any() or inside[:, -1].any())
    # corridors >= 0.8 m: a 0.8 m disc fits in the middle of every cell
    for x, y in ROOMS["maze"]:
        assert not w.footprint_collides(x, y, 0.0, 0.4)


def test_maze_world_is_saved_the_gazebo_way() -> None:
    # the <state> link poses and the model's own poses put every wall at the same place
    from_state = load_world("maze")
    from_model = load_sdf(BUNDLED_WORLDS_DIR / "models" / "maze" / "model.sdf")
    assert [s.name for s in from_state.shapes] == [s.name for s in from_model.shapes]
    assert np.allclose(from_state.to_scene().segments, from_model.to_scene().segments, atol=1e-6)
    text = (BUNDLED_WORLDS_DIR / "maze.world").read_text()
    for needle in (
        "model://ground_plane",
        "model://sun",
        "model://maze",
        "<state world_name='default'>",
    ):
        assert needle in text
    model = BUNDLED_WORLDS_DIR / "models" / "maze"
    assert (model / "model.config").is_file() and "<link name='Wall_0'>" in (
        model / "model.sdf"
    ).read_text()


def test_office_poster_faces_the_spawn() -> None:
    w = load_world("office")
    scene = w.to_scene()
    assert len(scene.textures) == 1
    face = scene.textures[0]
    assert face.shape == (200, 200, 3) and face.std() > 20
    textured = np.flatnonzero(scene.segment_texture == 0)
    segs = scene.segments[textured]
    # the face of the poster seen from the spawn: the 1 m side at the smallest x
    front = segs[np.argmin(segs[:, 0] + segs[:, 2])]
    x0, y0, x1, y1 = front
    assert x0 == pytest.approx(2.905) and x1 == pytest.approx(2.905)
    assert (y0, y1) == pytest.approx((0.5, -0.5))  # left to right as seen looking along +x
    assert scene.segment_z[textured[0]].tolist() == pytest.approx([0.2, 1.2])
    assert not w.footprint_collides(2.6, 0.0, 0.0, 0.2)  # a robot can drive up to it


def test_held_out_worlds_are_their_generator_s_output(tmp_path: Path) -> None:
    # written once by the script and never edited by hand (docs/exploration.md)
    script = Path(__file__).with_name("make_held_out_worlds.py")
    subprocess.run([sys.executable, str(script), str(tmp_path)], check=True, capture_output=True)
    for name in ("warehouse", "apartment"):
        assert (tmp_path / f"{name}.world").read_bytes() == bundled_world_path(name).read_bytes()


def test_unknown_bundled_name() -> None:
    with pytest.raises(WorldError, match="unknown world 'moon'"):
        bundled_world_path("moon")
