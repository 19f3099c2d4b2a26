"""The ``usb_cam`` node (``usb_cam/usb_cam_node``, ROS 1 names).

Publishes ``~image_raw`` (sensor_msgs/Image, ``rgb8``; ``mono8`` for ``grey``) and
``~camera_info`` (sensor_msgs/CameraInfo) at ``framerate`` Hz, so a node named
``usb_cam`` publishes ``/usb_cam/image_raw`` as in ROS 1; services ``~start_capture`` and
``~stop_capture`` (std_srvs/Empty).

Parameters (usb_cam's names and defaults): ``video_device`` (``/dev/video0``; also a
video file, an image file or a folder of images), ``image_width`` 640,
``image_height`` 480, ``pixel_format`` (``mjpeg``, ``yuyv``, ``uyvy``, ``rgb24``,
``grey``, ``yuvmono10``), ``io_method`` (``mmap``, ``read``, ``userptr``: accepted,
OpenCV always maps), ``framerate`` 30, ``camera_frame_id`` / ``camera_name``
(``head_camera``), ``camera_info_url`` (``package://`` or ``file://`` calibration YAML;
empty: an uncalibrated camera_info of the image's size), and the V4L2 controls
``brightness``, ``contrast``, ``saturation``, ``sharpness``, ``gain`` (-1: leave),
``autofocus``, ``focus``, ``autoexposure``, ``exposure``, ``auto_white_balance``,
``white_balance``, set on a camera through OpenCV.

A missing or lost device is one error line; the node retries every second and carries on
when the device is back. A bad parameter or calibration file raises at construction.
"""

from __future__ import annotations

from typing import Any, Final

import numpy as np

from roverlab.core import Context, Node, ParameterError
from roverlab.description import resolve_uri
from roverlab.description.errors import DescriptionError
from roverlab.drivers.errors import DeviceError, DriverError
from roverlab.drivers.usb_cam.calibration import CameraCalibration, load_calibration
from roverlab.drivers.usb_cam.capture import IO_METHODS, FrameSource, open_source
from roverlab.msgs import array_to_image
from roverlab.msgs import classes as mc
from roverlab.perception.image_transport.publisher import CompressedPublisher

__all__ = ["UsbCamNode"]

_RETRY_S: Final = 1.0
_CONTROLS: Final = (
    ("brightness", -1),
    ("contrast", -1),
    ("saturation", -1),
    ("sharpness", -1),
    ("gain", -1),
    ("autofocus", False),
    ("focus", -1),
    ("autoexposure", True),
    ("exposure", 100),
    ("auto_white_balance", True),
    ("white_balance", 4000),
)


