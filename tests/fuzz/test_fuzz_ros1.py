"""Fuzzing the ROS 1 wire's parsers: TCPROS connection headers and framing, XML-RPC
replies, and the master's XML-RPC dispatch (whatever a peer sends, the answer is a value,
a fault or one clear error, never a crash)."""

from __future__ import annotations

import socket
import xmlrpc.client
from collections.abc import Iterator

import pytest
from hypothesis import given
from hypothesis import strategies as st

from roverlab.core.transport.ros1.framing import read_frame, read_header
from roverlab.core.transport.ros1.header import decode_header, encode_header
from roverlab.core.transport.ros1.master import Master
from roverlab.core.transport.ros1.xmlrpc import parse_reply
from tests.fuzz.mutation import FUZZ, clean, mutated

HEADER = encode_header(
    {
        "callerid": "/listener",
        "md5sum": "992ce8a1687cec8c8bd883ec73ca41d1",
        "message_definition": "string data\n",
        "tcp_nodelay": "0",
        "topic": "/chatter",
        "type": "std_msgs/String",
    }
)
REPLY = xmlrpc.client.dumps(
    ([1, "current topics", [["/chatter", "std_msgs/String"], ["/nan", 1.5]]],),
    methodresponse=True,
)
REQUEST = xmlrpc.client.dumps(
    ("/talker", "/chatter", "std_msgs/String", "http://127.0.0.1:1/"), "registerPublisher"
)


@st.composite
def corrupted(draw: st.DrawFn, data: bytes) -> bytes:
    out = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        out[draw(st.integers(0, len(out) - 1))] = draw(st.integers(0, 255))
    if draw(st.booleans()):
        out = out[: draw(st.integers(0, len(out)))]
    return bytes(out)


@FUZZ
@given(corrupted(HEADER) | st.binary(max_size=64))
def test_connection_header(data: bytes) -> None:
    fields = clean(decode_header, data[4:])
    assert fields is None or all(isinstance(k, str) for k in fields)
    a, b = socket.socketpair()
    with a, b:
        a.sendall(data[:4096])
        a.shutdown(socket.SHUT_WR)
        clean(read_header, b)
    a, b = socket.socketpair()
    with a, b:
        a.sendall(data[:4096])
        a.shutdown(socket.SHUT_WR)
        clean(read_frame, b, 1 << 16)


@FUZZ
@given(mutated(REPLY) | st.text(max_size=64))
def test_xmlrpc_reply(text: str) -> None:
    clean(parse_reply, text.encode("utf-8", "surrogatepass"), "http://127.0.0.1:1/", "call")


@pytest.fixture(scope="module")
def master() -> Iterator[Master]:
    m = Master(port=0)  # never served: the dispatch is called directly
    yield m
    m.stop()


@FUZZ
@given(text=mutated(REQUEST) | st.text(max_size=64))
def test_master_dispatch(master: Master, text: str) -> None:
    body = text.encode("utf-8", "surrogatepass")
    answer = master.server._marshaled_dispatch(body)
    assert answer.startswith(b"<?xml")
    try:
        (reply,), _ = xmlrpc.client.loads(answer)
    except xmlrpc.client.Fault:
        return
    assert isinstance(reply, list) and len(reply) == 3 and reply[0] in (-1, 0, 1)
