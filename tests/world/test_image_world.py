"""Map images (map_server YAML + PGM/PNG) as worlds of merged wall boxes."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from roverlab.world import BoxShape, WorldError, load_image_world, load_world, occupied_rectangles

# image rows top to bottom; 0 = black (occupied), 254 = free, 205 = unknown
PIXELS = np.array(
    [
        [0, 0, 0, 0, 0, 0],
        [0, 254, 254, 205, 254, 0],
        [0, 254, 0, 0, 254, 0],
        [0, 254, 0, 0, 254, 0],
        [0, 0, 0, 254, 0, 0],
    ],
    dtype=np.uint8,
)


def write_map(
    tmp_path: Path,
    pixels: np.ndarray,
    *,
    yaml_extra: str = "",
    origin: str = "[-1.0, 2.0, 0.0]",
    resolution: float = 0.5,
) -> Path:
    Image.fromarray(pixels).save(tmp_path / "map.pgm")
    f = tmp_path / "map.yaml"
    f.write_text(
        f"image: map.pgm\nresolution: {resolution}\n"
        f"origin: {origin}\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n{yaml_extra}"
    )
    return f


def test_occupied_pixels_become_boxes_covering_exactly_those_cells(tmp_path: Path) -> None:
    w = load_image_world(write_map(tmp_path, PIXELS), wall_height=1.5)
    assert w.name == "map" and w.warnings == ()
    occupied = PIXELS == 0
    assert all(isinstance(s, BoxShape) for s in w.shapes)
    # merged: far fewer boxes than occupied pixels, same area
    assert len(w.shapes) < occupied.sum() / 2
    area = sum(s.size[0] * s.size[1] for s in w.shapes if isinstance(s, BoxShape))
    assert area == pytest.approx(occupied.sum() * 0.25)
    assert all(s.size[2] == 1.5 for s in w.shapes if isinstance(s, BoxShape))
    # occupancy() on the image's own grid gives the image back (row 0 of the grid = bottom row)
    grid, origin = w.occupancy(0.5, bounds=(-1.0, 2.0, -1.0 + 6 * 0.5, 2.0 + 5 * 0.5))
    assert origin == (-1.0, 2.0)
    assert np.array_equal(grid, occupied[::-1])
    # and the unknown (205) pixel is not a wall
    assert not grid[3, 3]


def test_round_trip_at_finer_resolution(tmp_path: Path) -> None:
    w = load_image_world(write_map(tmp_path, PIXELS))
    grid, _ = w.occupancy(0.25, bounds=(-1.0, 2.0, 2.0, 4.5))
    assert np.array_equal(grid, np.kron(PIXELS[::-1] == 0, np.ones((2, 2), dtype=bool)))


def test_occupied_rectangles_tile_the_mask_without_overlap() -> None:
    rng = np.random.default_rng(3)
    mask = rng.random((40, 50)) < 0.4
    mask[5:20, 10:30] = True
    rects = occupied_rectangles(mask)
    cover = np.zeros(mask.shape, dtype=int)
    for c0, r0, c1, r1 in rects:
        cover[r0:r1, c0:c1] += 1
    assert np.array_equal(cover, mask.astype(int))
    runs = int(np.sum(np.diff(np.pad(mask.astype(np.int8), ((0, 0), (1, 0))), axis=1) == 1))
    assert len(rects) < runs  # identical runs of consecutive rows were merged
    assert occupied_rectangles(np.zeros((3, 3), bool)).shape == (0, 4)


def test_a_big_map_stays_a_few_boxes(tmp_path: Path) -> None:
    pixels = np.full((1000, 1000), 254, np.uint8)
    pixels[:20, :] = pixels[-20:, :] = pixels[:, :20] = pixels[:, -20:] = 0
    pixels[300:700, 480:520] = 0
    f = write_map(tmp_path, pixels, origin="[-25.0, -25.0, 0.0]", resolution=0.05)
    t0 = time.perf_counter()
    w = load_world(f)  # dispatched on the map keys
    assert len(w.shapes) <= 6
    grid, _ = w.occupancy(0.05, bounds=(-25.0, -25.0, 25.0, 25.0))
    assert np.array_equal(grid, (pixels == 0)[::-1])
    assert time.perf_counter() - t0 < 10.0


def test_negate_and_origin_yaw(tmp_path: Path) -> None:
    pixels = np.zeros((2, 3), np.uint8)
    pixels[1, 0] = 255  # with negate, white is occupied: the bottom-left pixel
    f = write_map(tmp_path, pixels, yaml_extra="", origin=f"[1.0, 1.0, {math.pi / 2}]")
    f.write_text(f.read_text().replace("negate: 0", "negate: 1"))
    w = load_image_world(f)
    (box,) = w.shapes
    assert isinstance(box, BoxShape)
    # pixel centre (0.25, 0.25) in the map frame, turned 90 degrees about the origin (1, 1)
    assert box.transform.translation[:2] == pytest.approx((0.75, 1.25))
    assert box.transform.yaw == pytest.approx(math.pi / 2)


def test_colour_png_and_unknown_keys(tmp_path: Path) -> None:
    rgb = np.full((2, 2, 3), 255, np.uint8)
    rgb[0, 0] = (10, 10, 10)
    Image.fromarray(rgb).save(tmp_path / "m.png")
    f = tmp_path / "m.yaml"
    f.write_text("image: m.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: 0\nfoo: 1\n")
    w = load_image_world(f)
    assert len(w.shapes) == 1
    assert w.bounds == pytest.approx((0.0, 1.0, 1.0, 2.0))
    assert len(w.warnings) == 1 and "'foo'" in w.warnings[0]


@pytest.mark.parametrize(
    ("text", "needle"),
    [
        ("image: none.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n", "not found"),
        ("image: map.pgm\nresolution: 0\norigin: [0, 0, 0]\n", "resolution"),
        ("image: map.pgm\nresolution: 0.1\norigin: [0, 0]\n", "origin"),
        ("image: map.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nmode: fancy\n", "mode"),
        ("image: map.pgm\nresolution: 0.1\norigin: [0, 0, 0]\nnegate: 2\n", "negate"),
    ],
)
def test_bad_map_yaml(tmp_path: Path, text: str, needle: str) -> None:
    Image.fromarray(PIXELS).save(tmp_path / "map.pgm")
    f = tmp_path / "bad.yaml"
    f.write_text(text)
    with pytest.raises(WorldError) as info:
        load_image_world(f)
    assert str(f) in str(info.value) and needle in str(info.value) and "\n" not in str(info.value)
