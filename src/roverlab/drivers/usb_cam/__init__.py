"""``usb_cam``: V4L2 cameras through OpenCV, and video files or image folders for replay.

:mod:`~roverlab.drivers.usb_cam.calibration` reads and writes camera_calibration_parsers
YAML (what ``camera_info_url`` names); :mod:`~roverlab.drivers.usb_cam.capture` opens a
``video_device``; :mod:`roverlab.drivers.usb_cam.node` is ``usb_cam_node``.
"""

from __future__ import annotations

from roverlab.drivers.usb_cam.calibration import (
    CameraCalibration,
    load_calibration,
    save_calibration,
)
from roverlab.drivers.usb_cam.capture import PIXEL_FORMATS, FrameSource, open_source

__all__ = [
    "PIXEL_FORMATS",
    "CameraCalibration",
    "FrameSource",
    "load_calibration",
    "open_source",
    "save_calibration",
]
