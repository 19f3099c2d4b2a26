"""The launch registry imports a node's module only when a launch starts one; every
``module:Class`` it names must exist and be a node."""

from __future__ import annotations

import importlib

from roverlab.core import Node
from roverlab.launch.devices import DEVICE_NODES
from roverlab.launch.registry import _NODES
from tests.helpers.imports import loaded_after


def test_every_lazily_named_node_class_exists() -> None:
    paths = list(_NODES.values())
    paths += [
        "roverlab.drivers.usb_cam.node:UsbCamNode",
        "roverlab.drivers.rplidar.node:RplidarNode",
        "roverlab.perception.face_detector.node:FaceDetectorNode",
    ]
    for path in paths:
        module, _, name = path.partition(":")
        cls = getattr(importlib.import_module(module), name)
        assert isinstance(cls, type) and issubclass(cls, Node), path
    assert ("face_detector", "face_detector") in DEVICE_NODES


def test_importing_the_registry_loads_no_algorithm_node() -> None:
    nodes = ("roverlab.navigation.move_base.node", "roverlab.slam.gmapping.node",
             "roverlab.localization.amcl.node", "roverlab.perception.face_detector.node",
             "fastapi")  # fmt: skip
    assert loaded_after("import roverlab.launch.registry", nodes) == []