class UsbCamNode(Node):
    """usb_cam_node: frames from ``video_device`` on ``~image_raw`` + ``~camera_info``.

    Args:
        context: the context the node joins.
        node_name: defaults to ``usb_cam``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Raises:
        DriverError: an unknown pixel_format or io_method, or an unreadable calibration.
        ParameterError: a non-positive size or framerate.
    """

    def __init__(self, context: Context, *, node_name: str = "usb_cam", **node_kwargs: Any):
        super().__init__(node_name, context=context, **node_kwargs)
        p = self.declare_parameter
        self.video_device = str(p("video_device", "/dev/video0").value)
        self.width = int(p("image_width", 640).value)
        self.height = int(p("image_height", 480).value)
        self.pixel_format = str(p("pixel_format", "mjpeg").value)
        io_method = str(p("io_method", "mmap").value)
        self.framerate = float(p("framerate", 30).value)
        self.frame_id = str(p("camera_frame_id", "head_camera").value)
        self.camera_name = str(p("camera_name", "head_camera").value)
        info_url = str(p("camera_info_url", "").value)
        self.controls = {name: p(name, default).value for name, default in _CONTROLS}
        if io_method not in IO_METHODS:
            raise DriverError(f"io_method {io_method!r} unknown (one of {', '.join(IO_METHODS)})")
        if self.width <= 0 or self.height <= 0:
            raise ParameterError(f"{node_name}: image_width and image_height must be > 0")
        if not self.framerate > 0:
            raise ParameterError(f"{node_name}: framerate must be > 0, got {self.framerate}")
        self.calibration = self._load_calibration(info_url) if info_url else None
        self._image_pub = self.create_publisher(mc.Image, "~/image_raw", 1)
        self._compressed_pub = CompressedPublisher(self, "~/image_raw")  # image_transport's
        self._info_pub = self.create_publisher(mc.CameraInfo, "~/camera_info", 1)
        self.create_service("std_srvs/srv/Empty", "~/start_capture", self._on_start)
        self.create_service("std_srvs/srv/Empty", "~/stop_capture", self._on_stop)
        self.capturing = True
        self.source: FrameSource | None = None
        self.frames_published = 0
        self._last_error = ""
        self._next_retry_ns = 0
        self._open()
        self.create_timer(1.0 / self.framerate, self._tick)

    # ----------------------------------------------------------------- setup
    def _load_calibration(self, url: str) -> CameraCalibration:
        try:
            path = resolve_uri(url)
        except DescriptionError as err:
            raise DriverError(f"camera_info_url {url!r}: {err}") from err
        calib = load_calibration(path)
        if calib.camera_name and calib.camera_name != self.camera_name:
            self.get_logger().warning(
                f"[{self.camera_name}] does not match {calib.camera_name} in file {path}"
            )
        return calib

    def _open(self) -> bool:
        try:
            self.source = open_source(
                self.video_device,
                image_width=self.width,
                image_height=self.height,
                pixel_format=self.pixel_format,
                framerate=self.framerate,
            )
        except DeviceError as err:
            self._report(f"{err}; retrying every {_RETRY_S:g} s")
            self._next_retry_ns = self.get_clock().now_ns() + int(_RETRY_S * 1e9)
            return False
        if self._last_error:
            self.get_logger().info(f"{self.video_device}: opened again")
        self._last_error = ""
        self.get_logger().info(
            f"Starting '{self.camera_name}' ({self.source.description}) at "
            f"{self.width}x{self.height} via {self.pixel_format} at {self.framerate:g} FPS"
        )
        return True

    def _report(self, message: str) -> None:
        if message != self._last_error:
            self.get_logger().error(message)
            self._last_error = message

    # ----------------------------------------------------------------- services
    def _on_start(self, _request: Any, response: Any) -> Any:
        self.capturing = True
        return response

    def _on_stop(self, _request: Any, response: Any) -> Any:
        self.capturing = False
        return response

    # ----------------------------------------------------------------- frames
    def _tick(self) -> None:
        if not self.capturing:
            return
        if self.source is None and (
            self.get_clock().now_ns() < self._next_retry_ns or not self._open()
        ):
            return
        assert self.source is not None
        try:
            frame = self.source.read()
        except DeviceError as err:
            self.source.close()
            self.source = None
            self._report(f"{err}; retrying every {_RETRY_S:g} s")
            self._next_retry_ns = self.get_clock().now_ns() + int(_RETRY_S * 1e9)
            return
        if frame is not None:
            self.publish_frame(frame)

    def publish_frame(self, frame: np.ndarray[Any, Any]) -> None:
        """Publish one frame and its camera_info, stamped now."""
        stamp = self.get_clock().now().to_msg()
        encoding = "mono8" if frame.ndim == 2 else "rgb8"
        image = array_to_image(frame, encoding, frame_id=self.frame_id, stamp=stamp)
        self._image_pub.publish(image)
        self._compressed_pub.publish(image)  # only while someone subscribes
        self._info_pub.publish(self.camera_info(int(image.width), int(image.height), stamp))
        self.frames_published += 1

    def camera_info(self, width: int, height: int, stamp: Any) -> Any:
        """The CameraInfo of a frame: the calibration's, or an uncalibrated one."""
        c = self.calibration
        header = mc.Header(stamp, self.frame_id)
        roi = mc.RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
        if c is None:
            return mc.CameraInfo(
                header=header,
                height=height,
                width=width,
                distortion_model="",
                d=np.zeros(0),
                k=np.zeros(9),
                r=np.zeros(9),
                p=np.zeros(12),
                binning_x=0,
                binning_y=0,
                roi=roi,
            )
        return mc.CameraInfo(
            header=header,
            height=c.image_height,
            width=c.image_width,
            distortion_model=c.distortion_model,
            d=np.asarray(c.distortion_coefficients, dtype=float),
            k=np.asarray(c.camera_matrix, dtype=float),
            r=np.asarray(c.rectification_matrix, dtype=float),
            p=np.asarray(c.projection_matrix, dtype=float),
            binning_x=0,
            binning_y=0,
            roi=roi,
        )

    def destroy_node(self) -> None:
        if self.source is not None:
            self.source.close()
            self.source = None
        super().destroy_node()
