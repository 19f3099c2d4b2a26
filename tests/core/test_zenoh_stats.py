"""What an exposed process tells others about its topics, and what it sends them.

* Topic statistics (ROS 1's ``getBusStats``): each process answers how many messages it
  published per topic, under its own key, so one query tells them apart.
* A publisher sends (and serialises) nothing while no other process subscribes, as a ROS
  publisher with no subscriber connections: camera drivers and the simulator check
  ``has_listeners`` to skip rendering and compressing images nobody reads.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from roverlab.core import Context
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.core.transport.zenoh_stats import query_topic_counts
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh

Pair = tuple[Context, ZenohTransport, Context, ZenohTransport]


@pytest.fixture
def pair() -> Iterator[Pair]:
    """Two processes' contexts, a robot and a laptop joined to it."""
    ep = f"tcp/127.0.0.1:{free_port()}"
    robot, laptop = Context(clock="wall"), Context(clock="wall")
    robot_t = ZenohTransport(ZenohOptions(listen=(ep,)))
    robot.add_transport(robot_t)
    laptop_t = ZenohTransport(ZenohOptions(listen=(), connect=(ep,)))
    laptop.add_transport(laptop_t)
    robot.spin_in_thread()
    yield robot, robot_t, laptop, laptop_t
    laptop.shutdown()
    robot.shutdown()


def test_each_process_answers_its_own_counts(pair: Pair) -> None:
    robot, robot_t, laptop, laptop_t = pair
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
        return all(got.get(z, {}).get(t) == n for z, c in want.items() for t, n in c.items())

    wait_until(answered, 10.0)
    assert {z: {t: got[z][t] for t in want[z]} for z in want} == want
    assert "/chatter" not in got[laptop_t.zid]  # subscribed there, not published


def test_no_remote_subscriber_no_listeners_until_one_comes(pair: Pair) -> None:
    robot, robot_t, laptop, _ = pair
    pub = robot.create_node("camera").create_publisher(String, "/image_raw", 1)
    assert not pub.has_listeners  # was True: the matching status object is truthy
    sent = robot_t.sent
    pub.publish(String(data="nobody"))
    assert robot_t.sent == sent
    laptop.create_node("viewer").create_subscription(String, "/image_raw", lambda m: None, 1)
    assert wait_until(lambda: pub.has_listeners, 10.0)
