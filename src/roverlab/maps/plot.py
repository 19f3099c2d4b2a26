"""Maps as pictures: an occupancy grid in map_saver's grey levels with a path drawn on it.

Pure (arrays in, a PNG file out). The PNG is written to a temporary file and renamed, so
an interrupted run never leaves half a picture.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw

__all__ = ["map_image", "write_map_png"]

_PAD_CELLS = 20


def map_image(
    data: NDArray[np.integer],
    resolution: float,
    origin: tuple[float, float],
    paths: Sequence[tuple[NDArray[np.floating], tuple[int, int, int]]] = (),
    *,
    crop: bool = True,
    min_size: int = 480,
) -> Image.Image:
    """The grid (free 254, occupied 0, unknown 205; top row = max y) as an RGB image, each
    ``(xy, colour)`` path drawn on it (``xy``: (N, >=2) map-frame metres). With ``crop``
    the picture keeps the known cells and the paths plus a margin; a small map is scaled
    up (whole pixels per cell) until its longer side has ``min_size`` pixels."""
    data = np.asarray(data)
    pts = [np.asarray(p, dtype=np.float64).reshape(-1, np.shape(p)[-1])[:, :2] for p, _ in paths]
    if crop:
        rows_k, cols_k = np.nonzero(data >= 0)
        h, w = data.shape
        cs = [cols_k] + [(p[:, 0] - origin[0]) / resolution for p in pts]
        rs = [rows_k] + [(p[:, 1] - origin[1]) / resolution for p in pts]
        c_all = np.concatenate([np.asarray(c, dtype=np.float64) for c in cs])
        r_all = np.concatenate([np.asarray(r, dtype=np.float64) for r in rs])
        if c_all.size:
            c0 = int(max(0, c_all.min() - _PAD_CELLS))
            c1 = int(min(w, c_all.max() + _PAD_CELLS + 1))
            r0 = int(max(0, r_all.min() - _PAD_CELLS))
            r1 = int(min(h, r_all.max() + _PAD_CELLS + 1))
            if c1 > c0 and r1 > r0:
                data = data[r0:r1, c0:c1]
                origin = (origin[0] + c0 * resolution, origin[1] + r0 * resolution)
    img = np.full(data.shape, 205, dtype=np.uint8)
    img[data == 0] = 254
    img[data == 100] = 0
    k = max(1, -(-min_size // max(data.shape)))  # pixels per cell
    img = np.repeat(np.repeat(img, k, axis=0), k, axis=1)
    rgb = Image.fromarray(np.flipud(img)).convert("RGB")
    draw = ImageDraw.Draw(rgb)
    h = data.shape[0]
    for p, (_, colour) in zip(pts, paths, strict=True):
        if len(p) < 2:
            continue
        cols = k * (p[:, 0] - origin[0]) / resolution
        rows = k * (h - (p[:, 1] - origin[1]) / resolution)
        draw.line(list(zip(cols.tolist(), rows.tolist(), strict=True)), fill=colour, width=2)
    return rgb


def write_map_png(
    path: Path,
    data: NDArray[np.integer],
    resolution: float,
    origin: tuple[float, float],
    poses: NDArray[np.floating] | None = None,
    *,
    colour: tuple[int, int, int] = (220, 30, 30),
) -> None:
    """Write :func:`map_image` of the grid with ``poses`` ((N, >=2) map-frame metres) as a
    line to ``path`` (temporary file, then rename)."""
    paths = [] if poses is None else [(poses, colour)]
    image = map_image(data, resolution, origin, paths)
    tmp = path.with_name(path.name + ".part")
    image.save(tmp, format="PNG")
    tmp.replace(path)
