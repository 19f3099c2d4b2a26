"""A map_server map (YAML + PGM/PNG) as a world: occupied pixels become walls.

The YAML is map_server's::

    image: map.pgm            # relative to the YAML file
    resolution: 0.05          # metres per pixel
    origin: [-10.0, -10.0, 0.0]   # pose (x, y, yaw) of the lower-left pixel's corner
    negate: 0
    occupied_thresh: 0.65
    free_thresh: 0.196
    mode: trinary             # trinary | scale | raw (optional)

A pixel is occupied as map_server decides it: with ``p = (255 - value) / 255`` (or
``value / 255`` when ``negate`` is 1; colour pixels use the mean of their channels),
occupied when ``p > occupied_thresh``; in ``raw`` mode when ``occupied_thresh * 100 <=
value <= 100``. Unknown and free pixels are empty space. Occupied pixels are merged into
as few boxes as the simple scheme allows (runs along each row, then identical runs of
consecutive rows into rectangles), each a wall ``wall_height`` metres high. The robot
spawns at (0, 0, 0) unless told otherwise.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image, UnidentifiedImageError

from roverlab.geometry import SE2
from roverlab.world.errors import WorldError
from roverlab.world.model import RGB, BoxShape, Shape, World
from roverlab.world.yaml_world import read_yaml

__all__ = [
    "MAP_YAML_KEYS",
    "is_map_yaml",
    "load_image_world",
    "occupied_mask",
    "occupied_rectangles",
]

MAP_YAML_KEYS = (
    "image",
    "resolution",
    "origin",
    "negate",
    "occupied_thresh",
    "free_thresh",
    "mode",
)
DEFAULT_WALL_HEIGHT = 2.0
DEFAULT_WALL_RGB: RGB = (178, 178, 178)


def is_map_yaml(data: Any) -> bool:
    """Is parsed YAML a map_server map description (it has ``image`` and ``resolution``)?"""
    return isinstance(data, Mapping) and "image" in data and "resolution" in data


def occupied_rectangles(mask: NDArray[np.bool_]) -> NDArray[np.int64]:
    """Cover the True cells of a 2-D mask with rectangles, without overlap.

    Runs of True cells along each row are found, then identical runs (same start and end
    column) in consecutive rows are merged.

    Returns:
        (N, 4) ``col0, row0, col1, row1`` with exclusive ends.
    """
    m = np.asarray(mask, dtype=bool)
    if m.ndim != 2:
        raise ValueError(f"mask must be 2-D, got shape {m.shape}")
    padded = np.zeros((m.shape[0], m.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = m
    d = np.diff(padded, axis=1)
    rows, starts = np.nonzero(d == 1)
    _, ends = np.nonzero(d == -1)
    if not len(rows):
        return np.zeros((0, 4), dtype=np.int64)
    order = np.lexsort((rows, ends, starts))
    r, a, b = rows[order], starts[order], ends[order]
    new = np.ones(len(r), dtype=bool)
    new[1:] = (a[1:] != a[:-1]) | (b[1:] != b[:-1]) | (r[1:] != r[:-1] + 1)
    first = np.flatnonzero(new)
    last = np.append(first[1:], len(r)) - 1
    return np.column_stack([a[first], r[first], b[first], r[last] + 1]).astype(np.int64)


def occupied_mask(
    image: Image.Image,
    *,
    negate: bool = False,
    occupied_thresh: float = 0.65,
    mode: str = "trinary",
) -> NDArray[np.bool_]:
    """Occupied pixels of a map image as map_server reads them (row 0 = top of image)."""
    if image.mode in ("L", "1", "P") and "transparency" not in image.info:
        value = np.asarray(image.convert("L"), dtype=np.float64)
        alpha = None
    elif image.mode == "LA":
        la = np.asarray(image, dtype=np.float64)
        value, alpha = la[..., 0], la[..., 1]
    elif image.mode.startswith("I"):
        arr = np.asarray(image, dtype=np.float64)
        top = 65535.0 if arr.max(initial=0) > 255 else 255.0
        value, alpha = arr * (255.0 / top), None
    else:
        has_alpha = "A" in image.getbands() or "transparency" in image.info
        rgba = np.asarray(image.convert("RGBA"), dtype=np.float64)
        value = rgba[..., :3].mean(axis=2)
        alpha = rgba[..., 3] if has_alpha else None
    if mode == "raw":
        result: NDArray[np.bool_] = (value >= occupied_thresh * 100.0) & (value <= 100.0)
        return result
    p = value / 255.0 if negate else (255.0 - value) / 255.0
    occupied = p > occupied_thresh
    if mode == "scale" and alpha is not None:
        occupied &= alpha > 0
    return occupied


def load_image_world(
    path: str | os.PathLike[str],
    *,
    wall_height: float = DEFAULT_WALL_HEIGHT,
    rgb: RGB = DEFAULT_WALL_RGB,
) -> World:
    """Load a map_server YAML (and its image) as a world of wall boxes.

    Args:
        path: the map YAML file.
        wall_height: height of the walls in metres.
        rgb: wall colour.

    Raises:
        WorldError: a missing or bad key, an unreadable image; one line naming the file.
    """
    p = Path(path)
    data = read_yaml(p)
    if not is_map_yaml(data):
        raise WorldError(f"{p}: not a map YAML: needs 'image' and 'resolution'")
    warnings = [f"{p}: unknown map key {k!r} ignored" for k in data if k not in MAP_YAML_KEYS]

    def number(key: str, default: float | None = None) -> float:
        v = data.get(key, default)
        if v is None:
            raise WorldError(f"{p}: {key}: missing")
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise WorldError(f"{p}: {key}: must be a finite number, got {v!r}")
        return float(v)

    resolution = number("resolution")
    if resolution <= 0.0:
        raise WorldError(f"{p}: resolution: must be positive, got {data['resolution']!r}")
    origin = data.get("origin")
    if (
        not isinstance(origin, list)
        or len(origin) != 3
        or not all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in origin
        )
    ):
        raise WorldError(f"{p}: origin: must be [x, y, yaw], got {origin!r}")
    ox, oy, oyaw = (float(v) for v in origin)
    negate = data.get("negate", 0)
    if negate not in (0, 1) or isinstance(negate, float):
        raise WorldError(f"{p}: negate: must be 0 or 1, got {negate!r}")
    occ = number("occupied_thresh", 0.65)
    number("free_thresh", 0.196)
    mode = data.get("mode", "trinary")
    if mode not in ("trinary", "scale", "raw"):
        raise WorldError(f"{p}: mode: must be trinary, scale or raw, got {mode!r}")
    image_name = data["image"]
    if not isinstance(image_name, str) or not image_name:
        raise WorldError(f"{p}: image: must name an image file, got {image_name!r}")
    image_path = Path(image_name)
    if not image_path.is_absolute():
        image_path = p.resolve().parent / image_path
    try:
        with Image.open(image_path) as im:
            mask = occupied_mask(im, negate=bool(negate), occupied_thresh=occ, mode=mode)
    except FileNotFoundError as err:
        raise WorldError(f"{p}: image: {image_path} not found") from err
    except (OSError, UnidentifiedImageError) as err:
        raise WorldError(f"{p}: image: cannot read {image_path}: {err}") from err
    rects = occupied_rectangles(mask[::-1])
    if not (wall_height > 0.0 and math.isfinite(wall_height)):
        raise WorldError(f"{p}: wall height must be positive, got {wall_height!r}")
    c, s = math.cos(oyaw), math.sin(oyaw)
    shapes: list[Shape] = []
    for c0, r0, c1, r1 in rects.tolist():
        lx = (c0 + c1) * 0.5 * resolution
        ly = (r0 + r1) * 0.5 * resolution
        shapes.append(
            BoxShape(
                pose=(
                    ox + c * lx - s * ly,
                    oy + s * lx + c * ly,
                    0.5 * wall_height,
                    0.0,
                    0.0,
                    oyaw,
                ),
                size=((c1 - c0) * resolution, (r1 - r0) * resolution, wall_height),
                rgb=rgb,
            )
        )
    return World(
        name=p.stem,
        shapes=tuple(shapes),
        spawn_poses=(SE2(),),
        source=p,
        warnings=tuple(warnings),
    )
