"""cv_bridge for ROS 1 scripts: ``CvBridge`` between ``sensor_msgs/Image`` and numpy arrays.

OpenCV images are numpy arrays, so no OpenCV is needed: ``imgmsg_to_cv2(msg,
desired_encoding)`` returns the ``(h, w[, c])`` array OpenCV would get, converting between
the common encodings as cv_bridge does (``bgr8``, ``rgb8``, ``bgra8``, ``rgba8``,
``mono8``, ``mono16``, ``8UC1``/``8UC3``, ``16UC1``, ``32FC1``; ``passthrough`` keeps the
message's); ``cv2_to_imgmsg(array, encoding)`` builds the message. Colour to ``mono8``
uses OpenCV's weights (0.299 R + 0.587 G + 0.114 B). Problems raise :class:`CvBridgeError`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.errors import RoverlabError
from roverlab.msgs import array_to_image, image_to_array

__all__ = ["CvBridge", "CvBridgeError"]

_ALIASES = {"8UC1": "mono8", "8UC3": "bgr8", "8UC4": "bgra8", "16UC1": "mono16"}
_ORDER = {"rgb8": "RGB", "bgr8": "BGR", "rgba8": "RGBA", "bgra8": "BGRA", "mono8": "L"}


class CvBridgeError(RoverlabError):
    """An image that cannot be converted to or from the requested encoding."""


def _convert(arr: NDArray[Any], src: str, dst: str) -> NDArray[Any]:
    src, dst = _ALIASES.get(src, src), _ALIASES.get(dst, dst)
    if src == dst:
        return arr
    if src in _ORDER and dst in _ORDER:
        so, do = _ORDER[src], _ORDER[dst]
        if so == "L":
            rgb = np.repeat(arr.reshape(arr.shape[0], arr.shape[1], 1), 3, axis=2)
        else:
            rgb = arr[..., [so.index(c) for c in "RGB"]]
        if do == "L":
            grey = rgb.astype(np.float64) @ np.array([0.299, 0.587, 0.114])
            return np.clip(np.rint(grey), 0, 255).astype(np.uint8)
        out = rgb[..., ["RGB".index(c) for c in do if c != "A"]]
        if "A" in do:
            alpha = arr[..., so.index("A")] if "A" in so else np.full(arr.shape[:2], 255, np.uint8)
            out = np.dstack([out, alpha])
        return np.ascontiguousarray(out.astype(np.uint8))
    if src == "mono16" and dst == "mono8":
        return (arr >> 8).astype(np.uint8)
    if src == "mono8" and dst == "mono16":
        return arr.astype(np.uint16) << 8
    raise CvBridgeError(f"cannot convert an image from {src} to {dst}")


class CvBridge:
    """ROS 1 ``cv_bridge.CvBridge``."""

    def imgmsg_to_cv2(self, img_msg: Any, desired_encoding: str = "passthrough") -> NDArray[Any]:
        try:
            arr = image_to_array(img_msg)
        except RoverlabError as err:
            raise CvBridgeError(str(err)) from err
        if desired_encoding == "passthrough":
            return arr
        return _convert(arr, str(img_msg.encoding), desired_encoding)

    def cv2_to_imgmsg(self, cvim: Any, encoding: str = "passthrough", header: Any = None) -> Any:
        arr = np.asarray(cvim)
        if encoding == "passthrough":
            kinds = {
                (np.dtype(np.uint8), 2): "mono8",
                (np.dtype(np.uint8), 3): "bgr8",
                (np.dtype(np.uint16), 2): "mono16",
                (np.dtype(np.float32), 2): "32FC1",
            }
            found = kinds.get((arr.dtype, arr.ndim))
            if found is None:
                raise CvBridgeError(f"no encoding for a {arr.dtype} array of shape {arr.shape}")
            encoding = found
        try:
            msg = array_to_image(arr, _ALIASES.get(encoding, encoding))
        except RoverlabError as err:
            raise CvBridgeError(str(err)) from err
        if encoding in _ALIASES:
            msg.encoding = encoding
        if header is not None:
            msg.header = header
        return msg
