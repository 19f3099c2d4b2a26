"""Broadcasters and listener: on a fake node (always) and on roverlab.core (when it runs)."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

import pytest

from roverlab.core.time import Time
from roverlab.geometry import Transform3
from roverlab.tf import (
    TF_MESSAGE_TYPE,
    Buffer,
    StaticTransformBroadcaster,
    TransformBroadcaster,
    TransformListener,
    tf_message,
    transform_to_msg,
)


def _core_context() -> Any:
    """roverlab.core.Context, or None while the runtime cannot be imported."""
    try:
        return importlib.import_module("roverlab.core").Context
    except (ImportError, AttributeError):
        return None


Context = _core_context()
needs_core = pytest.mark.skipif(Context is None, reason="roverlab.core.Context not available")


def s(seconds: float) -> Time:
    return Time.from_seconds(seconds)


def ts(parent: str, child: str, seconds: float, x: float = 0.0) -> Any:
    return transform_to_msg(parent, child, s(seconds), Transform3((x, 0.0, 0.0)))


# ------------------------------------------------------------------ fake node
class FakePublisher:
    def __init__(self) -> None:
        self.sent: list[Any] = []

    def publish(self, msg: Any) -> None:
        self.sent.append(msg)


class FakeLogger:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def warning(self, msg: str) -> None:
        self.lines.append(("warning", msg))

    def error(self, msg: str) -> None:
        self.lines.append(("error", msg))


class FakeClock:
    def __init__(self) -> None:
        self.t = Time(0)

    def now(self) -> Time:
        return self.t


class FakeNode:
    def __init__(self) -> None:
        self.publishers: dict[str, tuple[Any, Any, FakePublisher]] = {}
        self.subscriptions: dict[str, tuple[Any, Callable[[Any], None], Any]] = {}
        self.clock = FakeClock()
        self.logger = FakeLogger()

    def create_publisher(self, msg_type: Any, topic: str, qos: Any) -> FakePublisher:
        pub = FakePublisher()
        self.publishers[topic] = (msg_type, qos, pub)
        return pub

    def create_subscription(
        self, msg_type: Any, topic: str, callback: Callable[[Any], None], qos: Any
    ) -> object:
        self.subscriptions[topic] = (msg_type, callback, qos)
        return object()

    def get_clock(self) -> FakeClock:
        return self.clock

    def get_logger(self) -> FakeLogger:
        return self.logger


def test_broadcaster_publishes_tf_messages_on_tf() -> None:
    node = FakeNode()
    br = TransformBroadcaster(node)
    msg_type, qos, pub = node.publishers["/tf"]
    assert msg_type == TF_MESSAGE_TYPE and qos == 100
    br.send_transform(ts("odom", "base_link", 1.0))
    br.send_transform([ts("map", "odom", 1.0), ts("odom", "base_link", 1.1)])
    assert [len(m.transforms) for m in pub.sent] == [1, 2]
    assert pub.sent[1].transforms[1].child_frame_id == "base_link"


def test_static_broadcaster_accumulates_one_latched_message() -> None:
    node = FakeNode()
    br = StaticTransformBroadcaster(node)
    _, qos, pub = node.publishers["/tf_static"]
    assert qos.depth == 1 and qos.durability == "transient_local"
    br.send_transform(ts("base_link", "laser", 0.0, x=0.1))
    br.send_transform([ts("base_link", "imu", 0.0), ts("base_link", "laser", 0.0, x=0.2)])
    last = pub.sent[-1]
    assert [t.child_frame_id for t in last.transforms] == ["laser", "imu"]
    assert last.transforms[0].transform.translation.x == 0.2


def test_listener_feeds_the_buffer() -> None:
    node = FakeNode()
    buf = Buffer()
    TransformListener(buf, node)
    _, on_tf, qos = node.subscriptions["/tf"]
    _, on_static, static_qos = node.subscriptions["/tf_static"]
    assert qos == 100 and static_qos.durability == "transient_local"
    on_tf(tf_message([ts("/odom", "base_link", 1.0, x=1.0), ts("odom", "base_link", 2.0, x=2.0)]))
    on_static(tf_message([ts("base_link", "laser", 0.0, x=0.5)]))
    t, _ = buf.lookup_transform("odom", "laser", s(1.5))
    assert t.translation[0] == pytest.approx(2.0)
    assert "broadcaster: 'default_authority'" in buf.all_frames_as_yaml()
    buf.clear()
    assert buf.can_transform("base_link", "laser", s(9.0))  # static


def test_listener_logs_bad_and_old_data_and_goes_on() -> None:
    node = FakeNode()
    buf = Buffer(cache_time=1.0)
    TransformListener(buf, node)
    _, on_tf, _ = node.subscriptions["/tf"]
    bad = transform_to_msg("odom", "base_link", s(1.0), Transform3((float("nan"), 0, 0)))
    on_tf(tf_message([bad, ts("odom", "base_link", 10.0), ts("odom", "base_link", 5.0)]))
    levels = [level for level, _ in node.logger.lines]
    assert levels == ["error", "warning"]
    assert "TF_NAN_INPUT" in node.logger.lines[0][1]
    assert "TF_OLD_DATA" in node.logger.lines[1][1]
    assert buf.can_transform("odom", "base_link", s(10.0))


def test_listener_clears_the_buffer_when_time_jumps_back() -> None:
    node = FakeNode()
    buf = Buffer()
    TransformListener(buf, node)
    _, on_tf, _ = node.subscriptions["/tf"]
    node.clock.t = s(10.0)
    on_tf(tf_message([ts("odom", "base_link", 10.0)]))
    node.clock.t = s(2.0)  # e.g. a bag restarted
    on_tf(tf_message([ts("odom", "base_link", 2.0)]))
    assert any("jump back in time" in line for _, line in node.logger.lines)
    assert not buf.can_transform("odom", "base_link", s(10.0))
    assert buf.can_transform("odom", "base_link", s(2.0))


# ------------------------------------------------------------------ roverlab.core
@needs_core
def test_broadcast_and_listen_through_the_runtime() -> None:
    from roverlab.core import Node

    ctx = Context()
    talker = Node("tf_talker", context=ctx)
    listener_node = Node("tf_listener", context=ctx)
    buf = Buffer()
    TransformListener(buf, listener_node)
    br = TransformBroadcaster(talker)
    br.send_transform([ts("map", "odom", 1.0, x=1.0), ts("odom", "base_link", 1.0, x=2.0)])
    ctx.spin_for(0.05)
    t, stamp = buf.lookup_transform("map", "base_link", Time(0))
    assert t.translation[0] == pytest.approx(3.0) and stamp == s(1.0)


@needs_core
def test_late_listener_gets_all_static_transforms() -> None:
    from roverlab.core import Node

    ctx = Context()
    talker = Node("rsp", context=ctx)
    static = StaticTransformBroadcaster(talker)
    static.send_transform(ts("base_link", "laser", 0.0, x=0.3))
    ctx.spin_for(0.05)
    static.send_transform(ts("base_link", "imu", 0.0, x=-0.1))
    ctx.spin_for(0.05)
    buf = Buffer()
    TransformListener(buf, Node("late", context=ctx))
    ctx.spin_for(0.05)
    assert buf.lookup_transform("laser", "imu", Time(0))[0].translation[0] == pytest.approx(-0.4)
