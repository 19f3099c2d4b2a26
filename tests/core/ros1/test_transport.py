"""The ROS 1 transport: a roverlab context's nodes in a real ROS 1 graph (Debian's
rosmaster, rospy, rostopic), messages in ROS 1's bytes both ways, latched topics."""

from __future__ import annotations

import time
from typing import Any

from roverlab.core.context import Context
from roverlab.core.qos import QoSProfile
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.msgs import classes as mc
from tests.core.ros1.conftest import SCRIPTS, run_ros, start_ros, stop


def test_roverlab_nodes_are_ros1_nodes(real_master: str) -> None:
    ctx = Context(clock="wall")
    transport = Ros1Transport(real_master)
    ctx.add_transport(transport)
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/ros_in")
    try:
        node = ctx.create_node("rl_node")
        got: list[Any] = []
        node.create_subscription(mc.String, "/ros_in", got.append, 10)
        latched = QoSProfile(depth=1, durability="transient_local")
        node.create_publisher(mc.String, "/rl_latched", latched).publish(mc.String(data="kept"))
        pub = node.create_publisher(mc.String, "/rl_out", 10)
        thread = ctx.spin_in_thread()
        listener = start_ros(
            real_master, "/usr/bin/python3", str(SCRIPTS / "listener.py"), "/rl_out", "3"
        )
        end = time.monotonic() + 30
        while listener.poll() is None and time.monotonic() < end:
            pub.publish(mc.String(data="from roverlab"))
            time.sleep(0.05)
        assert listener.returncode == 0
        echo = run_ros(real_master, "/usr/bin/rostopic", "echo", "-n", "1", "/rl_latched")
        assert 'data: "kept"' in echo.stdout
        topics = run_ros(real_master, "/usr/bin/rostopic", "list").stdout.split()
        assert {"/rl_out", "/rl_latched", "/ros_in"} <= set(topics)
        assert len(got) >= 3 and got[-1].data.startswith("hello ")
        assert transport.received >= 3 and transport.sent >= 3
        ctx.shutdown()
        thread.join(5)
    finally:
        stop(talker)
        transport.close()
