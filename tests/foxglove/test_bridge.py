"""A client speaking the Foxglove WebSocket protocol subscribes to /scan and publishes
/cmd_vel through ``FoxgloveBridge``; off loopback the token relay guards it."""

from __future__ import annotations

import json
import struct
import time
from typing import Any

import numpy as np
import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect

from roverlab.core import Context
from roverlab.foxglove import FoxgloveBridge
from roverlab.foxglove.proxy import TokenRelay
from roverlab.msgs import classes as mc
from roverlab.msgs import deserialize, serialize
from roverlab.msgs.factory import LaserScan, Twist

PROTO = "foxglove.sdk.v1"


def _json(ws: ClientConnection, op: str, timeout: float = 5.0) -> dict[str, Any]:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        frame = ws.recv(timeout=max(0.01, deadline - time.monotonic()))
        if isinstance(frame, str):
            msg = json.loads(frame)
            if msg.get("op") == op:
                return dict(msg)
    raise AssertionError(f"no {op!r} within {timeout} s")


def _speak(url: str, ctx: Context, twists: list[Any], **kw: Any) -> None:
    with connect(url, subprotocols=[PROTO], **kw) as ws:  # type: ignore[list-item]
        assert ws.subprotocol == PROTO
        info = _json(ws, "serverInfo")
        assert "clientPublish" in info["capabilities"]
        assert "cdr" in info["supportedEncodings"]
        channels: dict[str, Any] = {}
        deadline = time.monotonic() + 5
        while "/scan" not in channels and time.monotonic() < deadline:
            for ch in _json(ws, "advertise")["channels"]:
                channels[ch["topic"]] = ch
        scan_ch = channels["/scan"]
        assert scan_ch["encoding"] == "cdr" and scan_ch["schemaEncoding"] == "ros2msg"
        assert scan_ch["schemaName"] == "sensor_msgs/msg/LaserScan"
        assert "float32[] ranges" in scan_ch["schema"]
        ws.send(
            json.dumps(
                {"op": "subscribe", "subscriptions": [{"id": 7, "channelId": scan_ch["id"]}]}
            )
        )
        # binary messageData: op 1, subscription id, log time, CDR payload
        while True:
            frame = ws.recv(timeout=5)
            if isinstance(frame, bytes) and frame[0] == 1:
                break
        sub_id, _t = struct.unpack_from("<IQ", frame, 1)
        scan = deserialize(frame[13:], "sensor_msgs/msg/LaserScan")
        assert sub_id == 7 and scan.header.frame_id == "laser" and len(scan.ranges) == 360
        # client publishing: advertise /cmd_vel, send a CDR Twist
        ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 3, "topic": "/cmd_vel", "encoding": "cdr",
             "schemaName": "geometry_msgs/msg/Twist"}]}))  # fmt: skip
        time.sleep(0.3)
        ws.send(b"\x01" + struct.pack("<I", 3) + serialize(Twist(linear_x=0.3, angular_z=-0.2)))
        deadline = time.monotonic() + 5
        while not twists and time.monotonic() < deadline:
            time.sleep(0.05)
    assert twists and twists[0].linear.x == pytest.approx(0.3)
    assert twists[0].angular.z == pytest.approx(-0.2)


@pytest.fixture
def system() -> Any:
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("robot")
    pub = node.create_publisher(mc.LaserScan, "/scan", 10)
    twists: list[Any] = []
    node.create_subscription(mc.Twist, "/cmd_vel", twists.append, 10)
    scan = LaserScan(header_frame_id="laser", angle_min=-np.pi, angle_max=np.pi,
                     angle_increment=2 * np.pi / 360, range_max=10.0,
                     ranges=np.full(360, 2.0, np.float32))  # fmt: skip
    node.create_timer(0.1, lambda: pub.publish(scan))
    ctx.spin_in_thread()
    yield ctx, twists
    ctx.shutdown()


def test_client_subscribes_scan_and_publishes_cmd_vel(system: Any) -> None:
    ctx, twists = system
    bridge = FoxgloveBridge(ctx, "127.0.0.1", 0)
    try:
        assert "/scan" in bridge.topics
        _speak(f"ws://127.0.0.1:{bridge.port}", ctx, twists)
        assert bridge.received == 1
    finally:
        bridge.stop()


def test_token_relay_off_loopback(system: Any) -> None:
    ctx, twists = system
    bridge = FoxgloveBridge(ctx, "127.0.0.1", 0)
    relay = TokenRelay("127.0.0.1", 0, bridge.port, "s3cret")
    try:
        with pytest.raises(InvalidStatus, match="403"):
            connect(f"ws://127.0.0.1:{relay.port}/?token=wrong", subprotocols=[PROTO])  # type: ignore[list-item]
        with pytest.raises(InvalidStatus, match="403"):
            connect(f"ws://127.0.0.1:{relay.port}/", subprotocols=[PROTO])  # type: ignore[list-item]
        _speak(f"ws://127.0.0.1:{relay.port}/?token=s3cret", ctx, twists)
    finally:
        relay.stop()
        bridge.stop()
