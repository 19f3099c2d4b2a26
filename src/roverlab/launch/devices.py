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

from typing import Final

from roverlab.core import Node
from roverlab.drivers.arbotix.node import ArbotixDriver
from roverlab.drivers.serial_base.node import ArduinoBaseNode
from roverlab.launch.state import LaunchState, NodeFactory, build_node, node_factory
from roverlab.launch.xml import NodeSpec

__all__ = ["DEVICE_NODES"]


def _arbotix(state: LaunchState, spec: NodeSpec) -> Node | None:
    if spec.params.get("sim") is not True:
        state.warnings.append(
            f"{spec.source}: {spec.pkg}/{spec.type} not started: only sim: true (a fake base) "
            "is supported; a real ArbotiX board's protocol is not implemented"
        )
        return None
    return build_node(state, spec, ArbotixDriver)


ROBORTS_BASE_KEYS: Final = (
    "port",
    "baud",
    "timeout",
    "base_frame",
    "publish_odom_base_transform",
    "wheel_diameter",
    "wheel_track",
    "encoder_resolution",
    "gear_reduction",
    "base_controller_rate",
    "base_controller_timeout",
    "accel_limit",
    "motors_reversed",
    "odom_linear_scale_correction",
    "odom_angular_scale_correction",
    "Kp",
    "Kd",
    "Ki",
    "Ko",
)
"""The serial base's parameters that seed 002's ``roborts_base`` may set globally."""


def _roborts_base(state: LaunchState, spec: NodeSpec) -> Node:
    """Seed 002's ``roborts_base_node`` is the ros_arduino_bridge base: its parameters
    come from its private ones or, as the seed loads ``roborts_base_parameter.yaml`` at
    the top of the launch file, from the same names in the node's namespace."""
    params = dict(spec.params)
    for key in ROBORTS_BASE_KEYS:
        glob = spec.namespace.rstrip("/") + "/" + key
        if key not in params and glob in state.params:
            params[key] = state.params[glob]
    params.setdefault("use_base_controller", True)
    return build_node(state, spec, ArduinoBaseNode, parameter_overrides=params)


_SERIAL_BASE = "roverlab.drivers.serial_base.node:ArduinoBaseNode"

DEVICE_NODES: Final[dict[tuple[str, str], NodeFactory]] = {
    ("arbotix_python", "arbotix_driver"): _arbotix,
    ("usb_cam", "usb_cam_node"): node_factory("roverlab.drivers.usb_cam.node:UsbCamNode"),
    ("rplidar_ros", "rplidarNode"): node_factory("roverlab.drivers.rplidar.node:RplidarNode"),
    ("rplidar_ros", "rplidar_node"): node_factory("roverlab.drivers.rplidar.node:RplidarNode"),
    ("ros_arduino_python", "arduino_node.py"): node_factory(_SERIAL_BASE),
    ("roborts_base", "roborts_base_node"): _roborts_base,
    ("face_detector", "face_detector"): node_factory(
        "roverlab.perception.face_detector.node:FaceDetectorNode"
    ),
}
