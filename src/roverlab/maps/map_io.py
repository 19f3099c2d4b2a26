"""map_server map files: the YAML + image pair, read and written the way ROS 1 does.

Reading follows ``map_server``'s ``main.cpp`` and ``image_loader.cpp``:

* YAML keys ``image``, ``resolution``, ``origin: [x, y, yaw]``, ``negate``,
  ``occupied_thresh``, ``free_thresh`` (all required) and ``mode`` (``trinary``, the
  default, ``scale`` or ``raw``); a relative ``image`` is relative to the YAML's folder;
  other keys are ignored.
* Each pixel's channels are averaged (``avg``); the alpha channel takes part in the
  average in trinary mode and is left out otherwise; ``negate`` turns ``avg`` into
  ``255 - avg``. ``raw`` stores ``avg`` truncated to a byte (so 255 reads back as -1).
  Otherwise ``p = (255 - avg) / 255``: ``p > occupied_thresh`` -> 100,
  ``p < free_thresh`` -> 0, else -1 (trinary, or a fully transparent pixel in scale mode)
  or ``1 + 98 * (p - free_thresh) / (occupied_thresh - free_thresh)`` truncated (scale).
* The image's top row is the map's last row (largest y): rows are flipped into
  ``OccupancyGrid`` order.
* Channel layout as SDL_image gives it to map_server: grey and palette images have one
  channel (a palette image's *indices* are its values, as in ROS), 16-bit grey keeps its
  high byte, grey+alpha becomes RGBA, and in an RGB image without alpha the blue channel
  plays the part of alpha (a ROS quirk that only matters in scale mode).

Writing follows ``map_saver``: cells ``0 <= v <= threshold_free`` -> 254 (white),
``v >= threshold_occupied`` -> 0 (black), anything else -> 205 (grey); a binary PGM with the
header ``P5\\n# CREATOR: map_saver.cpp 0.050 m/pix\\nW H\\n255\\n`` and the YAML text
``image: NAME.pgm\\nresolution: 0.050000\\norigin: [x, y, yaw]\\nnegate: 0\\n
occupied_thresh: 0.65\\nfree_thresh: 0.196\\n\\n`` (``%f`` numbers). One difference:
``image`` names the file without its folder, so the pair can be moved and always loads
(ROS 1 writes the ``-f`` path as given, which breaks for a relative path with folders).
Both files are written to temporary files in the target folder and renamed into place,
so a failed save leaves nothing behind.

Every problem is a :class:`~roverlab.maps.errors.MapError` whose one-line message names
the file.
"""

from __future__ import annotations

import contextlib
import math
import os
import secrets
from dataclasses import dataclass
from enum import StrEnum
from io import BytesIO
from pathlib import Path
from typing import Any, Literal, NamedTuple

import numpy as np
import yaml
from numpy.typing import ArrayLike, NDArray
from PIL import Image, UnidentifiedImageError

from roverlab.maps.errors import MapError
from roverlab.msgs import array_to_occupancy_grid, occupancy_grid_to_array
from roverlab.msgs import classes as mc

ImageFormat = Literal["pgm", "png"]

#: Pixel values map_saver writes.
FREE_PIXEL = 254
OCCUPIED_PIXEL = 0
UNKNOWN_PIXEL = 205


class MapMode(StrEnum):
    """How pixel values become cell values (map_server's ``mode``)."""

    TRINARY = "trinary"
    SCALE = "scale"
    RAW = "raw"


def _one_line(text: object) -> str:
    return " ".join(str(text).split())


