"""Nodes in two processes talking over Zenoh on 127.0.0.1."""

from __future__ import annotations

import itertools
import time
from typing import Any

import pytest

from roverlab.core import Context, ParameterError
from roverlab.core.transport.daemon import connect_context
from roverlab.core.transport.zenoh import (
    ZenohOptions,
    ZenohTransport,
    query_graph,
    query_parameters,
)
from roverlab.msgs import String
from tests.helpers.net import free_port, wait_until

pytestmark = pytest.mark.zenoh


def test_messages_cross_processes(node_proc: Any) -> None:
    node_proc("talker")
    ctx = Context(clock="wall")
    got: list[str] = []
    ctx.create_node("listener").create_subscription(
        String, "/chatter", lambda m: got.append(m.data), 100
    )
    connect_context(ctx)
    ctx.spin_in_thread()
    try:
        assert wait_until(lambda: len(got) >= 10)
    finally:
        ctx.shutdown()
    numbers = [int(s.rsplit(" ", 1)[1]) for s in got]
    assert all(s.startswith("hello world ") for s in got)
    assert numbers == sorted(numbers) and len(set(numbers)) == len(numbers)


def test_round_trip_and_graph(node_proc: Any) -> None:
    node_proc("pong")
    ctx = Context(clock="wall")
    node = ctx.create_node("pinger")
    pub = node.create_publisher(String, "/ping", 100)
    got: list[str] = []
    node.create_subscription(String, "/pong", lambda m: got.append(m.data), 100)
    transport = connect_context(ctx)
    ctx.spin_in_thread()
    try:
        assert wait_until(lambda: pub.topic.remote_send is not None)
        for i in range(20):
            pub.publish(String(data=f"p{i}"))
        assert wait_until(lambda: len(got) == 20)
        assert got == [f"p{i}" for i in range(20)]

        def graph_complete() -> bool:
            # a liveliness query answers within its 1 s only on a machine with time to
            # spare (it came back empty at load 6 in a full run): ask until it has both
            ents = [e for e in query_graph(transport.session) if e.zid != transport.zid]
            return any(e.kind == "node" and e.node == "/proc_pong" for e in ents) and any(
                e.kind == "subscription"
                and e.topic == "/ping"
                and e.typename == "std_msgs/msg/String"
                for e in ents
            )

        assert wait_until(graph_complete, timeout=10)
        # remote parameters
        session = transport.session
        assert query_parameters(session, "proc_pong", {"op": "get", "name": "gain"})["value"] == 1.5
        assert query_parameters(session, "proc_pong", {"op": "set", "name": "gain", "value": 2})[
            "ok"
        ]
        assert query_parameters(session, "proc_pong", {"op": "get", "name": "gain"})["value"] == 2.0
        bad = query_parameters(session, "proc_pong", {"op": "set", "name": "gain", "value": "x"})
        assert "type double" in bad["error"]
        with pytest.raises(ParameterError, match="not found"):
            query_parameters(session, "nobody", {"op": "dump"}, timeout_s=0.5)
    finally:
        ctx.shutdown()


def test_clock_crosses_processes(node_proc: Any) -> None:
    node_proc("clock")
    ctx = Context(clock="external")
    fired: list[int] = []
    ctx.create_node("follower").create_timer(0.1, lambda: fired.append(ctx.now().nanoseconds))
    connect_context(ctx)
    ctx.spin_in_thread()
    try:
        assert wait_until(lambda: len(fired) >= 5)
    finally:
        ctx.shutdown()
    assert ctx.now().nanoseconds > 0
    # /clock arrives every 10 ms of sim time; a 0.1 s timer fires once per 0.1 s of it
    # (periods missed before the first /clock are skipped, as rcl does)
    steps = [b - a for a, b in itertools.pairwise(fired[1:])]
    assert steps and all(50_000_000 <= s <= 200_000_000 for s in steps), steps
    assert abs(sum(steps) / len(steps) - 100_000_000) < 20_000_000


def test_latched_topic_reaches_late_remote_subscriber(node_proc: Any) -> None:
    node_proc("latched")
    ctx = Context(clock="wall")
    got: list[str] = []
    ctx.create_node("late").create_subscription(String, "/map", lambda m: got.append(m.data), 10)
    connect_context(ctx)
    ctx.spin_in_thread()
    try:
        assert wait_until(lambda: got == ["the map"], timeout=5)
    finally:
        ctx.shutdown()


