"""face_detector on the simulated camera: mybot in the maze_faces world, facing a poster
(scikit-image's astronaut) and facing a bare wall."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import pytest

from roverlab.core import Context
from roverlab.msgs import classes as mc
from roverlab.msgs import get_factory, image_to_array
from roverlab.perception.face_detector.node import FaceDetectorNode
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose


def run(yaw: float, tmp_path: Path, name: str) -> tuple[list[object], mc.Image]:
    ctx = Context()
    Simulation(context=ctx, world="maze_faces", robot="mybot", spawn=SpawnPose(0.0, 0.0, yaw))
    FaceDetectorNode(
        ctx,
        parameter_overrides={"do_publish_faces_of_unknown_size": True, "classifier_name": "face"},
        remappings={"image": "/image_raw"},  # Gazebo's camera with cameraName "/"
    )
    probe = ctx.create_node("probe")
    found: list[object] = []
    images: list[mc.Image] = []
    probe.create_subscription(
        get_factory("people_msgs/msg/PositionMeasurementArray"),
        "/face_detector/people_tracker_measurements_array",
        found.append,
        10,
    )
    probe.create_subscription(mc.Image, "/face_detector/image", images.append, 10)
    ctx.spin_for(0.5)
    ctx.shutdown()
    assert images, "the camera published nothing"
    rgb = image_to_array(images[-1])
    cv2.imwrite(str(tmp_path / f"{name}.png"), cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
    return found, images[-1]


def test_mybot_facing_the_north_poster_sees_a_face(tmp_path: Path) -> None:
    found, image = run(math.pi / 2, tmp_path, "poster")
    assert found, "no face found in the simulated camera"
    people = found[-1].people  # type: ignore[attr-defined]
    assert len(people) == 1
    # the poster is straight ahead: the face is near the image's centre column
    assert people[0].pos.x == pytest.approx(image.width / 2, abs=image.width * 0.1)
    assert people[0].header.frame_id == "base_camera_link"


def test_mybot_facing_a_bare_wall_sees_none(tmp_path: Path) -> None:
    found, _ = run(0.0, tmp_path, "wall")
    assert found == []