@dataclass(frozen=True, slots=True)
class MapInfo:
    """The settings of a map YAML file, validated.

    Attributes:
        image: the image file (relative paths resolved against the YAML's folder).
        resolution: cell side, m.
        origin: ``(x, y, yaw)`` of the lower-left pixel's outer corner in the map frame.
        negate: white means occupied and black free.
        occupied_thresh: cells with occupancy probability above this are occupied.
        free_thresh: cells with occupancy probability below this are free.
        mode: how pixels become cells (:class:`MapMode`).

    Raises:
        MapError: a non-positive resolution, a non-finite origin or thresholds outside
            ``0 <= free_thresh <= occupied_thresh <= 1``.
    """

    image: Path
    resolution: float
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    mode: MapMode = MapMode.TRINARY

    def __post_init__(self) -> None:
        if not (math.isfinite(self.resolution) and self.resolution > 0):
            raise MapError(f"resolution must be a positive number, got {self.resolution}")
        if len(self.origin) != 3 or not all(math.isfinite(v) for v in self.origin):
            raise MapError(f"origin must be three finite numbers [x, y, yaw], got {self.origin}")
        if not (0.0 <= self.free_thresh <= self.occupied_thresh <= 1.0):
            raise MapError(
                "thresholds must satisfy 0 <= free_thresh <= occupied_thresh <= 1, got "
                f"free_thresh {self.free_thresh} and occupied_thresh {self.occupied_thresh}"
            )


class CellCounts(NamedTuple):
    """How many cells of a map are free (0), occupied (100), unknown (-1) or other."""

    free: int
    occupied: int
    unknown: int
    other: int


class GridShape:
    """``width`` and ``height`` (cells) of a class whose ``data`` is a ``(height, width)``
    array, row 0 at the origin (``OccupancyGrid`` order)."""

    __slots__ = ()
    data: NDArray[Any]

    @property
    def width(self) -> int:
        return int(self.data.shape[1])

    @property
    def height(self) -> int:
        return int(self.data.shape[0])


@dataclass(frozen=True, slots=True)
class OccupancyMap(GridShape):
    """A loaded map: its settings and its cells.

    Attributes:
        info: the YAML settings.
        data: ``(height, width)`` int8 cells, row 0 at the origin (``OccupancyGrid`` order).
    """

    info: MapInfo
    data: NDArray[np.int8]

    def counts(self) -> CellCounts:
        return cell_counts(self.data)

    def to_msg(self, *, frame_id: str = "map", stamp: Any = None) -> mc.OccupancyGrid:
        """The map as a ``nav_msgs/OccupancyGrid`` (``map_load_time`` = ``stamp``)."""
        return array_to_occupancy_grid(
            self.data,
            resolution=self.info.resolution,
            origin=self.info.origin,
            frame_id=frame_id,
            stamp=stamp,
        )


@dataclass(frozen=True, slots=True)
class SavedMap:
    """The files :func:`save_map` wrote."""

    image_path: Path
    yaml_path: Path


def cell_counts(data: ArrayLike) -> CellCounts:
    """Free / occupied / unknown / other cell counts of an occupancy array."""
    cells = np.asarray(data)
    free = int(np.count_nonzero(cells == 0))
    occupied = int(np.count_nonzero(cells == 100))
    unknown = int(np.count_nonzero(cells == -1))
    return CellCounts(free, occupied, unknown, int(cells.size) - free - occupied - unknown)


# ----------------------------------------------------------------------------- reading
def _number(path: Path, key: str, value: object) -> float:
    if isinstance(value, bool) or value is None:
        raise MapError(f"{path}: '{key}' must be a number, got {value!r}")
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise MapError(f"{path}: '{key}' must be a number, got {value!r}") from None
    if not math.isfinite(out):
        raise MapError(f"{path}: '{key}' must be finite, got {value!r}")
    return out


def _negate(path: Path, value: object) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, int):
        return value != 0
    if isinstance(value, str):
        with contextlib.suppress(ValueError):
            return int(value.strip()) != 0
    raise MapError(f"{path}: 'negate' must be 0 or 1, got {value!r}")


