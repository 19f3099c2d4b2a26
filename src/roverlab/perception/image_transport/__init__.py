"""image_transport's ``compressed`` transport: JPEG/PNG ``sensor_msgs/CompressedImage`` on
``<base topic>/compressed`` beside a raw ``Image`` (:mod:`.codec`, pure), the publisher a
camera driver offers it with and the ``republish`` node (:mod:`.node`).
"""

from __future__ import annotations

from roverlab.perception.image_transport.codec import (
    TRANSPORTS,
    CompressedParams,
    ImageTransportError,
    check_transport,
    compress,
    decompress,
)

__all__ = [
    "TRANSPORTS",
    "CompressedParams",
    "ImageTransportError",
    "check_transport",
    "compress",
    "decompress",
]