def test_user_password_auth_and_explicit_endpoints() -> None:
    ep = f"tcp/127.0.0.1:{free_port()}"
    server_ctx = Context(clock="wall")
    pub = server_ctx.create_node("robot").create_publisher(String, "/secret", 10)
    server_ctx.add_transport(
        ZenohTransport(ZenohOptions(listen=(ep,), user="robot", password="s3cret"))
    )
    good_ctx = Context(clock="wall")
    good: list[str] = []
    good_ctx.create_node("op").create_subscription(
        String, "/secret", lambda m: good.append(m.data), 10
    )
    good_ctx.add_transport(
        ZenohTransport(ZenohOptions(listen=(), connect=(ep,), user="robot", password="s3cret"))
    )
    bad_ctx = Context(clock="wall")
    bad: list[str] = []
    bad_ctx.create_node("intruder").create_subscription(
        String, "/secret", lambda m: bad.append(m.data), 10
    )
    bad_ctx.add_transport(
        ZenohTransport(ZenohOptions(listen=(), connect=(ep,), user="robot", password="wrong"))
    )
    for c in (server_ctx, good_ctx, bad_ctx):
        c.spin_in_thread()
    try:
        assert wait_until(lambda: pub.topic.remote_send is not None, timeout=5)
        for _ in range(5):
            pub.publish(String(data="ok"))
            time.sleep(0.05)
        assert wait_until(lambda: len(good) >= 3, timeout=5)
        assert bad == []
    finally:
        for c in (server_ctx, good_ctx, bad_ctx):
            c.shutdown()


def test_service_call_across_processes(node_proc: Any) -> None:
    from roverlab.core import ServiceError
    from roverlab.msgs import get_service_type

    node_proc("services")
    ctx = Context(clock="wall")
    node = ctx.create_node("caller")
    transport = connect_context(ctx)
    add = node.create_client("rospy_tutorials/AddTwoInts", "/add_two_ints")
    fail = node.create_client("std_srvs/Trigger", "/fail")
    wrong = node.create_client("std_srvs/Empty", "/add_two_ints")
    missing = node.create_client("std_srvs/Empty", "/nobody_serves_this")
    ctx.spin_in_thread()
    try:
        assert add.wait_for_service(timeout_sec=10)
        assert fail.wait_for_service(timeout_sec=10)
        req = get_service_type("rospy_tutorials/AddTwoInts").Request(a=20, b=22)
        assert add.call(req, timeout_sec=5).sum == 42
        future = add.call_async({"a": -1, "b": 1})
        assert future.wait(5) and future.result().sum == 0
        # a raising callback: one clear error for the caller; the server keeps serving
        with pytest.raises(
            ServiceError, match=r"service '/fail' failed: .*RuntimeError: the callback broke"
        ):
            fail.call({}, timeout_sec=5)
        with pytest.raises(ServiceError, match="takes rospy_tutorials/srv/AddTwoInts_Request"):
            wrong.call({}, timeout_sec=5)
        assert add.call({"a": 1, "b": 2}, timeout_sec=5).sum == 3
        assert missing.wait_for_service(timeout_sec=0.3) is False
        wanted = {
            ("/add_two_ints", "rospy_tutorials/srv/AddTwoInts"),
            ("/fail", "std_srvs/srv/Trigger"),
        }
        assert wait_until(
            lambda: (
                wanted
                <= {
                    (e.topic, e.typename)
                    for e in query_graph(transport.session)
                    if e.kind == "service"
                }
            ),
            timeout=10,
        )
    finally:
        ctx.shutdown()


def test_a_second_clock_source_is_warned_about(
    node_proc: Any, caplog: pytest.LogCaptureFixture
) -> None:
    node_proc("clock")  # a paced simulation publishing /clock elsewhere on the machine
    ctx = Context(clock="paced", rate=1.0)  # this process publishes /clock too
    with caplog.at_level("WARNING", logger="roverlab"):
        connect_context(ctx)
        ctx.spin_in_thread()
        try:
            assert wait_until(lambda: "a second /clock source" in caplog.text, timeout=10)
        finally:
            ctx.shutdown()
    assert "/proc_clock" in caplog.text or "/clock_publisher" in caplog.text
    assert "ROVERLAB_DOMAIN_ID" in caplog.text
