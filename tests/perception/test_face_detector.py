"""face_detector: the cascade, sizes from depth, the RGB-D node, bad classifier files."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from roverlab.core import Context
from roverlab.msgs import array_to_image, get_factory
from roverlab.msgs import classes as mc
from roverlab.perception.errors import PerceptionError
from roverlab.perception.face_detector import Faces, FaceSizeLimits
from roverlab.perception.face_detector.node import FaceDetectorNode, classifier_path
from roverlab.world import BUNDLED_WORLDS_DIR

FACE_PNG = BUNDLED_WORLDS_DIR / "models/poster_face/materials/textures/face.png"
K = np.array([[500.0, 0, 320], [0, 500, 240], [0, 0, 1]])


def scene() -> np.ndarray:
    rgb = np.full((480, 640, 3), 90, np.uint8)
    rgb[140:340, 220:420] = cv2.cvtColor(cv2.imread(str(FACE_PNG)), cv2.COLOR_BGR2RGB)
    return rgb


def test_face_sizes_from_depth() -> None:
    faces = Faces()
    rgb = scene()
    (box,) = faces.detect_boxes(rgb)
    depth = np.full((480, 640), 2.0)
    (face,) = faces.detect(rgb, depth, K)
    assert face.status == "good"
    assert face.width_m == pytest.approx(box[2] * 2.0 / 500.0)
    u, v = face.center_px
    assert face.center3d == pytest.approx(((u - 320) * 0.004, (v - 240) * 0.004, 2.0))
    (far,) = faces.detect(rgb, np.full((480, 640), 9.0), K)
    assert far.status == "bad"  # beyond max_face_z_m 8 m (and 1.6 m wide)
    tiny = Faces(limits=FaceSizeLimits(face_size_min_m=0.5, face_size_max_m=0.6))
    assert tiny.detect(rgb, depth, K)[0].status == "bad"
    (unknown,) = faces.detect(rgb, np.zeros((480, 640)), K)
    assert unknown.status == "unknown"  # no valid depth
    with pytest.raises(PerceptionError, match="differ in size"):
        faces.detect(rgb, np.ones((10, 10)), K)


def test_bad_classifier_and_limits(tmp_path: Path) -> None:
    with pytest.raises(PerceptionError, match="no such Haar cascade"):
        Faces(tmp_path / "x.xml")
    junk = tmp_path / "junk.xml"
    junk.write_text("<opencv_storage><x>1</x></opencv_storage>")
    with pytest.raises(PerceptionError, match="not an OpenCV Haar cascade"):
        Faces(junk)
    with pytest.raises(PerceptionError, match="face_size_min_m"):
        FaceSizeLimits(face_size_min_m=1.0, face_size_max_m=0.5)
    # a ROS install's path falls back to OpenCV's copy of the same cascade
    assert classifier_path("/opt/ros/haarcascade_profileface.xml").is_file()


def test_rgbd_node_publishes_good_faces_markers_and_cloud() -> None:
    ctx = Context()
    FaceDetectorNode(
        ctx,
        parameter_overrides={"use_rgbd": True, "classifier_name": "frontalface"},
        remappings={
            "camera": "camera",
            "image_topic": "image_rect_color",
            "depth_ns": "depth_registered",
            "depth_topic": "image_rect_raw",
        },
    )
    src = ctx.create_node("camera_driver")
    img_pub = src.create_publisher(mc.Image, "/camera/rgb/image_rect_color", 1)
    depth_pub = src.create_publisher(mc.Image, "/camera/depth_registered/image_rect_raw", 1)
    info_pub = src.create_publisher(mc.CameraInfo, "/camera/rgb/camera_info", 1)
    arrays: list[object] = []
    markers: list[mc.MarkerArray] = []
    src.create_subscription(
        get_factory("people_msgs/msg/PositionMeasurementArray"),
        "/face_detector/people_tracker_measurements_array",
        arrays.append,
        10,
    )
    src.create_subscription(mc.MarkerArray, "/face_detector/markers", markers.append, 10)
    rgb = scene()

    def send() -> None:
        stamp = src.get_clock().now().to_msg()
        info_pub.publish(get_factory("sensor_msgs/msg/CameraInfo")(k=K.reshape(-1)))
        depth_pub.publish(
            array_to_image(np.full((480, 640), 1500, np.uint16), "16UC1", stamp=stamp)
        )
        img_pub.publish(
            array_to_image(rgb, "rgb8", frame_id="camera_rgb_optical_frame", stamp=stamp)
        )

    src.create_timer(0.2, send)
    ctx.spin_for(1.0)
    people = arrays[-1].people  # type: ignore[attr-defined]
    assert len(people) == 1 and people[0].pos.z == pytest.approx(1.5)
    assert people[0].header.frame_id == "camera_rgb_optical_frame"
    cubes = [m for m in markers[-1].markers if m.action == 0]
    assert len(cubes) == 1 and cubes[0].pose.position.z == pytest.approx(1.5)
    ctx.shutdown()
