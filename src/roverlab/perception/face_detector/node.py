"""The ``face_detector`` node (people stack, ``face_detector/face_detector``).

Topics, as face_detector resolves them: ``camera``, ``image_topic``, ``depth_topic`` and
``depth_ns`` are *names* set with ``<remap>`` (``<remap from="camera" to="usb_cam"/>``,
``<remap from="image_topic" to="image_raw"/>``).

* ``use_rgbd`` false (RGB-only: roverlab's mode for a plain camera; ROS's stereo mode is
  not implemented): subscribes ``camera/image_topic`` (sensor_msgs/Image), or the topic
  ``image`` is remapped to (``<remap from="image" to="/image_raw"/>``, for a camera
  publishing outside a namespace, as Gazebo's with ``cameraName /``). Faces have no
  known size, so they are ``unknown`` and published only with
  ``do_publish_faces_of_unknown_size: true``, positioned at their image centre
  ``(u, v, 0)`` in pixels, as face_detector does for faces of unknown size.
* ``use_rgbd`` true: ``camera/rgb/image_topic``, ``camera/depth_ns/depth_topic`` (16UC1 mm
  or 32FC1 m) and ``camera/rgb/camera_info``, paired by stamp (exactly, or the nearest
  within the queue with ``approximate_sync``); faces get a 3-D centre in the image's
  frame and a width, checked against ``face_size_min_m`` / ``face_size_max_m`` /
  ``max_face_z_m``.

Publishes ``face_detector/people_tracker_measurements_array``
(people_msgs/PositionMeasurementArray: name ``classifier_name``, reliability
``classifier_reliability``, covariance diag 0.04, initialization 1) whenever a face is
seen, ``face_detector/faces_cloud`` (sensor_msgs/PointCloud, the good faces) for every
image, and, as roverlab's stand-in for ``do_display``'s OpenCV window,
``face_detector/image`` (the image with the boxes: good green, unknown blue, bad red) for
the dashboard's image panel, and ``face_detector/markers`` (visualization_msgs/MarkerArray:
a box per face with a known 3-D position).

Parameters: ``classifier_name`` (""), ``classifier_filename`` (empty, or a path whose file
does not exist but is named like one of OpenCV's cascades: OpenCV's own copy),
``classifier_reliability`` (0.0), ``do_display`` (false), ``do_continuous`` (true; false,
the action mode, is not implemented), ``do_publish_faces_of_unknown_size`` (false),
``use_depth`` (true), ``use_external_init`` (false), ``face_size_min_m`` (0.1),
``face_size_max_m`` (0.5), ``max_face_z_m`` (8.0), ``face_separation_dist_m`` (1.0),
``use_rgbd`` (false), ``queue_size`` (5), ``approximate_sync`` (false), ``fixed_frame``.
"""

from __future__ import annotations

from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.core import Context, Node, QoSProfile
from roverlab.core.graph import resolve_name
from roverlab.msgs import array_to_image, get_factory, image_to_array
from roverlab.msgs import classes as mc
from roverlab.perception.errors import PerceptionError
from roverlab.perception.face_detector.faces import (
    DEFAULT_CLASSIFIER,
    Face,
    Faces,
    FaceSizeLimits,
    draw_faces,
)

__all__ = ["FaceDetectorNode", "classifier_path"]

_ARRAY_TYPE = "people_msgs/msg/PositionMeasurementArray"
_MEASUREMENT_TYPE = "people_msgs/msg/PositionMeasurement"


def classifier_path(filename: str) -> Path:
    """The cascade file to load: ``filename``, or OpenCV's copy of a cascade of the same
    name when ``filename`` is empty or names a file that is not there (ROS launch files
    point into an OpenCV install)."""
    if not filename:
        return DEFAULT_CLASSIFIER
    path = Path(filename)
    if path.is_file():
        return path
    bundled = DEFAULT_CLASSIFIER.parent / path.name
    return bundled if bundled.is_file() else path


def _join(*parts: str) -> str:
    """``ros::names::clean`` of the parts joined with ``/``."""
    tokens = [t for p in parts for t in p.split("/") if t]
    return "/" + "/".join(tokens)


def _stamp_ns(msg: Any) -> int:
    return int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)


