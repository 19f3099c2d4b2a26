"""image_transport's publisher side: the ``compressed`` topic a camera driver offers beside its
raw image (:class:`CompressedPublisher`), as an ``image_transport::Publisher`` does in ROS.

It is a library a driver's node uses (like tf's broadcaster), not a node of its own, so the
simulator's cameras and usb_cam use it without importing another domain's nodes.
Its parameters are the node's ``<topic>.compressed.format`` / ``.jpeg_quality`` /
``.png_level`` (ROS 2's image_transport names; ROS 1 keeps them under
``<topic>/compressed/``), e.g. ``camera.image_raw.compressed.jpeg_quality`` for
``/camera/image_raw``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from roverlab.core import Node
from roverlab.msgs import classes as mc
from roverlab.msgs import image_to_array
from roverlab.perception.image_transport.codec import CompressedParams, compress

__all__ = ["CompressedPublisher", "compressed_message", "compressed_params"]


def compressed_message(image: Any, params: CompressedParams) -> Any:
    """The CompressedImage of a ``sensor_msgs/Image`` (same header).

    Raises:
        ImageTransportError: an encoding the format cannot hold.
    """
    fmt, data = compress(image_to_array(image), str(image.encoding), params)
    return mc.CompressedImage(
        header=image.header, format=fmt, data=np.frombuffer(data, dtype=np.uint8)
    )


def compressed_params(node: Node, prefix: str) -> CompressedParams:
    p = node.declare_parameter
    return CompressedParams(
        format=str(p(f"{prefix}format", "jpeg").value),
        jpeg_quality=int(p(f"{prefix}jpeg_quality", 80).value),
        png_level=int(p(f"{prefix}png_level", 9).value),
    )


class CompressedPublisher:
    """``topic``/compressed beside a raw image topic of ``node``.

    Args:
        node: the camera driver's node.
        topic: the raw image's topic as the node names it (``~/image_raw``,
            ``/camera/image_raw``).
        depth: the publisher's queue depth.

    Raises:
        ImageTransportError: a bad format parameter.
    """

    def __init__(self, node: Node, topic: str, depth: int = 1) -> None:
        base = node.resolve_topic_name(topic)
        self.params = compressed_params(node, f"{base.strip('/').replace('/', '.')}.compressed.")
        self.publisher = node.create_publisher(mc.CompressedImage, f"{base}/compressed", depth)

    @property
    def has_listeners(self) -> bool:
        return self.publisher.has_listeners

    def publish(self, image: Any) -> None:
        """Compress and publish ``image`` if anyone subscribes (else nothing is done)."""
        if self.publisher.has_listeners:
            self.publisher.publish(compressed_message(image, self.params))
