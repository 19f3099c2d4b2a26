"""map_server / map_saver files: exact bytes, round trips, every mode, bad input, atomicity."""

from __future__ import annotations

import errno
import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from roverlab.maps import (
    MapError,
    MapInfo,
    MapMode,
    cell_counts,
    format_map_yaml,
    image_to_occupancy,
    load_map,
    map_io,
    occupancy_to_image,
    read_image_pixels,
    read_map_yaml,
    save_map,
    save_occupancy_grid,
)
from roverlab.msgs import array_to_occupancy_grid, pose_from_xytheta

MAP_SAVER_YAML = (
    "image: office.pgm\n"
    "resolution: 0.050000\n"
    "origin: [-12.500000, 3.250000, 0.785398]\n"
    "negate: 0\n"
    "occupied_thresh: 0.65\n"
    "free_thresh: 0.196\n"
    "\n"
)


def _trinary(rng: np.random.Generator, shape: tuple[int, int]) -> np.ndarray:
    return rng.choice(np.array([-1, 0, 100], dtype=np.int8), size=shape)


def _write_yaml(path: Path, image: str | None = "m.pgm", **overrides: Any) -> Path:
    doc: dict[str, Any] = {
        "image": image,
        "resolution": 0.05,
        "origin": "[0.0, 0.0, 0.0]",
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    doc.update(overrides)
    lines = [f"{k}: {v}" for k, v in doc.items() if v is not None]
    path.write_text("\n".join(lines) + "\n")
    return path


def _ros_loader(
    pixels: np.ndarray, *, has_alpha: bool, negate: bool, occ_th: float, free_th: float, mode: str
) -> np.ndarray:
    """image_loader.cpp, one pixel at a time (the reference)."""
    h, w, n_channels = pixels.shape
    out = np.zeros((h, w), dtype=np.int8)
    avg_channels = n_channels if (mode == "trinary" or not has_alpha) else n_channels - 1
    for j in range(h):
        for i in range(w):
            p = [int(v) for v in pixels[j, i]]
            color_avg = sum(p[:avg_channels]) / float(avg_channels)
            alpha = 1 if n_channels == 1 else p[n_channels - 1]
            if negate:
                color_avg = 255 - color_avg
            if mode == "raw":
                value = int(color_avg)  # double -> unsigned char, then stored as int8
            else:
                occ = (255 - color_avg) / 255.0
                if occ > occ_th:
                    value = 100
                elif occ < free_th:
                    value = 0
                elif mode == "trinary" or alpha < 1.0:
                    value = -1
                else:
                    value = int(1 + 98 * ((occ - free_th) / (occ_th - free_th)))
            out[h - j - 1, i] = np.uint8(value & 0xFF).view(np.int8)
    return out


# ------------------------------------------------------------------------------- saving
def test_map_saver_yaml_text_and_pgm_header_exact(tmp_path: Path) -> None:
    data = np.array([[0, 100, -1], [25, 65, 64]], dtype=np.int8)
    saved = save_map(tmp_path / "office", data, resolution=0.05, origin=(-12.5, 3.25, 0.785398))
    assert saved.yaml_path == tmp_path / "office.yaml"
    assert saved.image_path == tmp_path / "office.pgm"
    assert saved.yaml_path.read_text() == MAP_SAVER_YAML
    raw = saved.image_path.read_bytes()
    header = b"P5\n# CREATOR: map_saver.cpp 0.050 m/pix\n3 2\n255\n"
    assert raw.startswith(header)
    # top row of the image = last map row; 25 -> free, 65 -> occupied, 64 -> unknown
    assert raw[len(header) :] == bytes([254, 0, 205, 254, 0, 205])


def test_map_saver_thresholds() -> None:
    cells = np.array([[-1, 0, 25, 26, 64, 65, 100, -128, 127]], dtype=np.int8)
    assert occupancy_to_image(cells)[0].tolist() == [205, 254, 254, 205, 205, 0, 0, 205, 0]
    custom = occupancy_to_image(cells, threshold_occupied=50, threshold_free=10)
    assert custom[0].tolist() == [205, 254, 205, 205, 0, 0, 0, 205, 0]


@pytest.mark.parametrize(
    ("occ", "free", "match"),
    [
        (0, 0, "between 1 and 100"),
        (101, 25, "between 1 and 100"),
        (65, -1, "0 and 100"),
        (30, 30, "smaller than"),
    ],
)
def test_map_saver_threshold_checks(tmp_path: Path, occ: int, free: int, match: str) -> None:
    with pytest.raises(MapError, match=match):
        save_map(
            tmp_path / "m",
            np.zeros((2, 2), np.int8),
            resolution=0.05,
            threshold_occupied=occ,
            threshold_free=free,
        )
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("fmt", ["pgm", "png"])
def test_round_trip_trinary(tmp_path: Path, fmt: str) -> None:
    rng = np.random.default_rng(3)
    data = _trinary(rng, (37, 53))
    origin = (-12.5, 3.25, -0.5)
    saved = save_map(tmp_path / "m", data, resolution=0.025, origin=origin, image_format=fmt)  # type: ignore[arg-type]
    assert saved.image_path.suffix == f".{fmt}"
    assert f"image: m.{fmt}\n" in saved.yaml_path.read_text()
    loaded = load_map(saved.yaml_path)
    assert loaded.data.dtype == np.int8
    assert np.array_equal(loaded.data, data)
    assert loaded.info.resolution == 0.025
    assert loaded.info.origin == origin
    assert loaded.info.mode is MapMode.TRINARY and not loaded.info.negate
    assert (loaded.width, loaded.height) == (53, 37)
    assert loaded.counts() == cell_counts(data)


def test_round_trip_of_a_message_keeps_yaw_and_is_byte_stable(tmp_path: Path) -> None:
    rng = np.random.default_rng(4)
    grid = array_to_occupancy_grid(
        _trinary(rng, (20, 30)), resolution=0.05, origin=(1.5, -2.0, 0.5)
    )
    first = save_occupancy_grid(tmp_path / "a", grid)
    assert "origin: [1.500000, -2.000000, 0.500000]\n" in first.yaml_path.read_text()
    msg = load_map(first.yaml_path).to_msg(frame_id="map")
    assert msg.info.origin.orientation.z == pytest.approx(math.sin(0.25))
    second = save_occupancy_grid(tmp_path / "b", msg)
    assert second.image_path.read_bytes() == first.image_path.read_bytes()
    assert second.yaml_path.read_text() == first.yaml_path.read_text().replace("a.pgm", "b.pgm")


def test_yaw_of_unnormalised_and_zero_quaternions(tmp_path: Path) -> None:
    grid = array_to_occupancy_grid(np.zeros((2, 2), np.int8), resolution=0.1)
    q = pose_from_xytheta(0, 0, -1.25).orientation
    grid.info.origin.orientation.z, grid.info.origin.orientation.w = q.z * 3, q.w * 3
    save_occupancy_grid(tmp_path / "scaled", grid)
    assert "origin: [0.000000, 0.000000, -1.250000]" in (tmp_path / "scaled.yaml").read_text()
    grid.info.origin.orientation.z = grid.info.origin.orientation.w = 0.0
    save_occupancy_grid(tmp_path / "zero", grid)
    assert "origin: [0.000000, 0.000000, 0.000000]" in (tmp_path / "zero.yaml").read_text()


def test_saved_map_loads_from_another_folder(tmp_path: Path) -> None:
    (tmp_path / "maps").mkdir()
    data = np.array([[0, 100]], dtype=np.int8)
    save_map(tmp_path / "maps" / "m", data, resolution=0.1)
    assert "image: m.pgm\n" in (tmp_path / "maps" / "m.yaml").read_text()
    cwd = os.getcwd()
    try:
        os.chdir(tmp_path)  # the image is found relative to the YAML, not the cwd
        assert np.array_equal(load_map("maps/m.yaml").data, data)
    finally:
        os.chdir(cwd)


def test_format_map_yaml_modes_and_quoting() -> None:
    text = format_map_yaml(
        "a: b.png", resolution=0.1, negate=True, occupied_thresh=0.9, free_thresh=0.1, mode="scale"
    )
    assert text.endswith("negate: 1\noccupied_thresh: 0.9\nfree_thresh: 0.1\nmode: scale\n\n")
    assert text.startswith('image: "a: b.png"\n')


# ------------------------------------------------------------------------------- loading
GREYS = np.array([[0, 50, 100, 150, 200, 205, 230, 254, 255]], dtype=np.uint8)


def test_trinary_values_of_map_saver_greys(tmp_path: Path) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.pgm")
    data = load_map(_write_yaml(tmp_path / "m.yaml")).data
    assert data[0].tolist() == [100, 100, -1, -1, -1, -1, 0, 0, 0]


def test_negate(tmp_path: Path) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.pgm")
    data = load_map(_write_yaml(tmp_path / "m.yaml", negate=1)).data
    assert data[0].tolist() == [0, -1, -1, -1, 100, 100, 100, 100, 100]  # 50 -> p = 0.19608


def test_scale_mode(tmp_path: Path) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.png")
    data = load_map(_write_yaml(tmp_path / "m.yaml", image="m.png", mode="scale")).data
    # p = (255 - v) / 255; in between: 1 + 98 * (p - 0.196) / (0.65 - 0.196), truncated
    expect = [100, 100, 89, 47, 5]
    expect += [int(1 + 98 * ((50 / 255 - 0.196) / (0.65 - 0.196))), 0, 0, 0]
    assert data[0].tolist() == expect
    assert expect[5] == 1


def test_raw_mode(tmp_path: Path) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.pgm")
    data = load_map(_write_yaml(tmp_path / "m.yaml", mode="raw")).data
    assert data[0].tolist() == [0, 50, 100, -106, -56, -51, -26, -2, -1]
    negated = load_map(_write_yaml(tmp_path / "n.yaml", mode="raw", negate=1)).data
    assert negated[0].tolist() == [-1, -51, -101, 105, 55, 50, 25, 1, 0]


def test_image_top_row_is_the_last_map_row(tmp_path: Path) -> None:
    img = np.array([[0, 0], [254, 254], [205, 205]], dtype=np.uint8)
    Image.fromarray(img, mode="L").save(tmp_path / "m.pgm")
    data = load_map(_write_yaml(tmp_path / "m.yaml")).data
    assert data[:, 0].tolist() == [-1, 0, 100]


def test_alpha_channel_handling(tmp_path: Path) -> None:
    rgba = np.array(
        [[[255, 255, 255, 0], [0, 0, 0, 0], [128, 128, 128, 0], [128, 128, 128, 255]]], np.uint8
    )
    Image.fromarray(rgba, mode="RGBA").save(tmp_path / "m.png")
    # trinary: alpha is averaged in (white but transparent: p = 0.25 -> unknown)
    tri = load_map(_write_yaml(tmp_path / "t.yaml", image="m.png")).data
    assert tri[0].tolist() == [-1, 100, -1, -1]
    # scale: alpha left out of the average; a transparent in-between pixel is unknown
    scale = load_map(_write_yaml(tmp_path / "s.yaml", image="m.png", mode="scale")).data
    p = (255 - 128) / 255
    assert scale[0].tolist() == [0, 100, -1, int(1 + 98 * (p - 0.196) / (0.65 - 0.196))]


def test_grey_alpha_png_reads_as_rgba(tmp_path: Path) -> None:
    la = np.array([[[128, 0], [128, 255]]], dtype=np.uint8)
    Image.fromarray(la, mode="LA").save(tmp_path / "m.png")
    pixels, has_alpha = read_image_pixels(tmp_path / "m.png")
    assert has_alpha and pixels.shape == (1, 2, 4)
    assert pixels[0, 1].tolist() == [128, 128, 128, 255]


def test_rgb_blue_channel_acts_as_alpha_in_scale_mode(tmp_path: Path) -> None:
    rgb = np.array([[[128, 128, 128], [192, 192, 0]]], dtype=np.uint8)
    Image.fromarray(rgb, mode="RGB").save(tmp_path / "m.png")
    data = load_map(_write_yaml(tmp_path / "m.yaml", image="m.png", mode="scale")).data
    assert data[0, 0] > 0 and data[0, 1] == -1  # map_server's quirk, kept


def test_sixteen_bit_and_palette_images(tmp_path: Path) -> None:
    Image.fromarray(np.array([[0x0000, 0xFE80, 0x8000]], dtype=np.uint16)).save(tmp_path / "g.png")
    pixels, _ = read_image_pixels(tmp_path / "g.png")
    assert pixels[0, :, 0].tolist() == [0, 254, 128]
    pal = Image.fromarray(np.array([[0, 1, 2]], dtype=np.uint8), mode="P")
    pal.putpalette([255, 255, 255, 0, 0, 0, 9, 9, 9])
    pal.save(tmp_path / "p.png")
    pixels, has_alpha = read_image_pixels(tmp_path / "p.png")
    assert pixels[0, :, 0].tolist() == [0, 1, 2] and not has_alpha  # indices, as in ROS


@pytest.mark.parametrize("seed", range(6))
def test_loader_matches_image_loader_cpp(seed: int) -> None:
    rng = np.random.default_rng(seed)
    channels, has_alpha = [(1, False), (3, False), (4, True), (4, False)][seed % 4]
    pixels = rng.integers(0, 256, size=(7, 9, channels), dtype=np.uint8)
    pixels[0, 0, -1] = 0  # a fully transparent pixel
    for mode in ("trinary", "scale", "raw"):
        for negate in (False, True):
            got = image_to_occupancy(
                pixels,
                has_alpha=has_alpha,
                negate=negate,
                occupied_thresh=0.6,
                free_thresh=0.25,
                mode=mode,
            )
            ref = _ros_loader(
                pixels, has_alpha=has_alpha, negate=negate, occ_th=0.6, free_th=0.25, mode=mode
            )
            assert np.array_equal(got, ref), (mode, negate)


def test_pgm_and_png_of_one_image_load_the_same(tmp_path: Path) -> None:
    img = np.random.default_rng(5).integers(0, 256, size=(11, 13), dtype=np.uint8)
    Image.fromarray(img, mode="L").save(tmp_path / "m.pgm")
    Image.fromarray(img, mode="L").save(tmp_path / "m.png")
    a = load_map(_write_yaml(tmp_path / "a.yaml", image="m.pgm", mode="scale")).data
    b = load_map(_write_yaml(tmp_path / "b.yaml", image="m.png", mode="scale")).data
    assert np.array_equal(a, b)
    assert len(np.unique(a)) > 10


def test_yaml_values(tmp_path: Path) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.pgm")
    info = read_map_yaml(
        _write_yaml(tmp_path / "m.yaml", resolution="5e-2", origin="[-1, 2.5, 0.1]", extra="x")
    )
    assert info == MapInfo(
        image=tmp_path / "m.pgm", resolution=0.05, origin=(-1.0, 2.5, 0.1), negate=False
    )
    absolute = read_map_yaml(_write_yaml(tmp_path / "abs.yaml", image=str(tmp_path / "m.pgm")))
    assert absolute.image == tmp_path / "m.pgm"


# ------------------------------------------------------------------------------- errors
BAD_YAML = [
    ("image: [unclosed\n", "malformed YAML"),
    ("- a\n- b\n", "mapping"),
    (None, "missing key"),
    ("resolution: -0.05", "resolution"),
    ("resolution: abc", "'resolution' must be a number"),
    ("resolution: .nan", "'resolution' must be finite"),
    ("origin: [1, 2]", "'origin'"),
    ("origin: [1, x, 0]", "origin[1]"),
    ("negate: maybe", "'negate'"),
    ("free_thresh: 0.9", "thresholds"),
    ("occupied_thresh: 1.5", "thresholds"),
    ("mode: fuzzy", "invalid mode"),
    ("image: ''", "'image'"),
]


@pytest.mark.parametrize(("change", "match"), BAD_YAML)
def test_malformed_yaml(tmp_path: Path, change: str | None, match: str) -> None:
    Image.fromarray(GREYS, mode="L").save(tmp_path / "m.pgm")
    path = tmp_path / "bad.yaml"
    if change is None:
        _write_yaml(path, free_thresh=None)
    elif ":" in change and not change.startswith(("image: [", "- ")):
        key, _, value = change.partition(": ")
        _write_yaml(path, **{key: value})
    else:
        path.write_text(change)
    with pytest.raises(MapError, match=re.escape(match)) as info:
        load_map(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message


@pytest.mark.parametrize(
    "key", ["image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"]
)
def test_each_required_key(tmp_path: Path, key: str) -> None:
    path = _write_yaml(tmp_path / "m.yaml", **{key: None})
    with pytest.raises(MapError, match=f"missing key '{key}'"):
        read_map_yaml(path)


def test_missing_and_unreadable_files(tmp_path: Path) -> None:
    with pytest.raises(MapError, match=re.escape("nope.yaml: map file not found")):
        load_map(tmp_path / "nope.yaml")
    with pytest.raises(MapError, match="cannot read map file"):
        load_map(tmp_path)  # a folder
    yaml_path = _write_yaml(tmp_path / "m.yaml", image="gone.pgm")
    with pytest.raises(MapError, match=re.escape("gone.pgm: image file not found")):
        load_map(yaml_path)
    (tmp_path / "junk.pgm").write_bytes(b"this is no image")
    with pytest.raises(MapError, match=re.escape("junk.pgm: cannot read image")):
        load_map(_write_yaml(tmp_path / "j.yaml", image="junk.pgm"))
    (tmp_path / "short.pgm").write_bytes(b"P5\n10 10\n255\n" + bytes(20))
    with pytest.raises(MapError, match=re.escape("short.pgm: cannot read image")):
        load_map(_write_yaml(tmp_path / "s.yaml", image="short.pgm"))


# ------------------------------------------------------------------------------- atomicity
def _fail_on_call(n: int, real: Any) -> Any:
    calls = [0]

    def fake(*args: Any) -> Any:
        calls[0] += 1
        if calls[0] == n:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(*args)

    return fake


@pytest.mark.parametrize(
    ("what", "call", "named"),
    [
        ("fsync", 1, "m.pgm"),  # writing the image fails
        ("fsync", 2, "m.yaml"),  # writing the YAML fails after the image was written
        ("replace", 1, "m.pgm"),  # renaming into place fails
    ],
)
def test_failed_save_leaves_nothing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, what: str, call: int, named: str
) -> None:
    monkeypatch.setattr(map_io.os, what, _fail_on_call(call, getattr(os, what)))
    with pytest.raises(
        MapError, match=re.escape(f"{named}: cannot write map file: No space left")
    ) as err:
        save_map(tmp_path / "m", np.zeros((3, 3), np.int8), resolution=0.05)
    assert "\n" not in str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_failed_save_keeps_the_previous_map(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    old = save_map(tmp_path / "m", np.zeros((3, 3), np.int8), resolution=0.05)
    before = (old.image_path.read_bytes(), old.yaml_path.read_bytes())
    monkeypatch.setattr(map_io.os, "fsync", _fail_on_call(2, os.fsync))
    with pytest.raises(MapError):
        save_map(tmp_path / "m", np.full((4, 4), 100, np.int8), resolution=0.1)
    assert (old.image_path.read_bytes(), old.yaml_path.read_bytes()) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.pgm", "m.yaml"]


def test_save_into_missing_folder_or_onto_a_folder(tmp_path: Path) -> None:
    with pytest.raises(MapError, match=re.escape("no_such_dir/m.pgm: cannot write map file")):
        save_map(tmp_path / "no_such_dir" / "m", np.zeros((2, 2), np.int8), resolution=0.05)
    (tmp_path / "m.yaml").mkdir()
    with pytest.raises(MapError, match=re.escape("m.yaml")):
        save_map(tmp_path / "m", np.zeros((2, 2), np.int8), resolution=0.05)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.yaml"]


def test_bad_save_arguments(tmp_path: Path) -> None:
    with pytest.raises(MapError, match="resolution"):
        save_map(tmp_path / "m", np.zeros((2, 2), np.int8), resolution=0.0)
    with pytest.raises(MapError, match="2-D"):
        save_map(tmp_path / "m", np.zeros(4, np.int8), resolution=0.05)
    with pytest.raises(MapError, match="format"):
        save_map(tmp_path / "m", np.zeros((2, 2), np.int8), resolution=0.05, image_format="bmp")  # type: ignore[arg-type]
    assert list(tmp_path.iterdir()) == []
