"""A publisher exposed over Zenoh sends (and serialises) nothing while no other process
subscribes, as a ROS publisher with no subscriber connections: camera drivers and the
simulator check ``has_listeners`` to skip rendering and compressing images nobody reads."""

from __future__ import annotations

import pytest

from roverlab.core import Context
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh


def test_no_remote_subscriber_no_listeners_until_one_comes() -> None:
    ep = f"tcp/127.0.0.1:{free_port()}"
    robot, laptop = Context(clock="wall"), Context(clock="wall")
    robot_t = ZenohTransport(ZenohOptions(listen=(ep,)))
    robot.add_transport(robot_t)
    laptop.add_transport(ZenohTransport(ZenohOptions(listen=(), connect=(ep,))))
    robot.spin_in_thread()
    try:
        pub = robot.create_node("camera").create_publisher(String, "/image_raw", 1)
        assert not pub.has_listeners  # was True: the matching status object is truthy
        sent = robot_t.sent
        pub.publish(String(data="nobody"))
        assert robot_t.sent == sent
        laptop.create_node("viewer").create_subscription(String, "/image_raw", lambda m: None, 1)
        assert wait_until(lambda: pub.has_listeners, 10.0)
    finally:
        laptop.shutdown()
        robot.shutdown()