class FaceDetectorNode(Node):
    """face_detector: Haar-cascade faces on an image stream.

    Args:
        context: the context the node joins.
        node_name: defaults to ``face_detector``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Raises:
        PerceptionError: the cascade cannot be loaded, or bad size limits.
    """

    def __init__(
        self, context: Context, *, node_name: str = "face_detector", **node_kwargs: Any
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        p = self.declare_parameter
        self.classifier_name = str(p("classifier_name", "").value)
        filename = str(p("classifier_filename", "").value)
        self.reliability = float(p("classifier_reliability", 0.0).value)
        do_display = bool(p("do_display", False).value)
        do_continuous = bool(p("do_continuous", True).value)
        self.publish_unknown = bool(p("do_publish_faces_of_unknown_size", False).value)
        p("use_depth", True)
        p("use_external_init", False)
        limits = FaceSizeLimits(
            face_size_min_m=float(p("face_size_min_m", 0.1).value),
            face_size_max_m=float(p("face_size_max_m", 0.5).value),
            max_face_z_m=float(p("max_face_z_m", 8.0).value),
        )
        p("face_separation_dist_m", 1.0)
        self.use_rgbd = bool(p("use_rgbd", False).value)
        queue_size = int(p("queue_size", 5).value)
        self.approximate = bool(p("approximate_sync", False).value)
        p("fixed_frame", "camera_rgb_optical_frame")
        self.faces = Faces(classifier_path(filename), limits=limits)
        if do_display:
            self.get_logger().info("do_display: the boxes are drawn on face_detector/image")
        if not do_continuous:
            self.get_logger().warning(
                "do_continuous false (the action mode) is not implemented: detecting continuously"
            )
        self._array = get_factory(_ARRAY_TYPE)
        self._measurement = get_factory(_MEASUREMENT_TYPE)
        self._array_pub = self.create_publisher(
            self._array, "face_detector/people_tracker_measurements_array", 1
        )
        self._cloud_pub = self.create_publisher(_CLOUD, "face_detector/faces_cloud", 1)
        self._image_pub = self.create_publisher(mc.Image, "face_detector/image", 1)
        self._marker_pub = self.create_publisher(mc.MarkerArray, "face_detector/markers", 1)
        camera = self.resolve_topic_name("camera")
        image_topic = self.resolve_topic_name("image_topic")
        self.detections = 0
        self._depths: deque[Any] = deque(maxlen=max(1, queue_size))
        self._info: Any = None
        depth_qos = QoSProfile(depth=max(1, queue_size))
        if self.use_rgbd:
            depth_ns = self.resolve_topic_name("depth_ns")
            depth_topic = self.resolve_topic_name("depth_topic")
            self.image_topic = _join(camera, "rgb", image_topic)
            self.depth_topic = _join(camera, depth_ns, depth_topic)
            self.create_subscription(mc.Image, self.depth_topic, self._depths.append, depth_qos)
            self.create_subscription(
                mc.CameraInfo, _join(camera, "rgb", "camera_info"), self._on_info, 3
            )
        else:
            image = self.resolve_topic_name("image")
            remapped = image != resolve_name("image", self.get_namespace(), self.get_name())
            self.image_topic = image if remapped else _join(camera, image_topic)
        self.create_subscription(mc.Image, self.image_topic, self._on_image, 3)
        self.get_logger().info(
            f"face_detector on {self.image_topic} ({'RGB-D' if self.use_rgbd else 'RGB only'}),"
            f" cascade {self.faces.classifier_filename.name}"
        )

    def _on_info(self, msg: Any) -> None:
        self._info = msg

    def _depth_for(self, image: Any) -> Any | None:
        stamp = _stamp_ns(image)
        best = None
        for d in self._depths:
            gap = abs(_stamp_ns(d) - stamp)
            if gap == 0 or (self.approximate and (best is None or gap < best[0])):
                best = (gap, d)
        return None if best is None else best[1]

    def _on_image(self, msg: Any) -> None:
        try:
            pixels = image_to_array(msg)
        except Exception as err:  # an encoding image_to_array cannot read
            self.get_logger().warning(f"{self.image_topic}: cannot read the image: {err}")
            return
        rgb = _as_rgb(pixels, str(msg.encoding))
        if rgb is None:
            self.get_logger().warning(f"{self.image_topic}: unsupported encoding {msg.encoding}")
            return
        depth = k = None
        if self.use_rgbd:
            depth_msg = self._depth_for(msg)
            if depth_msg is None or self._info is None:
                return  # the synchronizer waits for a matching depth image
            depth = image_to_array(depth_msg).astype(np.float64)
            if str(depth_msg.encoding) != "32FC1":
                depth = depth * 0.001
            k = np.asarray(self._info.k, dtype=float).reshape(3, 3)
        try:
            faces = self.faces.detect(rgb, depth, k)
        except PerceptionError as err:
            self.get_logger().warning(f"{self.image_topic}: {err}")
            return
        self.publish(msg.header, faces, rgb)

    def publish(self, header: Any, faces: list[Face], rgb: Any) -> None:
        """Publish one image's detections on every output topic."""
        good = [f for f in faces if f.status == "good"]
        if faces:
            people = []
            for f in faces:
                if not (f.status == "good" or (f.status == "unknown" and self.publish_unknown)):
                    continue
                if f.center3d is not None:
                    x, y, z = f.center3d
                else:
                    (x, y), z = f.center_px, 0.0
                people.append(
                    self._measurement(
                        header=header,
                        name=self.classifier_name,
                        object_id="",
                        pos=mc.Point(float(x), float(y), float(z)),
                        reliability=self.reliability,
                        covariance=np.diag([0.04, 0.04, 0.04]).reshape(-1),
                        initialization=1,
                    )
                )
            self._array_pub.publish(self._array(header=header, people=people))
            self.detections += len(people)
        self._cloud_pub.publish(
            _CLOUD(
                header=header,
                points=[mc.Point32(*(float(v) for v in f.center3d)) for f in good if f.center3d],
                channels=[_CHANNEL(name="intensity", values=np.ones(len(good), np.float32))]
                if good
                else [],
            )
        )
        self._marker_pub.publish(mc.MarkerArray(self._markers(header, faces)))
        if self._image_pub.has_listeners:
            self._image_pub.publish(
                array_to_image(
                    draw_faces(rgb, faces), "rgb8", frame_id=header.frame_id, stamp=header.stamp
                )
            )

    def _markers(self, header: Any, faces: list[Face]) -> list[Any]:
        out = [_marker(header, 0, 3, None, 0.0, (0.0, 0.0, 0.0))]  # DELETEALL first
        for i, f in enumerate(faces):
            if f.center3d is None or f.width_m is None:
                continue
            colour = (0.0, 1.0, 0.0) if f.status == "good" else (1.0, 0.0, 0.0)
            out.append(_marker(header, i + 1, 0, f.center3d, f.width_m, colour))
        return out


_MARKER = get_factory("visualization_msgs/msg/Marker")
_CLOUD = get_factory("sensor_msgs/msg/PointCloud")
_CHANNEL = get_factory("sensor_msgs/msg/ChannelFloat32")


def _marker(
    header: Any,
    marker_id: int,
    action: int,
    center: tuple[float, float, float] | None,
    size: float,
    rgb: tuple[float, float, float],
) -> Any:
    x, y, z = center or (0.0, 0.0, 0.0)
    return _MARKER(
        header=header,
        ns="faces",
        id=marker_id,
        type=1,  # CUBE
        action=action,
        pose=mc.Pose(mc.Point(x, y, z), mc.Quaternion(0.0, 0.0, 0.0, 1.0)),
        scale=mc.Vector3(size, size, 0.02) if size else mc.Vector3(0.0, 0.0, 0.0),
        color=mc.ColorRGBA(rgb[0], rgb[1], rgb[2], 0.6),
        lifetime=mc.Duration(1, 0),
    )


def _as_rgb(pixels: Any, encoding: str) -> Any | None:
    if encoding in ("rgb8", "mono8"):
        return pixels
    if encoding == "bgr8":
        return pixels[:, :, ::-1]
    if encoding in ("rgba8", "bgra8"):
        rgb = pixels[:, :, :3]
        return rgb if encoding == "rgba8" else rgb[:, :, ::-1]
    return None
