"""usb_cam: image files, folders and videos as video_device, calibration files, a missing
device; face_detector on usb_cam's frames (a shipped face picture)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from roverlab.core import Context
from roverlab.drivers.errors import DeviceError, DriverError
from roverlab.drivers.usb_cam import (
    CameraCalibration,
    load_calibration,
    open_source,
    save_calibration,
)
from roverlab.drivers.usb_cam.node import UsbCamNode
from roverlab.launch import LaunchError, build_launch, load_launch
from roverlab.msgs import classes as mc
from roverlab.msgs import get_factory, image_to_array
from roverlab.world import BUNDLED_WORLDS_DIR

FACE_PNG = BUNDLED_WORLDS_DIR / "models/poster_face/materials/textures/face.png"


def scene_with_face(tmp_path: Path) -> tuple[Path, tuple[int, int]]:
    """A 640x480 picture with the shipped face (scikit-image's astronaut) pasted at
    (220, 140); returns its path and the face's expected centre in pixels."""
    face = cv2.imread(str(FACE_PNG))
    scene = np.full((480, 640, 3), 90, np.uint8)
    scene[140:340, 220:420] = face
    path = tmp_path / "scene.png"
    cv2.imwrite(str(path), scene)
    return path, (320, 240)


def calib(tmp_path: Path) -> Path:
    path = tmp_path / "head_camera.yaml"
    save_calibration(
        CameraCalibration(
            image_width=640,
            image_height=480,
            camera_name="head_camera",
            camera_matrix=[500.0, 0, 320, 0, 500, 240, 0, 0, 1],
            distortion_coefficients=[0.1, -0.2, 0.0, 0.0, 0.0],
            projection_matrix=[500.0, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0],
        ),
        path,
    )
    return path


def test_calibration_round_trip_and_errors(tmp_path: Path) -> None:
    path = calib(tmp_path)
    c = load_calibration(path)
    assert c.camera_matrix[0] == 500.0 and c.distortion_coefficients == [0.1, -0.2, 0, 0, 0]
    save_calibration(c, tmp_path / "again.yaml")
    assert load_calibration(tmp_path / "again.yaml") == c
    bad = tmp_path / "bad.yaml"
    bad.write_text("image_width: 640\nimage_height: 480\ncamera_matrix: {data: [1, 2]}\n")
    with pytest.raises(DriverError, match=r"bad\.yaml: camera_matrix needs 9 numbers"):
        load_calibration(bad)
    bad.write_text("image_width: [\n")
    with pytest.raises(DriverError, match="malformed camera calibration YAML"):
        load_calibration(bad)
    with pytest.raises(DriverError, match="cannot read"):
        load_calibration(tmp_path / "nope.yaml")


def test_sources_file_folder_video_and_missing(tmp_path: Path) -> None:
    kw = {"image_width": 640, "image_height": 480, "pixel_format": "mjpeg", "framerate": 30.0}
    folder = tmp_path / "frames"
    folder.mkdir()
    for i in range(3):
        cv2.imwrite(str(folder / f"{i:03d}.png"), np.full((48, 64, 3), 40 * i, np.uint8))
    src = open_source(str(folder), **kw)
    assert [int(src.read()[0, 0, 0]) for _ in range(4)] == [0, 40, 80, 0]  # (loops)
    video = tmp_path / "clip.avi"
    writer = cv2.VideoWriter(str(video), cv2.VideoWriter.fourcc(*"MJPG"), 10, (64, 48))
    for i in range(5):
        writer.write(np.full((48, 64, 3), 50 * i, np.uint8))
    writer.release()
    src = open_source(str(video), **kw)
    values = [int(src.read()[0, 0].mean()) for _ in range(6)]
    assert values[:5] == pytest.approx([0, 50, 100, 150, 200], abs=4) and values[5] < 5
    grey = open_source(str(folder), **{**kw, "pixel_format": "grey"}).read()
    assert grey is not None and grey.ndim == 2
    with pytest.raises(DeviceError, match="/dev/video77: no such video device"):
        open_source("/dev/video77", **kw)
    with pytest.raises(DeviceError, match="no such video device, video file or image folder"):
        open_source(str(tmp_path / "none.mp4"), **kw)
    with pytest.raises(DriverError, match="pixel_format 'h264' unknown"):
        open_source(str(folder), **{**kw, "pixel_format": "h264"})


def test_usb_cam_file_to_face_detector_through_a_launch_file(tmp_path: Path) -> None:
    picture, (u, v) = scene_with_face(tmp_path)
    launch_file = tmp_path / "camera.launch"
    launch_file.write_text(
        f"""<launch>
  <node name="usb_cam" pkg="usb_cam" type="usb_cam_node" output="screen">
    <param name="video_device" value="{picture}"/>
    <param name="pixel_format" value="yuyv"/>
    <param name="framerate" value="10"/>
    <param name="camera_frame_id" value="usb_cam"/>
    <param name="io_method" value="mmap"/>
    <param name="camera_info_url" value="file://{calib(tmp_path)}"/>
  </node>
  <node pkg="face_detector" type="face_detector" name="face_detector" output="screen">
    <remap from="camera" to="usb_cam"/>
    <remap from="image_topic" to="image_raw"/>
    <param name="classifier_name" value="frontalface"/>
    <param name="classifier_filename"
           value="/opt/ros/kinetic/share/OpenCV-3.3.1/haarcascades/haarcascade_frontalface_alt.xml"/>
    <param name="classifier_reliability" value="0.9"/>
    <param name="do_continuous" value="true"/>
    <param name="do_publish_faces_of_unknown_size" value="true"/>
    <param name="do_display" value="false"/>
  </node>
</launch>"""
    )
    ctx = Context()
    launch = build_launch(load_launch(launch_file), context=ctx)
    assert launch.warnings == []
    probe = ctx.create_node("probe")
    images: list[mc.Image] = []
    infos: list[mc.CameraInfo] = []
    found: list[object] = []
    annotated: list[mc.Image] = []
    probe.create_subscription(mc.Image, "/usb_cam/image_raw", images.append, 10)
    probe.create_subscription(mc.CameraInfo, "/usb_cam/camera_info", infos.append, 10)
    probe.create_subscription(
        get_factory("people_msgs/msg/PositionMeasurementArray"),
        "/face_detector/people_tracker_measurements_array",
        found.append,
        10,
    )
    probe.create_subscription(mc.Image, "/face_detector/image", annotated.append, 10)
    ctx.spin_for(1.05)
    assert len(images) == 10  # framerate 10
    assert (images[0].encoding, images[0].width, images[0].header.frame_id) == (
        "rgb8",
        640,
        "usb_cam",
    )
    assert infos[0].k[0] == 500.0 and infos[0].d[0] == 0.1
    assert len(found) == 10
    people = found[-1].people  # type: ignore[attr-defined]
    assert len(people) == 1
    face = people[0]
    assert (face.name, face.reliability, face.header.frame_id) == ("frontalface", 0.9, "usb_cam")
    assert face.pos.x == pytest.approx(u, abs=25) and face.pos.y == pytest.approx(v, abs=25)
    assert face.pos.z == 0.0  # unknown size: the image position
    boxed = image_to_array(annotated[-1])
    assert (boxed[:, :, 2] == 255).any()  # the blue box of an unknown-size face
    ctx.shutdown()


def test_no_face_no_detection(tmp_path: Path) -> None:
    empty = tmp_path / "wall.png"
    rng = np.random.default_rng(3)
    cv2.imwrite(str(empty), rng.integers(0, 255, (480, 640, 3), dtype=np.uint8))
    ctx = Context()
    UsbCamNode(ctx, parameter_overrides={"video_device": str(empty), "framerate": 5})
    from roverlab.perception.face_detector.node import FaceDetectorNode

    det = FaceDetectorNode(
        ctx,
        parameter_overrides={"do_publish_faces_of_unknown_size": True},
        remappings={"camera": "usb_cam", "image_topic": "image_raw"},
    )
    ctx.spin_for(1.0)
    assert det.detections == 0
    ctx.shutdown()


def test_missing_device_is_one_error_and_other_nodes_run(
    caplog: pytest.LogCaptureFixture, tmp_path: Path
) -> None:
    ctx = Context()
    cam = UsbCamNode(ctx, parameter_overrides={"video_device": "/dev/video77"})
    other = ctx.create_node("other")
    ticks: list[int] = []
    other.create_timer(0.1, lambda: ticks.append(1))
    ctx.spin_for(3.0)
    errors = [r.getMessage() for r in caplog.records if r.levelname == "ERROR"]
    assert errors == ["/dev/video77: no such video device; retrying every 1 s"]
    assert cam.frames_published == 0 and len(ticks) == 30
    ctx.shutdown()
    bad = tmp_path / "bad.launch"
    bad.write_text(
        """<launch><node name="cam" pkg="usb_cam" type="usb_cam_node">
  <param name="camera_info_url" value="file:///nowhere/cam.yaml"/></node></launch>"""
    )
    with pytest.raises(LaunchError, match=r"bad\.launch.*cam\.yaml: cannot read camera calib"):
        build_launch(load_launch(bad), context=Context())
