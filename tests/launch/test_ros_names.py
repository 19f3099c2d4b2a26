"""Nodes keep the names they have in ROS: ``rosrun`` names a node as its source's
``ros::init`` does, and a node waiting for ``/robot_description`` waits under its own name."""

from __future__ import annotations

from pathlib import Path

from roverlab.cli.run import _resolve
from roverlab.core import Context, QoSProfile
from roverlab.description.node import RobotStatePublisher
from roverlab.launch import build_launch
from roverlab.msgs import classes as mc

URDF = """<robot name="r">
  <link name="base_link"/><link name="laser"/>
  <joint name="j" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0.1 0 0.2"/></joint>
</robot>"""


def test_rosrun_names_nodes_as_their_ros_sources_do() -> None:
    names = {
        ("usb_cam", "usb_cam_node"): "usb_cam",  # usb_cam_node.cpp: ros::init(..., "usb_cam")
        ("rplidar_ros", "rplidarNode"): "rplidar_node",
        ("hector_mapping", "hector_mapping"): "hector_slam",
        ("map_server", "map_server"): "map_server",
        ("amcl", "amcl"): "amcl",
    }
    for (pkg, type_), name in names.items():
        _, spec, _ = _resolve([pkg, type_])
        assert spec is not None and spec.name == name, (pkg, type_, spec)
    _, spec, _ = _resolve(["usb_cam", "usb_cam_node", "__name:=front_cam"])
    assert spec is not None and spec.name == "front_cam"


def test_a_node_waiting_for_the_robot_description_keeps_its_name(tmp_path: Path) -> None:
    launch_file = tmp_path / "rsp.launch"
    launch_file.write_text(
        '<launch><node pkg="robot_state_publisher" type="robot_state_publisher" '
        'name="robot_state_publisher"/></launch>\n'
    )
    ctx = Context(clock="sim")
    try:
        build_launch(launch_file, context=ctx)
        assert sorted(n for n in ctx.nodes if "clock" not in n) == ["/robot_state_publisher"]
        publisher = ctx.create_node("description_publisher")
        latched = QoSProfile(depth=1, durability="transient_local")
        publisher.create_publisher(mc.String, "/robot_description", latched).publish(
            mc.String(data=URDF)
        )
        ctx.spin_for(0.1)
        rsp = ctx.nodes["/robot_state_publisher"]
        assert isinstance(rsp, RobotStatePublisher)  # the waiter handed its name over
        assert not [n for n in ctx.nodes if "waiting" in n]
    finally:
        ctx.shutdown()
