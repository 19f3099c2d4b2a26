"""Topic statistics across processes (ROS 1's ``getBusStats``): each process answers how
many messages it published per topic, under its own key, so one query tells them apart."""

from __future__ import annotations

import pytest

from roverlab.core import Context
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.core.transport.zenoh_stats import query_topic_counts
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh


def test_each_process_answers_its_own_counts() -> None:
    ep = f"tcp/127.0.0.1:{free_port()}"
    robot, laptop = Context(clock="wall"), Context(clock="wall")
    robot_t = ZenohTransport(ZenohOptions(listen=(ep,)))
    robot.add_transport(robot_t)
    laptop_t = ZenohTransport(ZenohOptions(listen=(), connect=(ep,)))
    laptop.add_transport(laptop_t)
    try:
        chatter = robot.create_node("talker").create_publisher(String, "/chatter", 10)
        cmd = laptop.create_node("teleop").create_publisher(String, "/cmd", 10)
        laptop.create_node("quiet").create_subscription(String, "/chatter", lambda m: None, 1)
        for i in range(7):
            chatter.publish(String(data=str(i)))
        for _ in range(3):
            cmd.publish(String(data="go"))
        want = {robot_t.zid: {"/chatter": 7}, laptop_t.zid: {"/cmd": 3}}
        got: dict[str, dict[str, int]] = {}

        def answered() -> bool:
            got.update(query_topic_counts(laptop_t.session))
            return all(
                got.get(z, {}).get(t) == n for z, counts in want.items() for t, n in counts.items()
            )

        wait_until(answered, 10.0)
        assert {z: {t: got[z][t] for t in want[z]} for z in want} == want
        assert "/chatter" not in got[laptop_t.zid]  # subscribed there, not published
    finally:
        laptop.shutdown()
        robot.shutdown()
