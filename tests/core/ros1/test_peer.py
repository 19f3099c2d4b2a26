"""A roverlab process's ROS 1 peer against real rospy under Debian's real rosmaster:
the slave API (requestTopic, publisherUpdate, getBusInfo, getPid) and TCPROS both ways."""

from __future__ import annotations

import logging
import struct
import subprocess
import sys
import time
from typing import Any

import pytest

from roverlab.core.transport.ros1.peer import Ros1Peer, TopicSpec
from roverlab.core.transport.ros1.xmlrpc import call
from tests.core.ros1.conftest import SCRIPTS, run_ros, start_ros, stop, wait_master
from tests.helpers.net import free_port

STRING = TopicSpec("std_msgs/String", "992ce8a1687cec8c8bd883ec73ca41d1", "string data\n")


def _string(text: str) -> bytes:
    raw = text.encode()
    return struct.pack("<I", len(raw)) + raw


def test_peer_talks_tcpros_with_rospy_both_ways(
    real_master: str, caplog: pytest.LogCaptureFixture
) -> None:
    peer = Ros1Peer(real_master)
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/peer_in")
    try:
        got: list[bytes] = []
        peer.subscribe("/rl_listener", "/peer_in", STRING, got.append)
        peer.advertise("/rl_talker", "/peer_out", STRING, latched=True)
        peer.publish("/peer_out", _string("latched hello"))  # before anyone listens
        listener = start_ros(
            real_master, "/usr/bin/python3", str(SCRIPTS / "listener.py"), "/peer_out", "3"
        )
        end = time.monotonic() + 30
        while not peer.has_subscribers("/peer_out") and time.monotonic() < end:
            time.sleep(0.02)
        while listener.poll() is None and time.monotonic() < end:
            peer.publish("/peer_out", _string("hello from roverlab"))
            time.sleep(0.05)
        out = listener.stdout.read() if listener.stdout else ""
        assert listener.returncode == 0, out
        assert out.splitlines()[0] == "latched hello"
        end = time.monotonic() + 10
        while len(got) < 3 and time.monotonic() < end:
            time.sleep(0.05)
        assert len(got) >= 3 and got[-1][4:].startswith(b"hello ")
        # the wrong type: refused by rospy's publisher, one line naming both sides
        twist = TopicSpec("geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a")
        with caplog.at_level(logging.WARNING, logger="roverlab.ros1"):
            peer.subscribe("/rl_wrong", "/peer_in2", twist, got.append)
            talker2 = start_ros(
                real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/peer_in2"
            )
            end = time.monotonic() + 20
            while not caplog.records and time.monotonic() < end:
                time.sleep(0.05)
            time.sleep(1.0)  # reconnection attempts meanwhile: no second line
            stop(talker2)
        lines = [r.getMessage() for r in caplog.records]
        assert len(lines) == 1, lines
        assert "geometry_msgs/Twist/9f195f881246fdfa2798d1d3eebca84a" in lines[0]
        assert "[std_msgs/String]" in lines[0]  # rospy's publisher names its type only
        info = run_ros(real_master, "/usr/bin/rosnode", "info", "/rl_listener")
        assert "/peer_in [std_msgs/String]" in info.stdout and "Pid:" in info.stdout
        assert "Connections:" in info.stdout
        wrong = run_ros(real_master, "/usr/bin/rostopic", "info", "/peer_out")
        assert "/rl_talker" in wrong.stdout
    finally:
        stop(talker)
        peer.close()


def _roverlab_roscore(port: int) -> subprocess.Popen[bytes]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "roscore", "-p", str(port)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    wait_master(f"http://127.0.0.1:{port}/")
    return proc


def test_peer_registers_again_with_a_master_that_restarted() -> None:
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    master = _roverlab_roscore(port)
    peer = Ros1Peer(uri)
    try:
        peer.advertise("/rl_pub", "/kept", STRING)
        time.sleep(1.5)  # the peer learns the first master's pid
        stop(master)
        master = _roverlab_roscore(port)  # a new master: it knows nothing of /kept
        end = time.monotonic() + 10
        pubs: list[Any] = []
        while time.monotonic() < end:
            pubs, _, _ = call(uri, "getSystemState", "/test")
            if ["/kept", ["/rl_pub"]] in pubs:
                break
            time.sleep(0.1)
        assert ["/kept", ["/rl_pub"]] in pubs
    finally:
        peer.close()
        stop(master)
