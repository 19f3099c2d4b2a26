"""The launch registry imports a node's module only when a launch starts one; every
``module:Class`` it names must exist and be a node."""

from __future__ import annotations

import importlib
import subprocess
import sys

from roverlab.core import Node
from roverlab.launch.devices import DEVICE_NODES
from roverlab.launch.registry import _NODES


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
    code = (
        "import sys\n"
        "import roverlab.launch.registry\n"
        "mods = ('roverlab.navigation.move_base.node', 'roverlab.slam.gmapping.node',\n"
        "        'roverlab.localization.amcl.node', 'roverlab.perception.face_detector.node',\n"
        "        'fastapi')\n"
        "print([m for m in mods if m in sys.modules])\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
