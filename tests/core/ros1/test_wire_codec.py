"""The ROS 1 wire's parsers and bookkeeping, without any process: connection headers,
bounded framing, XML-RPC as ROS peers write it, names and the parameter tree."""

from __future__ import annotations

import math
import socket
import struct
import threading
import time
import xmlrpc.client

import pytest

from roverlab.core.transport.ros1.errors import HeaderError, ProtocolError
from roverlab.core.transport.ros1.framing import (
    FrameReader,
    PeerClosedError,
    read_frame,
    read_header,
)
from roverlab.core.transport.ros1.header import decode_header, encode_header
from roverlab.core.transport.ros1.names import namespace_of, resolve_name
from roverlab.core.transport.ros1.params import ParamTree, compute_updates
from roverlab.core.transport.ros1.tcpros import OutboundLink, check_md5
from roverlab.core.transport.ros1.xmlrpc import advertised_host, bind_host

# a subscriber's header as rospy 1.15 encodes it (rosgraph.network.encode_ros_handshake_header)
RO_SPY_HEADER = (
    b"\x9f\x00\x00\x00\x12\x00\x00\x00callerid=/listener'\x00\x00\x00"
    b"md5sum=992ce8a1687cec8c8bd883ec73ca41d1\x1f\x00\x00\x00"
    b"message_definition=string data\n\r\x00\x00\x00tcp_nodelay=0\x0e\x00\x00\x00"
    b"topic=/chatter\x14\x00\x00\x00type=std_msgs/String"
)


def test_header_reads_rospys_bytes_and_round_trips() -> None:
    fields = decode_header(RO_SPY_HEADER[4:])
    assert fields["callerid"] == "/listener"
    assert fields["md5sum"] == "992ce8a1687cec8c8bd883ec73ca41d1"
    assert fields["message_definition"].startswith("string data")
    assert struct.unpack("<I", RO_SPY_HEADER[:4])[0] == len(RO_SPY_HEADER) - 4
    assert decode_header(encode_header(fields)[4:]) == fields
    # '=' inside a value, an empty value, an empty header
    assert decode_header(encode_header({"a": "x=y", "b": ""})[4:]) == {"a": "x=y", "b": ""}
    assert decode_header(b"") == {}


@pytest.mark.parametrize(
    "body",
    [b"\x05\x00\x00\x00ab", b"\x02\x00", b"\x03\x00\x00\x00abc", b"\x02\x00\x00\x00\xff="],
)
def test_malformed_header_is_one_header_error(body: bytes) -> None:
    with pytest.raises(HeaderError):
        decode_header(body)


def test_framing_caps_lengths_and_notices_a_peer_closing_mid_message() -> None:
    a, b = socket.socketpair()
    with a, b:
        a.sendall(struct.pack("<I", 0xFFFFFFF0))  # 4 GB claimed: refused, nothing allocated
        with pytest.raises(ProtocolError, match="cap"):
            read_frame(b, max_bytes=1 << 20)
        a.sendall(struct.pack("<I", 3 << 20) + b"x" * 1000)  # 3 MiB promised, 1 kB sent
        a.close()
        with pytest.raises(PeerClosedError, match="1000 of"):
            read_frame(b)
    a, b = socket.socketpair()
    with a, b:
        big = struct.pack("<I", (2 << 20) + 4) + b"\x00" * ((2 << 20) + 4)
        sender = threading.Thread(target=a.sendall, args=(big + RO_SPY_HEADER,))
        sender.start()
        assert len(read_frame(b)) == (2 << 20) + 4
        assert read_header(b)["topic"] == "/chatter"
        sender.join()


def test_xmlrpc_reads_what_ros_peers_write() -> None:
    body = (
        "<?xml version='1.0'?><methodResponse><params><param><value><array><data>"
        "<value><int>1</int></value><value><i4>2</i4></value><value>bare text</value>"
        "<value><double>nan</double></value><value><double>-inf</double></value>"
        "<value><string></string></value><value></value>"
        "</data></array></value></param></params></methodResponse>"
    )
    (values,), _ = xmlrpc.client.loads(body)
    assert values[:3] == [1, 2, "bare text"]
    assert math.isnan(values[3]) and values[4] == -math.inf
    assert values[5:] == ["", ""]


def test_md5_star_and_missing_md5_match_anything() -> None:
    assert check_md5("992ce8a1687cec8c8bd883ec73ca41d1", "*")
    assert check_md5("992ce8a1687cec8c8bd883ec73ca41d1", None)
    assert check_md5("*", "abc")
    assert not check_md5("992ce8a1687cec8c8bd883ec73ca41d1", "abc")


