"""Frame sources for usb_cam's ``video_device``: a V4L2 camera, a video file, an image
file or a folder of images (replay and tests).

Frames come out as RGB ``uint8`` arrays ``(height, width, 3)``, or ``(height, width)``
for ``pixel_format: grey`` (usb_cam publishes ``rgb8`` and ``mono8``).
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Final, Protocol

import cv2
import numpy as np
from numpy.typing import NDArray

from roverlab.drivers.errors import DeviceError, DriverError

__all__ = ["IMAGE_SUFFIXES", "IO_METHODS", "PIXEL_FORMATS", "FrameSource", "open_source"]

PIXEL_FORMATS: Final = {
    "mjpeg": "MJPG",
    "yuyv": "YUYV",
    "uyvy": "UYVY",
    "rgb24": "RGB3",
    "grey": "GREY",
    "yuvmono10": "Y10 ",
}
"""usb_cam's ``pixel_format`` values and the V4L2 FourCC asked of the camera."""
IO_METHODS: Final = ("mmap", "read", "userptr")
"""usb_cam's ``io_method`` values (OpenCV's V4L2 backend always uses mmap)."""
IMAGE_SUFFIXES: Final = (".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff")
_DEVICE_FAILURES: Final = 30  # consecutive failed grabs before the device counts as lost

Frame = NDArray[np.uint8]


class FrameSource(Protocol):
    """Where frames come from."""

    description: str

    def read(self) -> Frame | None:
        """The next frame, or None when none is ready yet.

        Raises:
            DeviceError: the source failed (a camera unplugged, a file unreadable).
        """
        ...

    def close(self) -> None: ...


def _convert(bgr: NDArray[Any], grey: bool) -> Frame:
    if bgr.ndim == 2:
        out = bgr if grey else cv2.cvtColor(bgr, cv2.COLOR_GRAY2RGB)
    elif grey:
        out = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    else:
        out = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
    return np.asarray(out, dtype=np.uint8)


class ImageFolderSource:
    """Images played in name order, looping: an image folder or a single image file."""

    def __init__(self, files: Sequence[Path], *, grey: bool, description: str) -> None:
        self.files = list(files)
        self.grey = grey
        self.description = description
        self._index = 0
        self._cache: dict[Path, Frame] = {}

    def read(self) -> Frame:
        path = self.files[self._index % len(self.files)]
        self._index += 1
        frame = self._cache.get(path)
        if frame is None:
            bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
            if bgr is None:
                raise DeviceError(f"{path}: not a readable image")
            frame = _convert(bgr, self.grey)
            if len(self.files) <= 16:
                self._cache[path] = frame
        return frame

    def close(self) -> None:
        self._cache.clear()


class VideoFileSource:
    """A video file decoded by OpenCV, restarting at its end."""

    def __init__(self, path: Path, *, grey: bool) -> None:
        self.path = path
        self.grey = grey
        self.description = str(path)
        self._cap = cv2.VideoCapture(str(path))
        if not self._cap.isOpened():
            raise DeviceError(f"{path}: not a video OpenCV can read")

    def read(self) -> Frame:
        ok, bgr = self._cap.read()
        if not ok:
            self._cap.set(cv2.CAP_PROP_POS_FRAMES, 0)
            ok, bgr = self._cap.read()
            if not ok:
                raise DeviceError(f"{self.path}: no frame could be decoded")
        return _convert(bgr, self.grey)

    def close(self) -> None:
        self._cap.release()


class DeviceSource:
    """A V4L2 camera; a thread grabs frames so that a read never blocks the node."""

    def __init__(
        self, device: str, *, width: int, height: int, fourcc: str, fps: float, grey: bool
    ) -> None:
        self.device = device
        self.grey = grey
        self.description = device
        index: Any = int(device) if device.isdigit() else device
        self._cap = cv2.VideoCapture(index, cv2.CAP_V4L2)
        if not self._cap.isOpened():
            self._cap.release()
            raise DeviceError(f"{device}: cannot open the video device")
        self._cap.set(cv2.CAP_PROP_FOURCC, cv2.VideoWriter.fourcc(*fourcc))
        self._cap.set(cv2.CAP_PROP_FRAME_WIDTH, width)
        self._cap.set(cv2.CAP_PROP_FRAME_HEIGHT, height)
        self._cap.set(cv2.CAP_PROP_FPS, fps)
        self._lock = threading.Lock()
        self._frame: Frame | None = None
        self._error: str | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._grab, name=f"usb_cam {device}", daemon=True)
        self._thread.start()

    def _grab(self) -> None:
        failures = 0
        while not self._stop.is_set():
            ok, bgr = self._cap.read()
            if not ok:
                failures += 1
                if failures >= _DEVICE_FAILURES:
                    with self._lock:
                        self._error = f"{self.device}: the camera stopped delivering frames"
                    return
                self._stop.wait(0.01)
                continue
            failures = 0
            frame = _convert(bgr, self.grey)
            with self._lock:
                self._frame = frame

    def read(self) -> Frame | None:
        with self._lock:
            if self._error is not None:
                raise DeviceError(self._error)
            frame, self._frame = self._frame, None
        return frame

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._cap.release()


def open_source(
    video_device: str,
    *,
    image_width: int,
    image_height: int,
    pixel_format: str,
    framerate: float,
) -> FrameSource:
    """Open usb_cam's ``video_device``: ``/dev/videoN`` (or ``N``), a video file, an
    image file or a folder of images.

    Raises:
        DriverError: an unknown ``pixel_format``.
        DeviceError: no such device or file, or one that cannot be read.
    """
    if pixel_format not in PIXEL_FORMATS:
        raise DriverError(
            f"pixel_format {pixel_format!r} unknown (one of {', '.join(PIXEL_FORMATS)})"
        )
    grey = pixel_format == "grey"
    path = Path(video_device)
    if video_device.startswith("/dev/") or video_device.isdigit():
        if not video_device.isdigit() and not path.exists():
            raise DeviceError(f"{video_device}: no such video device")
        return DeviceSource(
            video_device,
            width=image_width,
            height=image_height,
            fourcc=PIXEL_FORMATS[pixel_format],
            fps=framerate,
            grey=grey,
        )
    if path.is_dir():
        files = sorted(p for p in path.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES)
        if not files:
            raise DeviceError(f"{path}: the folder holds no image ({', '.join(IMAGE_SUFFIXES)})")
        return ImageFolderSource(files, grey=grey, description=str(path))
    if not path.is_file():
        raise DeviceError(f"{video_device}: no such video device, video file or image folder")
    if path.suffix.lower() in IMAGE_SUFFIXES:
        return ImageFolderSource([path], grey=grey, description=str(path))
    return VideoFileSource(path, grey=grey)
