"""The YAML world format: every key, strict validation, load_world dispatch."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.geometry import SE2
from roverlab.world import (
    BoxShape,
    CylinderShape,
    PolylineShape,
    PosterShape,
    WorldError,
    load_world,
    load_yaml_world,
)

EXAMPLE = """
name: office
floor_rgb: [110, 110, 110]
sky_rgb: [10, 20, 30]
gravity: [0, 0, -3.7]
walls:
  - {from: [0, 0], to: [10, 0], thickness: 0.1, height: 2.5}
  - {points: [[0, 0], [0, 5], [10, 5]], rgb: [50, 60, 70], name: north}
boxes:
  - {center: [3, 2], size: [1, 0.6, 0.75], yaw: 0.3, rgb: [150, 100, 60], name: desk}
  - {center: [6, 2], size: [1, 1, 1], z: 0.5, texture: face.png}
cylinders:
  - {center: [5, 3], radius: 0.2, height: 1.0}
polygons:
  - {points: [[7, 1], [8, 1], [7.5, 2]], height: 0.5}
posters:
  - {image: face.png, from: [2, 4.9], to: [3, 4.9], z: [1.0, 2.0]}
spawn: {x: 1.0, y: 1.0, yaw: 0.5}
"""


@pytest.fixture
def example(tmp_path: Path) -> Path:
    Image.new("RGB", (8, 8), (200, 150, 120)).save(tmp_path / "face.png")
    f = tmp_path / "office.yaml"
    f.write_text(EXAMPLE)
    return f


def test_example_world(example: Path) -> None:
    w = load_yaml_world(example)
    assert w.name == "office" and w.source == example and w.warnings == ()
    assert w.floor_rgb == (110, 110, 110) and w.sky_rgb == (10, 20, 30)
    assert w.gravity == (0.0, 0.0, -3.7)
    assert w.spawn == SE2(1.0, 1.0, 0.5)
    kinds = [type(s).__name__ for s in w.shapes]
    assert kinds == ["BoxShape"] * 5 + ["CylinderShape", "PolylineShape", "PosterShape"]
    wall = w.shapes[0]
    assert isinstance(wall, BoxShape)
    # 10 m centre line, grown by half the thickness at each end; standing on the floor
    assert wall.size == pytest.approx((10.1, 0.1, 2.5))
    assert wall.transform.translation == pytest.approx((5.0, 0.0, 1.25))
    chain = w.shapes[1:3]
    assert [s.name for s in chain] == ["north_0", "north_1"]
    assert isinstance(chain[0], BoxShape) and chain[0].rgb == (50, 60, 70)
    assert chain[0].transform.yaw == pytest.approx(math.pi / 2)
    desk = w.shapes[3]
    assert isinstance(desk, BoxShape) and desk.name == "desk"
    assert desk.transform.yaw == pytest.approx(0.3) and desk.transform.translation[
        2
    ] == pytest.approx(0.375)
    textured = w.shapes[4]
    assert isinstance(textured, BoxShape) and textured.texture == example.parent / "face.png"
    assert textured.transform.translation[2] == pytest.approx(1.0)
    cyl = w.shapes[5]
    assert isinstance(cyl, CylinderShape) and cyl.length == 1.0
    assert isinstance(w.shapes[6], PolylineShape)
    poster = w.shapes[7]
    assert isinstance(poster, PosterShape) and poster.z_range == (1.0, 2.0)
    scene = w.to_scene()
    assert len(scene.textures) == 1  # the box and the poster share one image
    assert (scene.segment_texture >= 0).sum() == 5
    # walls meet at the corner (0, 0) without a gap
    assert w.footprint_collides(0.0, 0.0, 0.0, 0.01)
    grid, (_, oy) = w.occupancy(0.05, bounds=(-0.5, -0.5, 10.5, 5.5))
    assert grid[int((0 - oy) / 0.05), :].sum() > 200


def test_load_world_dispatches_yaml(example: Path) -> None:
    assert load_world(example).name == "office"
    assert load_world(str(example)).name == "office"


def test_spawn_list_and_defaults(tmp_path: Path) -> None:
    f = tmp_path / "s.yml"
    f.write_text("spawn:\n  - {x: 1}\n  - {y: 2, yaw: 3}\n")
    w = load_world(f)
    assert w.name == "s" and w.spawn_poses == (SE2(1.0, 0.0, 0.0), SE2(0.0, 2.0, 3.0))
    f.write_text("")
    assert load_yaml_world(f).shapes == ()


@pytest.mark.parametrize(
    ("text", "needles"),
    [
        ("wals: []\n", ("unknown key 'wals'",)),
        (
            "walls:\n  - {from: [0, 0], to: [1, 0], thicknes: 0.1}\n",
            ("walls[0]", "unknown key 'thicknes'"),
        ),
        ("boxes:\n  - {center: [0, 0], size: [1, 0, 1]}\n", ("boxes[0].size", "positive")),
        ("boxes:\n  - {center: [0, 0]}\n", ("boxes[0]", "missing key 'size'")),
        ("cylinders:\n  - {center: [0, 0], radius: .nan, height: 1}\n", ("cylinders[0].radius",)),
        (
            "cylinders:\n  - {center: [0], radius: 1, height: 1}\n",
            ("cylinders[0].center", "2 finite"),
        ),
        ("walls:\n  - {from: [0, 0], to: [0, 0]}\n", ("walls[0]", "zero length")),
        ("walls:\n  - {from: [0, 0], to: [1, 0], rgb: [0, 0, 300]}\n", ("walls[0].rgb",)),
        ("walls: {from: [0, 0]}\n", ("walls", "must be a list")),
        (
            "posters:\n  - {image: none.png, from: [0, 0], to: [1, 0], z: [0, 1]}\n",
            ("posters[0].image", "not found"),
        ),
        (
            "polygons:\n  - {points: [[0, 0], [1, 0]], height: 1}\n",
            ("polygons[0].points", "at least 3"),
        ),
        ("spawn: {x: 1, theta: 2}\n", ("spawn", "unknown key 'theta'")),
        ("floor_rgb: [1, 2]\n", (": floor_rgb: must be [r, g, b]",)),
        ("name: 7\n", (": name: must be a string",)),
        ("- just\n- a list\n", ("must be a mapping",)),
        ("walls: [\n", ("malformed YAML",)),
    ],
)
def test_bad_yaml_worlds_name_file_and_key(
    tmp_path: Path, text: str, needles: tuple[str, ...]
) -> None:
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    with pytest.raises(WorldError) as info:
        load_world(f)
    msg = str(info.value)
    assert "\n" not in msg and str(f) in msg
    for n in needles:
        assert n in msg


def test_unknown_suffix_and_missing_file(tmp_path: Path) -> None:
    f = tmp_path / "w.txt"
    f.write_text("x")
    with pytest.raises(WorldError, match="unknown world file type"):
        load_world(f)
    with pytest.raises(WorldError, match="not found"):
        load_world(tmp_path / "none.yaml")
    with pytest.raises(
        WorldError,
        match="bundled worlds are apartment, empty, house, maze, maze_faces, office, warehouse",
    ):
        load_world("mze")


def test_wall_chain_closed(tmp_path: Path) -> None:
    f = tmp_path / "room.yaml"
    f.write_text(
        "walls:\n  - {points: [[0, 0], [4, 0], [4, 3], [0, 3]], closed: true, thickness: 0.2}\n"
    )
    w = load_world(f)
    assert len(w.shapes) == 4
    assert w.bounds == pytest.approx((-0.1, -0.1, 4.1, 3.1))
    grid, _ = w.occupancy(0.1, bounds=(-0.5, -0.5, 4.5, 3.5))
    # row 5 is y in [0, 0.1] (on the south wall), column 5 is x in [0, 0.1] (west wall)
    border = np.concatenate([grid[5, 4:46], grid[4:36, 5], grid[34, 4:46], grid[4:36, 45]])
    assert border.all()
    assert not grid[7:33, 7:43].any()