def test_a_subscriber_that_stops_reading_never_stalls_the_publisher() -> None:
    a, b = socket.socketpair()  # b is never read
    a.settimeout(None)
    link = OutboundLink(a, callerid="/stuck", queue_size=10)
    payload = b"\x00" * 65536
    t0 = time.monotonic()
    for _ in range(2000):  # 128 MB: far past any socket buffer
        link.send(payload)
    assert time.monotonic() - t0 < 2.0
    assert link.dropped > 1500 and len(link.queue) <= 10
    done = threading.Event()
    link._on_close = lambda _l: done.set()
    b.close()
    assert done.wait(5.0) and link.closed


def test_an_outbound_link_keeps_every_frame_whole_and_in_order() -> None:
    # an idle link writes in the publisher's thread; a message the socket takes only
    # part of is finished by the writer thread before anything queued after it
    a, b = socket.socketpair()
    a.settimeout(None)
    a.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, 4096)
    link = OutboundLink(a, callerid="/reader", queue_size=1000)
    sent = [bytes([i % 251]) * (1 + 37 * i % 20000) for i in range(400)]
    got: list[bytes] = []

    def read() -> None:
        for _ in sent:
            got.append(read_frame(b))
            if len(got) % 50 == 0:
                time.sleep(0.01)  # the reader lags: partial writes and queueing

    reader = threading.Thread(target=read)
    reader.start()
    for i, data in enumerate(sent):
        link.send(data)
        if i % 100 == 0:
            time.sleep(0.05)  # idle again: the direct path
    reader.join(10.0)
    end = time.monotonic() + 5.0
    while link.sent < len(sent) and time.monotonic() < end:  # the writer's count follows
        time.sleep(0.01)
    assert got == sent and link.dropped == 0 and link.sent == len(sent)
    assert link.bytes_sent == sum(len(d) + 4 for d in sent)
    link.close()
    b.close()


def test_a_frame_reader_splits_a_stream_at_any_boundary() -> None:
    units = [b"", b"a" * 5, b"b" * 70000, b"c" * 3, b"d" * 5800, b"e" * 200000]
    stream = b"".join(struct.pack("<I", len(u)) + u for u in units)
    a, b = socket.socketpair()

    def write() -> None:
        for i in range(0, len(stream), 9973):  # chunks that cut lengths and bodies
            a.sendall(stream[i : i + 9973])
            time.sleep(0.001)
        a.sendall(struct.pack("<I", 10) + b"xy")
        a.close()

    writer = threading.Thread(target=write)
    writer.start()
    reader = FrameReader(b)
    assert [reader.read() for _ in units] == units
    with pytest.raises(PeerClosedError, match="inside a unit"):
        reader.read()
    writer.join(5.0)
    b.close()
    c, d = socket.socketpair()
    c.sendall(struct.pack("<I", 1 << 30))
    with pytest.raises(ProtocolError, match="cap"):
        FrameReader(d, max_bytes=1 << 20).read()
    c.close()
    d.close()


def test_names_resolve_like_rosgraph() -> None:
    assert namespace_of("/a/b/node") == "/a/b/"
    assert namespace_of("/node") == "/"
    assert resolve_name("x", "/a/node") == "/a/x"
    assert resolve_name("~x", "/a/node") == "/a/node/x"
    assert resolve_name("/x//y/", "/a/node") == "/x/y"


def test_parameter_tree_and_its_notifications() -> None:
    tree = ParamTree()
    tree.set("/robot/arm/len", 1.5)
    tree.set("/robot/name", "r")
    assert tree.get("/robot") == {"arm": {"len": 1.5}, "name": "r"}
    assert sorted(tree.names()) == ["/robot/arm/len", "/robot/name"]
    assert tree.search("/robot/node", "arm") == "/robot/arm"
    assert tree.search("/other/node", "robot/name") == "/robot/name"
    assert tree.search("/other/node", "nothing") is None
    subs = ["/robot/", "/robot/arm/len/", "/robot/gone/"]
    assert ("/robot/", "/robot/name/", "s") in compute_updates(subs, "/robot/name", "s")
    # replacing /robot with a tree: the parent hears the tree, a child its own value,
    # a key no longer in it hears {} (rosmaster's compute_param_updates)
    ups = compute_updates(subs, "/robot", {"arm": {"len": 2.0}})
    assert ("/robot/arm/len/", "/robot/arm/len/", 2.0) in ups
    assert ("/robot/gone/", "/robot/gone/", {}) in ups
    tree.delete("/robot/arm")
    with pytest.raises(KeyError):
        tree.get("/robot/arm/len")


def test_advertised_address_follows_ros_hostname_then_ros_ip(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv("ROS_HOSTNAME", raising=False)
    monkeypatch.delenv("ROS_IP", raising=False)
    assert advertised_host() == "127.0.0.1"  # loopback unless told
    monkeypatch.setenv("ROS_IP", "127.0.0.2")
    assert advertised_host() == "127.0.0.2"
    monkeypatch.setenv("ROS_HOSTNAME", "localhost")
    assert advertised_host() == "localhost"
    assert bind_host("localhost") == "127.0.0.1"
