"""Length-prefixed TCPROS framing over a socket, bounded.

Every TCPROS unit (connection header, message, service request or response) is a 4-byte
little-endian length and that many bytes. A length is untrusted: it is checked against a
cap, and the buffer grows only as bytes arrive, so a peer that claims 4 GB and sends
nothing costs nothing.
"""

from __future__ import annotations

import socket
import struct

from roverlab.core.transport.ros1.errors import ProtocolError
from roverlab.core.transport.ros1.header import MAX_HEADER_BYTES, decode_header, encode_header

__all__ = [
    "MAX_MESSAGE_BYTES",
    "FrameReader",
    "PeerClosedError",
    "frame",
    "read_exact",
    "read_frame",
    "read_header",
    "write_header",
]

MAX_MESSAGE_BYTES = 512 << 20  # 512 MiB: larger than any camera or cloud message
_CHUNK = 1 << 20
_U32 = struct.Struct("<I")


class PeerClosedError(ProtocolError):
    """The peer closed the connection (cleanly between units, or mid-unit)."""


def read_exact(sock: socket.socket, size: int) -> bytes:
    """Exactly ``size`` bytes; the buffer grows by at most 1 MiB per read.

    Raises:
        PeerClosedError: the connection ended first.
    """
    if size <= _CHUNK:
        # one system call for the whole unit, no copy: MSG_WAITALL returns short only
        # at the end of the stream (or on a signal, hence the loop)
        data = sock.recv(size, socket.MSG_WAITALL)
        if len(data) == size:
            return data
        buf = bytearray(data)
        while len(buf) < size:
            part = sock.recv(size - len(buf), socket.MSG_WAITALL)
            if not part:
                raise PeerClosedError(f"connection closed after {len(buf)} of {size} bytes")
            buf += part
        return bytes(buf)
    out = bytearray()
    while len(out) < size:
        part = sock.recv(min(_CHUNK, size - len(out)))
        if not part:
            raise PeerClosedError(f"connection closed after {len(out)} of {size} bytes")
        out += part
    return bytes(out)


def read_frame(sock: socket.socket, max_bytes: int = MAX_MESSAGE_BYTES) -> bytes:
    """One length-prefixed unit.

    Raises:
        PeerClosedError: the connection ended (before or inside the unit).
        ProtocolError: the length is over ``max_bytes``.
    """
    try:
        head = read_exact(sock, 4)
    except PeerClosedError:
        raise PeerClosedError("connection closed") from None
    (size,) = _U32.unpack(head)
    if size > max_bytes:
        raise ProtocolError(f"length prefix {size} bytes is over the {max_bytes}-byte cap")
    return read_exact(sock, size)


class FrameReader:
    """Length-prefixed units from a socket, read 64 kB at a time: under a flood, one
    system call (each one hands the GIL over) brings many units instead of two per unit.
    The buffer holds at most one read and a unit's start; a unit over 64 kB is finished
    by :func:`read_exact`."""

    _READ = 1 << 16

    def __init__(self, sock: socket.socket, max_bytes: int = MAX_MESSAGE_BYTES) -> None:
        self.sock = sock
        self.max_bytes = max_bytes
        self._buf = b""
        self._pos = 0

    def read(self) -> bytes:
        """The next unit (same errors as :func:`read_frame`)."""
        while True:
            buf, pos = self._buf, self._pos
            have = len(buf) - pos
            if have >= 4:
                (size,) = _U32.unpack_from(buf, pos)
                if size > self.max_bytes:
                    raise ProtocolError(
                        f"length prefix {size} bytes is over the {self.max_bytes}-byte cap"
                    )
                end = pos + 4 + size
                if end <= len(buf):
                    self._pos = end
                    return buf[pos + 4 : end]
                if size > self._READ:
                    self._buf, self._pos = b"", 0
                    return buf[pos + 4 :] + read_exact(self.sock, end - len(buf))
            more = self.sock.recv(self._READ)
            if not more:
                if have:
                    raise PeerClosedError(f"connection closed inside a unit ({have} bytes)")
                raise PeerClosedError("connection closed")
            self._buf, self._pos = buf[pos:] + more, 0


def frame(data: bytes) -> bytes:
    """``data`` with its 4-byte length in front."""
    return _U32.pack(len(data)) + data


def read_header(sock: socket.socket) -> dict[str, str]:
    """A connection header from the socket (capped at :data:`MAX_HEADER_BYTES`)."""
    return decode_header(read_frame(sock, MAX_HEADER_BYTES))


def write_header(sock: socket.socket, fields: dict[str, str]) -> None:
    sock.sendall(encode_header(fields))
