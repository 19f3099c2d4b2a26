"""image_transport's ``compressed`` plugin (compressed_image_transport), pure: an image
array to JPEG or PNG bytes and the ``format`` string ROS writes, and back.

As compressed_image_transport: ``format`` ``jpeg`` (8-bit images; colour is stored as the
JPEG's colours, written ``"<encoding>; jpeg compressed bgr8"``, ``mono8`` as
``"mono8; jpeg compressed mono8"``) or ``png`` (8- or 16-bit, ``"<encoding>; png compressed
bgr8"``); ``jpeg_quality`` 1..100 (80), ``png_level`` 1..9 (9). Other transports are
refused by name (``theora``: not provided).
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from roverlab.perception.errors import PerceptionError

__all__ = [
    "TRANSPORTS",
    "CompressedParams",
    "ImageTransportError",
    "check_transport",
    "compress",
    "decompress",
]

TRANSPORTS: Final = ("raw", "compressed")
"""The transports roverlab provides (image_transport's ``raw`` and ``compressed``)."""
_COLOUR: Final = ("rgb8", "bgr8", "rgba8", "bgra8")
_COLOUR16: Final = ("rgb16", "bgr16", "rgba16", "bgra16")


class ImageTransportError(PerceptionError):
    """A transport roverlab does not provide, a bad parameter, or an image a format
    cannot hold."""


def check_transport(name: str) -> str:
    """``name`` if it is a transport roverlab provides.

    Raises:
        ImageTransportError: e.g. ``theora`` (one line saying what is provided).
    """
    if name not in TRANSPORTS:
        raise ImageTransportError(
            f"image transport {name!r} is not provided (theora is not implemented); "
            f"use one of {', '.join(TRANSPORTS)}"
        )
    return name


@dataclass(frozen=True)
class CompressedParams:
    """compressed_image_transport's parameters, validated.

    Raises:
        ImageTransportError: a format other than jpeg/png, or a value out of range.
    """

    format: str = "jpeg"
    jpeg_quality: int = 80
    png_level: int = 9

    def __post_init__(self) -> None:
        if self.format not in ("jpeg", "png"):
            raise ImageTransportError(f"format must be jpeg or png, got {self.format!r}")
        if not 1 <= self.jpeg_quality <= 100:
            raise ImageTransportError(f"jpeg_quality must be 1..100, got {self.jpeg_quality}")
        if not 1 <= self.png_level <= 9:
            raise ImageTransportError(f"png_level must be 1..9, got {self.png_level}")


def _channels_to_rgb(pixels: NDArray[Any], encoding: str) -> NDArray[Any]:
    if encoding.startswith("bgr"):
        order = [2, 1, 0, 3] if pixels.shape[-1] == 4 else [2, 1, 0]
        return pixels[..., order]
    return pixels


def compress(pixels: NDArray[Any], encoding: str, params: CompressedParams) -> tuple[str, bytes]:
    """The CompressedImage ``format`` string and bytes of an image.

    Raises:
        ImageTransportError: an encoding the format cannot hold (JPEG: 8-bit colour or
            mono8; PNG: 8/16-bit colour or mono).
    """
    arr = np.ascontiguousarray(pixels)
    mono = encoding in ("mono8", "8UC1") or (encoding in ("mono16", "16UC1") and arr.ndim == 2)
    if params.format == "jpeg":
        if encoding not in (*_COLOUR, "mono8", "8UC1"):
            raise ImageTransportError(
                f"JPEG compression needs an 8-bit colour or mono8 image, not {encoding}"
            )
        target = "mono8" if mono else "bgr8"
        rgb = arr if mono else _channels_to_rgb(arr, encoding)[..., :3]
        buf = io.BytesIO()
        Image.fromarray(rgb).save(buf, format="JPEG", quality=params.jpeg_quality)
        return f"{encoding}; jpeg compressed {target}", buf.getvalue()
    if encoding not in (*_COLOUR, *_COLOUR16, "mono8", "8UC1", "mono16", "16UC1"):
        raise ImageTransportError(f"PNG compression needs a colour or mono image, not {encoding}")
    if mono:
        target = "mono16" if arr.dtype == np.uint16 else "mono8"
        img = Image.fromarray(arr.astype(np.uint16) if target == "mono16" else arr)
    else:
        rgb = _channels_to_rgb(arr, encoding)[..., :3]
        if rgb.dtype == np.uint16:  # Pillow writes 8-bit colour: keep the high bytes
            rgb = (rgb >> 8).astype(np.uint8)
        target = "bgr8"
        img = Image.fromarray(rgb)
    buf = io.BytesIO()
    img.save(buf, format="PNG", compress_level=params.png_level)
    return f"{encoding}; png compressed {target}", buf.getvalue()


def decompress(fmt: str, data: bytes) -> tuple[NDArray[Any], str]:
    """The pixels and encoding of a CompressedImage (``format`` as above, or a bare
    ``jpeg``/``png``): colour as ``rgb8`` or ``bgr8`` (the original encoding's order),
    grey as ``mono8``/``mono16``.

    Raises:
        ImageTransportError: bytes that are not an image.
    """
    try:
        img = Image.open(io.BytesIO(data))
        img.load()
    except (OSError, ValueError) as err:
        raise ImageTransportError(f"cannot decode the compressed image ({fmt!r}): {err}") from err
    original = fmt.split(";", 1)[0].strip() if ";" in fmt else ""
    if img.mode in ("L", "I;16", "I"):
        arr = np.asarray(img)
        if arr.dtype != np.uint8:
            return arr.astype(np.uint16), "mono16"
        return arr, "mono8"
    rgb = np.asarray(img.convert("RGB"))
    if original.startswith("bgr"):
        return np.ascontiguousarray(rgb[..., ::-1]), "bgr8"
    return rgb, "rgb8"
