"""Launch factories of the device drivers and perception nodes.

``arbotix_python/arbotix_driver``, ``usb_cam/usb_cam_node``, ``face_detector/face_detector``,
``rplidar_ros/rplidarNode``, ``ros_arduino_python/arduino_node.py`` and seed 002's
``roborts_base/roborts_base_node`` (the same serial base). :data:`DEVICE_NODES` is merged
into the launch registry.

A device that is missing or stops answering does not stop a launch: its node logs one
error line and keeps trying to reconnect while the other nodes run. A malformed
configuration (a bad parameter, an unreadable calibration file) is a LaunchError naming
the file and the node.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Final

from roverlab.core import Node
from roverlab.drivers.arbotix.node import ArbotixDriver
from roverlab.drivers.rplidar.node import RplidarNode
from roverlab.drivers.usb_cam.node import UsbCamNode
from roverlab.errors import RoverlabError
from roverlab.launch.state import LaunchState, NodeFactory, node_kwargs
from roverlab.launch.xml import LaunchError, NodeSpec
from roverlab.perception.face_detector.node import FaceDetectorNode

__all__ = ["DEVICE_NODES"]


def _arbotix(state: LaunchState, spec: NodeSpec) -> Node | None:
    if spec.params.get("sim") is not True:
        state.warnings.append(
            f"{spec.source}: {spec.pkg}/{spec.type} not started: only sim: true (a fake base) "
            "is supported; a real ArbotiX board's protocol is not implemented"
        )
        return None
    try:
        return ArbotixDriver(state.context, node_name=spec.name, **node_kwargs(spec))
    except (RoverlabError, ValueError) as err:
        raise LaunchError(f"{spec.source}: {spec.pkg}/{spec.type}: {err}") from err


def _plain(make: Callable[..., Node]) -> NodeFactory:
    """A node built from its ``<node>`` (private params, remaps); a bad configuration is a
    LaunchError naming the file."""

    def factory(state: LaunchState, spec: NodeSpec) -> Node:
        try:
            return make(state.context, node_name=spec.name, **node_kwargs(spec))
        except (RoverlabError, ValueError) as err:
            raise LaunchError(f"{spec.source}: {spec.pkg}/{spec.type}: {err}") from err

    return factory


DEVICE_NODES: Final[dict[tuple[str, str], NodeFactory]] = {
    ("arbotix_python", "arbotix_driver"): _arbotix,
    ("usb_cam", "usb_cam_node"): _plain(UsbCamNode),
    ("rplidar_ros", "rplidarNode"): _plain(RplidarNode),
    ("rplidar_ros", "rplidar_node"): _plain(RplidarNode),
    ("face_detector", "face_detector"): _plain(FaceDetectorNode),
}
