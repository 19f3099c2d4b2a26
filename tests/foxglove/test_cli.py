"""``roverlab foxglove`` against other processes (Zenoh): topics of a `topic pub` reach a
Foxglove client; its /cmd_vel reaches a `topic echo`."""

from __future__ import annotations

import json
import struct
import sys
import time

from websockets.sync.client import connect

from roverlab.msgs import deserialize
from tests.foxglove.test_bridge import PROTO, _json
from tests.helpers.procs import Proc

RL = [sys.executable, "-m", "roverlab.cli"]


def test_foxglove_command_serves_other_processes(daemon: str) -> None:
    talker = Proc([*RL, "topic", "pub", "/chatter", "std_msgs/String", "{data: hi}", "-r", "10"])
    fox = Proc([*RL, "foxglove", "--port", "0"])
    echo = Proc([*RL, "topic", "echo", "/cmd_vel", "geometry_msgs/Twist", "--once"])
    try:
        url = fox.wait_line(lambda s: s.startswith("foxglove: ws://"), timeout=60).split()[1]
        with connect(url, subprotocols=[PROTO]) as ws:  # type: ignore[list-item]
            chans: dict[str, int] = {}
            deadline = time.monotonic() + 15
            while "/chatter" not in chans and time.monotonic() < deadline:
                chans.update({c["topic"]: c["id"] for c in _json(ws, "advertise", 15)["channels"]})
            sub = {"id": 1, "channelId": chans["/chatter"]}
            ws.send(json.dumps({"op": "subscribe", "subscriptions": [sub]}))
            while True:
                frame = ws.recv(timeout=10)
                if isinstance(frame, bytes) and frame[0] == 1:
                    break
            assert deserialize(frame[13:], "std_msgs/msg/String").data == "hi"
            ws.send(json.dumps({"op": "advertise", "channels": [
                {"id": 2, "topic": "/cmd_vel", "encoding": "json",
                 "schemaName": "geometry_msgs/msg/Twist"}]}))  # fmt: skip
            time.sleep(1.0)
            for _ in range(20):  # until the echo (another process) has it
                ws.send(b"\x01" + struct.pack("<I", 2) + json.dumps(
                    {"linear": {"x": 0.25}, "angular": {"z": 0.5}}).encode())  # fmt: skip
                if echo.popen.poll() is not None:
                    break
                time.sleep(0.3)
        out = echo.rest()
        assert "x: 0.25" in out and "z: 0.5" in out
    finally:
        for p in (echo, fox, talker):
            p.stop()
