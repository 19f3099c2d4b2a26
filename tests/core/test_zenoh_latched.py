"""Latched topics across processes: a late subscriber gets the last message once, then the
new ones in order, however its history query's reply and the live messages interleave."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

from roverlab.core import Context, QoSProfile
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.core.transport.zenoh_latched import LatchedInbox, Source, parse_tag, tag
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh

LATCHED = QoSProfile(depth=1, durability="transient_local")


class _HeldQuery:
    """A history query whose replies are held back until :meth:`release` (the reply's
    content is taken when the query arrives, as always; only its delivery is late)."""

    def __init__(self, query: Any) -> None:
        self.query = query
        self.key_expr = query.key_expr
        self.replies: list[tuple[Any, Any, dict[str, Any]]] = []

    def reply(self, key: Any, payload: Any, **kwargs: Any) -> None:
        self.replies.append((key, payload, kwargs))

    def release(self) -> None:
        for key, payload, kwargs in self.replies:
            self.query.reply(key, payload, **kwargs)
        self.query = None  # dropping the query ends it


@pytest.fixture
def pair() -> Iterator[tuple[Context, ZenohTransport, Context]]:
    ep = f"tcp/127.0.0.1:{free_port()}"
    robot = Context(clock="wall")
    robot_t = ZenohTransport(ZenohOptions(listen=(ep,)))
    robot.add_transport(robot_t)
    laptop = Context(clock="wall")
    laptop.add_transport(ZenohTransport(ZenohOptions(listen=(), connect=(ep,))))
    robot.spin_in_thread()
    laptop.spin_in_thread()
    yield robot, robot_t, laptop
    laptop.shutdown()
    robot.shutdown()


def test_a_late_history_reply_does_not_undo_newer_messages(
    pair: tuple[Context, ZenohTransport, Context], monkeypatch: pytest.MonkeyPatch
) -> None:
    robot, robot_t, laptop = pair
    held: list[_HeldQuery] = []
    answer = robot_t._on_latched_query

    def hold(topic: Any, query: Any) -> None:
        q = _HeldQuery(query)
        answer(topic, q)
        held.append(q)

    monkeypatch.setattr(robot_t, "_on_latched_query", hold)
    pub = robot.create_node("move_base").create_publisher(String, "/status", LATCHED)
    pub.publish(String(data="old"))
    got: list[str] = []
    sub = laptop.create_node("client").create_subscription(
        String, "/status", lambda m: got.append(m.data), 10
    )
    assert wait_until(lambda: held and pub.topic.remote_send is not None, timeout=5)
    pub.publish(String(data="new"))
    assert wait_until(lambda: got == ["new"], timeout=5), got
    held[0].release()  # the history ("old", taken when the query came) arrives last
    time.sleep(0.3)
    pub.publish(String(data="newer"))
    assert wait_until(lambda: got[-1:] == ["newer"], timeout=5)
    assert got == ["new", "newer"]
    # a later subscription in the laptop's process gets the last message, not the reply's
    later: list[str] = []
    laptop.create_node("later").create_subscription(
        String, "/status", lambda m: later.append(m.data), 10
    )
    assert wait_until(lambda: later == ["newer"], timeout=5), later
    assert sub.received == 2


def test_a_history_reply_before_any_live_message_is_delivered_once(
    pair: tuple[Context, ZenohTransport, Context],
) -> None:
    robot, _, laptop = pair
    pub = robot.create_node("map_server").create_publisher(String, "/map", LATCHED)
    pub.publish(String(data="the map"))
    got: list[str] = []
    laptop.create_node("rviz").create_subscription(String, "/map", lambda m: got.append(m.data), 10)
    assert wait_until(lambda: got == ["the map"], timeout=5)
    pub.publish(String(data="the map, updated"))
    assert wait_until(lambda: len(got) == 2, timeout=5)
    time.sleep(0.3)
    assert got == ["the map", "the map, updated"]


def test_the_inbox_keeps_order_per_process() -> None:
    inbox = LatchedInbox()
    a, b = "a" * 32, "b" * 32
    assert inbox.accept(Source(a, 3, 1), "a3")
    assert not inbox.accept(Source(a, 3, 1), "a3 again")
    assert not inbox.accept(Source(a, 2, 1), "a2")
    assert inbox.accept(Source(b, 1, 2), "b1")  # another process has its own numbers
    assert inbox.accept(Source(b, 2, 2), "b2")
    assert inbox.accept(Source(a, 5, 1), "a5")
    assert inbox.replay() == ["a5", "b1", "b2"]
    assert parse_tag(tag(a, 7, 2)) == Source(a, 7, 2)
    assert parse_tag(b"not a tag") is None and parse_tag(None) is None