def read_map_yaml(path: str | os.PathLike[str]) -> MapInfo:
    """The settings of a map_server YAML file.

    Raises:
        MapError: the file is missing or unreadable, not YAML, not a mapping, lacks a
            required key, or holds a bad value.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MapError(f"{p}: map file not found") from None
    except (OSError, UnicodeDecodeError) as err:
        raise MapError(f"{p}: cannot read map file: {_one_line(err)}") from err
    try:
        doc = yaml.safe_load(text)
    except yaml.YAMLError as err:
        raise MapError(f"{p}: malformed YAML: {_one_line(err)}") from err
    if not isinstance(doc, dict):
        raise MapError(f"{p}: expected a YAML mapping of map settings")
    for key in ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"):
        if key not in doc:
            raise MapError(f"{p}: missing key '{key}'")
    image = doc["image"]
    if not isinstance(image, str) or not image.strip():
        raise MapError(f"{p}: 'image' must be a non-empty file name, got {image!r}")
    origin = doc["origin"]
    if not isinstance(origin, list | tuple) or len(origin) != 3:
        raise MapError(f"{p}: 'origin' must be a list [x, y, yaw], got {origin!r}")
    mode_text = doc.get("mode", MapMode.TRINARY.value)
    try:
        mode = MapMode(str(mode_text).strip())
    except ValueError:
        raise MapError(f"{p}: invalid mode {mode_text!r} (use trinary, scale or raw)") from None
    image_path = Path(image)
    if not image_path.is_absolute():
        image_path = p.parent / image_path
    try:
        return MapInfo(
            image=image_path,
            resolution=_number(p, "resolution", doc["resolution"]),
            origin=(
                _number(p, "origin[0]", origin[0]),
                _number(p, "origin[1]", origin[1]),
                _number(p, "origin[2]", origin[2]),
            ),
            negate=_negate(p, doc["negate"]),
            occupied_thresh=_number(p, "occupied_thresh", doc["occupied_thresh"]),
            free_thresh=_number(p, "free_thresh", doc["free_thresh"]),
            mode=mode,
        )
    except MapError as err:
        if str(err).startswith(f"{p}:"):
            raise
        raise MapError(f"{p}: {err}") from err


def _palette_is_translucent(img: Image.Image) -> bool:
    """Whether SDL_image expands a palette PNG to RGBA: more than one transparent index,
    or a partly transparent one (a single transparent index stays a colour key)."""
    trns = img.info.get("transparency")
    if not isinstance(trns, bytes):
        return False
    return sum(1 for a in trns if a == 0) > 1 or any(0 < a < 255 for a in trns)


def read_image_pixels(path: str | os.PathLike[str]) -> tuple[NDArray[np.uint8], bool]:
    """The pixels of a map image as SDL_image hands them to map_server.

    Returns:
        ``(pixels, has_alpha)``: ``(H, W, C)`` uint8 channels, top row first, and whether
        the last channel is an alpha channel (SDL's ``Amask``).

    Raises:
        MapError: a missing or unreadable image.
    """
    p = Path(path)
    try:
        with Image.open(p) as img:
            img.load()
            return _pixels(img)
    except FileNotFoundError:
        raise MapError(f"{p}: image file not found") from None
    except (UnidentifiedImageError, Image.DecompressionBombError) as err:
        raise MapError(f"{p}: cannot read image: {_one_line(err)}") from err
    except (OSError, ValueError, SyntaxError) as err:
        raise MapError(f"{p}: cannot read image: {_one_line(err)}") from err


def _pixels(img: Image.Image) -> tuple[NDArray[np.uint8], bool]:
    mode = img.mode
    if mode in ("L", "P") and not (mode == "P" and _palette_is_translucent(img)):
        return np.asarray(img, dtype=np.uint8)[:, :, None], False
    if mode == "P":  # expanded by libpng with no alpha mask: 4 channels averaged
        return np.asarray(img.convert("RGBA"), dtype=np.uint8), False
    if mode == "1":
        return np.asarray(img.convert("L"), dtype=np.uint8)[:, :, None], False
    if mode.startswith("I"):  # 16-bit grey: libpng's strip_16 keeps the high byte
        wide = np.clip(np.asarray(img, dtype=np.int64), 0, 65535)
        return (wide >> 8).astype(np.uint8)[:, :, None], False
    if mode == "RGB":
        return np.asarray(img, dtype=np.uint8), False
    if mode == "RGBA":
        return np.asarray(img, dtype=np.uint8), True
    if mode == "LA":  # png_set_gray_to_rgb: grey + alpha becomes RGBA
        la = np.asarray(img, dtype=np.uint8)
        grey, alpha = la[:, :, 0], la[:, :, 1]
        return np.stack([grey, grey, grey, alpha], axis=2), True
    if "A" in img.getbands() or mode in ("PA", "RGBa", "La"):
        return np.asarray(img.convert("RGBA"), dtype=np.uint8), True
    if mode == "F":
        return np.clip(np.asarray(img), 0, 255).astype(np.uint8)[:, :, None], False
    return np.asarray(img.convert("RGB"), dtype=np.uint8), False


def image_to_occupancy(
    pixels: ArrayLike,
    *,
    has_alpha: bool = False,
    negate: bool = False,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    mode: MapMode | str = MapMode.TRINARY,
) -> NDArray[np.int8]:
    """map_server's pixel -> cell rule over a whole image.

    Args:
        pixels: ``(H, W)`` or ``(H, W, C)`` uint8 image, top row first.
        has_alpha: the last channel is alpha (SDL's ``Amask``).
        negate, occupied_thresh, free_thresh, mode: as in the YAML file.

    Returns:
        ``(H, W)`` int8 cells in ``OccupancyGrid`` order (row 0 = the image's bottom row).

    Raises:
        MapError: a bad pixel array or mode.
    """
    px = np.asarray(pixels)
    if px.ndim == 2:
        px = px[:, :, None]
    if px.ndim != 3 or px.shape[2] < 1 or px.dtype != np.uint8:
        raise MapError(f"expected an (H, W[, C]) uint8 image, got {px.dtype} {px.shape}")
    try:
        mmode = MapMode(mode)
    except ValueError:
        raise MapError(f"invalid mode {mode!r} (use trinary, scale or raw)") from None
    n_channels = px.shape[2]
    avg_channels = n_channels if (mmode is MapMode.TRINARY or not has_alpha) else n_channels - 1
    color_sum = px[:, :, :avg_channels].sum(axis=2, dtype=np.int64)
    color_avg = color_sum / float(avg_channels)
    if negate:
        color_avg = 255.0 - color_avg
    if mmode is MapMode.RAW:
        out = color_avg.astype(np.uint8).view(np.int8)
        return np.ascontiguousarray(out[::-1])
    occ = (255.0 - color_avg) / 255.0
    out = np.full(occ.shape, -1, dtype=np.int8)
    if mmode is MapMode.SCALE:
        alpha = (
            np.ones(occ.shape, dtype=np.int64)
            if n_channels == 1
            else px[:, :, n_channels - 1].astype(np.int64)
        )
        span = occupied_thresh - free_thresh
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.nan_to_num((occ - free_thresh) / span, nan=0.0, posinf=1.0, neginf=0.0)
        scaled = (1.0 + 98.0 * np.clip(ratio, 0.0, 1.0)).astype(np.uint8).view(np.int8)
        middle = alpha >= 1
        out[middle] = scaled[middle]
    out[occ < free_thresh] = 0
    out[occ > occupied_thresh] = 100
    return np.ascontiguousarray(out[::-1])


def load_map(path: str | os.PathLike[str]) -> OccupancyMap:
    """Load a map as ``map_server NAME.yaml`` does.

    Raises:
        MapError: a bad YAML file or a missing or unreadable image.
    """
    info = read_map_yaml(path)
    try:
        pixels, has_alpha = read_image_pixels(info.image)
        if pixels.shape[0] == 0 or pixels.shape[1] == 0:
            raise MapError(f"{info.image}: empty image")
    except MapError as err:  # name the YAML file that points at the image too
        raise MapError(f"{path}: image {err}") from err
    data = image_to_occupancy(
        pixels,
        has_alpha=has_alpha,
        negate=info.negate,
        occupied_thresh=info.occupied_thresh,
        free_thresh=info.free_thresh,
        mode=info.mode,
    )
    return OccupancyMap(info=info, data=data)


# ----------------------------------------------------------------------------- writing
def check_save_thresholds(threshold_occupied: int, threshold_free: int) -> None:
    """map_saver's checks of ``--occ`` and ``--free``.

    Raises:
        MapError: ``threshold_occupied`` outside 1..100, ``threshold_free`` outside 0..100,
            or ``threshold_free >= threshold_occupied``.
    """
    for name, value in (
        ("threshold_occupied", threshold_occupied),
        ("threshold_free", threshold_free),
    ):
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise MapError(f"{name} must be an integer, got {value!r}")
    if not 1 <= threshold_occupied <= 100:
        raise MapError(f"threshold_occupied must be between 1 and 100, got {threshold_occupied}")
    if not 0 <= threshold_free <= 100:
        raise MapError(f"threshold_free must be between 0 and 100, got {threshold_free}")
    if threshold_occupied <= threshold_free:
        raise MapError(
            f"threshold_free ({threshold_free}) must be smaller than threshold_occupied "
            f"({threshold_occupied})"
        )


def occupancy_to_image(
    data: ArrayLike, *, threshold_occupied: int = 65, threshold_free: int = 25
) -> NDArray[np.uint8]:
    """map_saver's cell -> pixel rule: ``(H, W)`` uint8, top row = the map's last row.

    Raises:
        MapError: bad thresholds or a non 2-D array.
    """
    check_save_thresholds(threshold_occupied, threshold_free)
    cells = np.asarray(data)
    if cells.ndim != 2:
        raise MapError(f"expected a 2-D occupancy array, got shape {cells.shape}")
    cells = cells.astype(np.int16)
    free = (cells >= 0) & (cells <= threshold_free)
    occupied = ~free & (cells >= threshold_occupied)
    out = np.full(cells.shape, UNKNOWN_PIXEL, dtype=np.uint8)
    out[free] = FREE_PIXEL
    out[occupied] = OCCUPIED_PIXEL
    return np.ascontiguousarray(out[::-1])


def pgm_bytes(pixels: ArrayLike, resolution: float) -> bytes:
    """A binary PGM exactly as map_saver writes it (``# CREATOR`` comment included)."""
    px = np.ascontiguousarray(pixels, dtype=np.uint8)
    if px.ndim != 2:
        raise MapError(f"expected a 2-D image, got shape {px.shape}")
    h, w = px.shape
    header = f"P5\n# CREATOR: map_saver.cpp {resolution:.3f} m/pix\n{w} {h}\n255\n"
    return header.encode("ascii") + px.tobytes()


def _yaml_scalar(text: str) -> str:
    """``text`` as map_saver prints it, quoted only when YAML would misread it."""
    try:
        if yaml.safe_load(f"image: {text}") == {"image": text}:
            return text
    except yaml.YAMLError:
        pass
    return yaml.safe_dump(text, default_style='"').strip().removesuffix("\n...")


def format_map_yaml(
    image: str,
    *,
    resolution: float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    negate: bool = False,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    mode: MapMode | str = MapMode.TRINARY,
) -> str:
    """map_saver's YAML text; with the defaults it is byte for byte map_saver's output.

    A ``mode`` line is added only for scale and raw maps (map_saver writes none).
    """
    x, y, yaw = origin
    text = (
        f"image: {_yaml_scalar(image)}\n"
        f"resolution: {resolution:f}\n"
        f"origin: [{x:f}, {y:f}, {yaw:f}]\n"
        f"negate: {int(bool(negate))}\n"
        f"occupied_thresh: {float(occupied_thresh)!r}\n"
        f"free_thresh: {float(free_thresh)!r}\n"
    )
    if MapMode(mode) is not MapMode.TRINARY:
        text += f"mode: {MapMode(mode).value}\n"
    return text + "\n"


def _write_atomically(files: list[tuple[Path, bytes]]) -> None:
    """Write every file to a temporary sibling, then rename them all into place.

    Raises:
        MapError: naming the file that could not be written; no file is left behind
            (neither a temporary one nor a half-written target).
    """
    for target, _ in files:
        if target.is_dir():
            raise MapError(f"{target}: cannot write map file: it is a folder")
    temps: list[tuple[Path, Path]] = []
    current = files[0][0]
    try:
        for target, payload in files:
            current = target
            tmp = target.with_name(f".{target.name}.{secrets.token_hex(4)}.tmp")
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
            temps.append((tmp, target))
            with os.fdopen(fd, "wb") as fh:
                fh.write(payload)
                fh.flush()
                os.fsync(fh.fileno())
        for tmp, target in temps:
            current = target
            os.replace(tmp, target)
    except BaseException as err:
        for tmp, _ in temps:
            with contextlib.suppress(OSError):
                tmp.unlink()
        if isinstance(err, OSError):
            reason = err.strerror or _one_line(err)
            raise MapError(f"{current}: cannot write map file: {reason}") from err
        raise


def save_map(
    path_prefix: str | os.PathLike[str],
    data: ArrayLike,
    *,
    resolution: float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    threshold_occupied: int = 65,
    threshold_free: int = 25,
    image_format: ImageFormat = "pgm",
) -> SavedMap:
    """Write ``PREFIX.pgm`` (or ``.png``) and ``PREFIX.yaml`` as ``map_saver -f PREFIX``.

    Args:
        path_prefix: file name without extension (``-f``); the extensions are appended.
        data: ``(height, width)`` occupancy cells, row 0 at the origin.
        resolution: cell side, m.
        origin: ``(x, y, yaw)`` of cell ``[0, 0]``'s outer corner.
        threshold_occupied: cells ``>=`` this are occupied (``--occ``, 1..100).
        threshold_free: cells ``0..`` this are free (``--free``, 0..100).
        image_format: ``pgm`` (map_saver) or ``png`` (8-bit grey).

    Raises:
        MapError: bad arguments, or the files cannot be written (nothing is left behind).
    """
    if not (math.isfinite(resolution) and resolution > 0):
        raise MapError(f"resolution must be a positive number, got {resolution}")
    if len(origin) != 3 or not all(math.isfinite(float(v)) for v in origin):
        raise MapError(f"origin must be three finite numbers, got {origin}")
    if image_format not in ("pgm", "png"):
        raise MapError(f"image format must be pgm or png, got {image_format!r}")
    pixels = occupancy_to_image(
        data, threshold_occupied=threshold_occupied, threshold_free=threshold_free
    )
    prefix = os.fspath(path_prefix)
    if not prefix or prefix.endswith(("/", os.sep)):
        raise MapError(f"map name {prefix!r} names a folder, not a file")
    image_path = Path(prefix + "." + image_format)
    yaml_path = Path(prefix + ".yaml")
    if image_format == "pgm":
        image_bytes = pgm_bytes(pixels, resolution)
    else:
        buf = BytesIO()
        Image.fromarray(pixels, mode="L").save(buf, format="PNG")
        image_bytes = buf.getvalue()
    text = format_map_yaml(
        image_path.name,
        resolution=resolution,
        origin=(float(origin[0]), float(origin[1]), float(origin[2])),
    )
    _write_atomically([(image_path, image_bytes), (yaml_path, text.encode("utf-8"))])
    return SavedMap(image_path=image_path, yaml_path=yaml_path)


def yaw_of_quaternion(q: Any) -> float:
    """Yaw of a ``geometry_msgs/Quaternion`` as tf2's ``Matrix3x3::getEulerYPR`` gives it
    (any non-zero length; the zero quaternion gives 0)."""
    x, y, z, w = float(q.x), float(q.y), float(q.z), float(q.w)
    return math.atan2(2.0 * (x * y + w * z), w * w + x * x - y * y - z * z)


def save_occupancy_grid(
    path_prefix: str | os.PathLike[str],
    grid: Any,
    *,
    threshold_occupied: int = 65,
    threshold_free: int = 25,
    image_format: ImageFormat = "pgm",
) -> SavedMap:
    """:func:`save_map` of a ``nav_msgs/OccupancyGrid`` message (what map_saver does)."""
    origin = grid.info.origin
    return save_map(
        path_prefix,
        occupancy_grid_to_array(grid),
        resolution=float(grid.info.resolution),
        origin=(
            float(origin.position.x),
            float(origin.position.y),
            yaw_of_quaternion(origin.orientation),
        ),
        threshold_occupied=threshold_occupied,
        threshold_free=threshold_free,
        image_format=image_format,
    )
