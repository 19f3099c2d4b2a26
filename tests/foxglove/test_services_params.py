"""Services and parameters through ``FoxgloveBridge``, by a client speaking the Foxglove
WebSocket protocol: the bridge in the nodes' process, and (as ``roverlab foxglove`` runs)
in another process's context reaching the nodes over Zenoh."""

from __future__ import annotations

import json
import struct
import time
from collections.abc import Iterator
from typing import Any

import pytest
from websockets.sync.client import ClientConnection, connect

from roverlab.cli.common import Connection, NetworkOptions
from roverlab.core import Context
from roverlab.core.transport.daemon import connect_context
from roverlab.foxglove import FoxgloveBridge
from roverlab.msgs import deserialize, get_service_type, serialize

from .test_bridge import PROTO, _json

ADD = get_service_type("example_interfaces/srv/AddTwoInts")


def _robot(ctx: Context) -> None:
    node = ctx.create_node("robot")
    node.declare_parameter("max_speed", 0.5)
    node.declare_parameter("count", 3)
    node.declare_parameter("frame", "base_link")
    cleared: list[int] = []

    def add(req: Any, resp: Any) -> Any:
        resp.sum = req.a + req.b
        return resp

    def clear(req: Any, resp: Any) -> Any:
        cleared.append(1)
        return resp

    def broken(req: Any, resp: Any) -> Any:
        raise RuntimeError("costmap locked")

    node.create_service("example_interfaces/srv/AddTwoInts", "/add_two_ints", add)
    node.create_service("std_srvs/srv/Empty", "/move_base/clear_costmaps", clear)
    node.create_service("std_srvs/srv/Empty", "/broken", broken)
    ctx.robot_node = node  # type: ignore[attr-defined]
    ctx.cleared = cleared  # type: ignore[attr-defined]


@pytest.fixture(params=["local", "remote"])
def served(request: Any) -> Iterator[tuple[Context, FoxgloveBridge]]:
    ctx = Context(clock="wall", publish_clock=False)
    if request.param == "local":
        _robot(ctx)
        ctx.spin_in_thread()
        bridge = FoxgloveBridge(ctx, "127.0.0.1", 0)
        yield ctx, bridge
        bridge.stop()
        ctx.shutdown()
        return
    request.getfixturevalue("daemon")
    connect_context(ctx)
    _robot(ctx)
    ctx.spin_in_thread()
    with Connection(NetworkOptions()) as conn:
        conn.context.spin_in_thread()
        bridge = FoxgloveBridge(conn.context, "127.0.0.1", 0, remote_graph=conn.graph)
        yield ctx, bridge
        bridge.stop()
    ctx.shutdown()


def _call(ws: ClientConnection, service_id: int, call_id: int, payload: bytes) -> Any:
    """A binary service call request (op 2); the response (op 3) payload, or the failure."""
    enc = b"cdr"
    ws.send(b"\x02" + struct.pack("<III", service_id, call_id, len(enc)) + enc + payload)
    deadline = time.monotonic() + 15
    while time.monotonic() < deadline:
        frame = ws.recv(timeout=15)
        if isinstance(frame, bytes) and frame[0] == 3:
            sid, cid, n = struct.unpack_from("<III", frame, 1)
            assert (sid, cid) == (service_id, call_id) and frame[13 : 13 + n] == b"cdr"
            return frame[13 + n :]
        if isinstance(frame, str) and json.loads(frame).get("op") == "serviceCallFailure":
            return json.loads(frame)
    raise AssertionError("no service call response")


def _params(ws: ClientConnection, op: str, rid: str, **kw: Any) -> dict[str, Any]:
    ws.send(json.dumps({"op": op, "id": rid, **kw}))
    while True:
        msg = _json(ws, "parameterValues", 10.0)
        if msg.get("id") == rid:
            return {p["name"]: p.get("value") for p in msg["parameters"]}


def test_client_calls_services_and_gets_sets_parameters(
    served: tuple[Context, FoxgloveBridge],
) -> None:
    ctx, bridge = served
    deadline = time.monotonic() + 10
    while len(bridge.services) < 3 and time.monotonic() < deadline:
        time.sleep(0.1)
    with connect(f"ws://127.0.0.1:{bridge.port}", subprotocols=[PROTO]) as ws:  # type: ignore[list-item]
        info = _json(ws, "serverInfo")
        assert {"services", "parameters"} <= set(info["capabilities"])
        services: dict[str, Any] = {}
        while not {"/add_two_ints", "/move_base/clear_costmaps", "/broken"} <= set(services):
            for s in _json(ws, "advertiseServices", 10.0)["services"]:
                services[s["name"]] = s
        add = services["/add_two_ints"]
        assert add["type"] == "example_interfaces/srv/AddTwoInts"
        assert add["request"]["encoding"] == "cdr" and "int64 a" in add["request"]["schema"]
        assert add["response"]["schemaEncoding"] == "ros2msg"
        assert "int64 sum" in add["response"]["schema"]
        # AddTwoInts: 2 + 40
        out = _call(ws, add["id"], 1, serialize(ADD.Request(a=2, b=40)))
        assert deserialize(out, "example_interfaces/srv/AddTwoInts_Response").sum == 42
        # std_srvs/Empty: move_base's clear_costmaps
        out = _call(ws, services["/move_base/clear_costmaps"]["id"], 2, b"\x00\x01\x00\x00")
        assert isinstance(out, bytes) and ctx.cleared == [1]  # type: ignore[attr-defined]
        # a server that raises: the protocol's call failure, with the reason
        fail = _call(ws, services["/broken"]["id"], 3, b"\x00\x01\x00\x00")
        assert fail["op"] == "serviceCallFailure" and fail["callId"] == 3
        assert "costmap locked" in fail["message"]
        # parameters: /node.param, all of them or by name
        every = _params(ws, "getParameters", "a", parameterNames=[])
        assert every["/robot.max_speed"] == 0.5 and every["/robot.frame"] == "base_link"
        assert _params(ws, "getParameters", "b", parameterNames=["/robot.count"]) == {
            "/robot.count": 3
        }
        got = _params(ws, "setParameters", "c", parameters=[
            {"name": "/robot.max_speed", "value": 0.8}])  # fmt: skip
        assert got == {"/robot.max_speed": 0.8}
        assert ctx.robot_node.get_parameter_value("max_speed") == 0.8  # type: ignore[attr-defined]
        # a value of the wrong type is refused: the old value stays
        got = _params(ws, "setParameters", "d", parameters=[
            {"name": "/robot.count", "value": "many"}])  # fmt: skip
        assert got == {"/robot.count": 3}
        assert ctx.robot_node.get_parameter_value("count") == 3  # type: ignore[attr-defined]
