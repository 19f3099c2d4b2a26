"""Services in one process: rclpy's semantics on the deterministic executor."""

from __future__ import annotations

import logging
import threading
from typing import Any

import pytest

from roverlab.core import Context, ServiceError, ServiceUnavailableError
from roverlab.msgs import UnknownTypeError, get_service_type

AddTwoInts = get_service_type("rospy_tutorials/AddTwoInts")


def _add(req: Any, resp: Any) -> Any:
    resp.sum = req.a + req.b
    return resp


@pytest.fixture
def ctx() -> Context:
    return Context()


def test_call_async_completes_on_the_executor(ctx: Context) -> None:
    ctx.create_node("server").create_service(AddTwoInts, "add_two_ints", _add)
    client = ctx.create_node("client").create_client(
        "rospy_tutorials/srv/AddTwoInts", "add_two_ints"
    )
    assert client.service_is_ready() and client.wait_for_service(0.0)
    future = client.call_async(AddTwoInts.Request(a=2, b=40))
    assert not future.done()  # the server runs when the executor does
    seen: list[int] = []
    future.add_done_callback(lambda f: seen.append(f.result().sum))
    assert ctx.spin_until_future_complete(future, timeout_sec=5)
    assert future.result().sum == 42
    ctx.spin_once(0.0)
    assert seen == [42]


def test_call_without_a_spinning_executor_runs_inline(ctx: Context) -> None:
    ctx.create_node("server").create_service("rospy_tutorials/AddTwoInts", "add", _add)
    client = ctx.create_node("client").create_client(AddTwoInts, "/add")
    assert client.call({"a": 1, "b": 2}).sum == 3


def test_call_from_another_thread_while_spinning(ctx: Context) -> None:
    ctx = Context(clock="wall")
    calls: list[str] = []

    def record(req: Any, resp: Any) -> Any:
        calls.append(threading.current_thread().name)
        return _add(req, resp)

    ctx.create_node("server").create_service(AddTwoInts, "add", record)
    client = ctx.create_node("client").create_client(AddTwoInts, "add")
    ctx.spin_in_thread()
    try:
        assert client.call(AddTwoInts.Request(a=5, b=6), timeout_sec=5).sum == 11
    finally:
        ctx.shutdown()
    assert calls == ["roverlab-executor"]


def test_a_raising_callback_is_an_error_for_the_caller_and_the_server_goes_on(
    ctx: Context, caplog: pytest.LogCaptureFixture
) -> None:
    fail = [True]

    def flaky(req: Any, resp: Any) -> Any:
        if fail[0]:
            fail[0] = False
            raise ValueError("no battery")
        return _add(req, resp)

    ctx.create_node("server").create_service(AddTwoInts, "flaky", flaky)
    client = ctx.create_node("client").create_client(AddTwoInts, "flaky")
    future = client.call_async({"a": 1, "b": 1})
    ctx.spin_until_future_complete(future)
    with pytest.raises(ServiceError, match=r"service '/flaky' failed: .*ValueError: no battery"):
        future.result()
    assert client.call({"a": 1, "b": 1}).sum == 2  # still serving


def test_a_callback_returning_the_wrong_thing_is_an_error(ctx: Context) -> None:
    ctx.create_node("server").create_service(AddTwoInts, "wrong", lambda req, resp: None)
    client = ctx.create_node("client").create_client(AddTwoInts, "wrong")
    with pytest.raises(ServiceError, match="expected rospy_tutorials/srv/AddTwoInts_Response"):
        client.call({})


def test_no_server(ctx: Context) -> None:
    client = ctx.create_node("client").create_client("std_srvs/Empty", "nobody")
    assert not client.service_is_ready()
    assert client.wait_for_service(timeout_sec=0.05) is False
    future = client.call_async({})
    assert future.done()
    with pytest.raises(ServiceUnavailableError, match="service '/nobody' is not available"):
        future.result()


def test_a_second_server_takes_over_until_destroyed(
    ctx: Context, caplog: pytest.LogCaptureFixture
) -> None:
    first = ctx.create_node("first").create_service(
        "std_srvs/Trigger", "who", lambda q, r: setattr(r, "message", "first") or r
    )
    with caplog.at_level(logging.WARNING, logger="roverlab"):
        second = ctx.create_node("second").create_service(
            "std_srvs/Trigger", "/who", lambda q, r: setattr(r, "message", "second") or r
        )
    assert "service '/who' was served by '/first': this node serves it now" in caplog.text
    client = ctx.create_node("client").create_client("std_srvs/Trigger", "who")
    assert client.call({}).message == "second"
    second.destroy()
    assert client.call({}).message == "first"
    first.destroy()
    assert not client.service_is_ready()


def test_type_mismatch(ctx: Context) -> None:
    node = ctx.create_node("server")
    node.create_service("std_srvs/Empty", "reset", lambda req, resp: resp)
    client = ctx.create_node("client").create_client("std_srvs/Trigger", "reset")
    with pytest.raises(
        ServiceError, match="is of type std_srvs/srv/Empty, not std_srvs/srv/Trigger"
    ):
        client.call({})
    other = ctx.create_node("c2").create_client("std_srvs/Trigger", "trigger")
    with pytest.raises(ServiceError, match="expected std_srvs/srv/Trigger_Request, got str"):
        other.call("please")
    with pytest.raises(UnknownTypeError, match="unknown service type"):
        node.create_service("std_srvs/Emty", "x", lambda q, r: r)


def test_names_resolve_like_topics_and_destroy(ctx: Context) -> None:
    node = ctx.create_node("amcl", namespace="robot1")
    srv = node.create_service("std_srvs/Empty", "global_localization", lambda q, r: r)
    assert srv.srv_name == "/robot1/global_localization"
    private = node.create_service("std_srvs/Empty", "~/reset", lambda q, r: r)
    assert private.srv_name == "/robot1/amcl/reset"
    client = ctx.create_node("c", namespace="robot1").create_client(
        "std_srvs/Empty", "global_localization"
    )
    assert client.service_is_ready()
    node.destroy_node()
    assert not client.service_is_ready()
    assert ctx.graph.services == {}


def test_call_async_is_deterministic_in_order(ctx: Context) -> None:
    order: list[int] = []

    def log(req: Any, resp: Any) -> Any:
        order.append(int(req.a))
        return _add(req, resp)

    ctx.create_node("server").create_service(AddTwoInts, "log", log)
    client = ctx.create_node("client").create_client(AddTwoInts, "log")
    futures = [client.call_async({"a": i, "b": 0}) for i in range(5)]
    ctx.spin_for(0.1)
    assert order == [0, 1, 2, 3, 4]
    assert [f.result().sum for f in futures] == [0, 1, 2, 3, 4]


def test_cancelled_future_ignores_the_answer(ctx: Context) -> None:
    ctx.create_node("server").create_service(AddTwoInts, "add", _add)
    client = ctx.create_node("client").create_client(AddTwoInts, "add")
    future = client.call_async({"a": 1, "b": 1})
    client.remove_pending_request(future)
    ctx.spin_for(0.1)
    assert future.done() and future.cancelled() and future.result() is None
