"""ROS 1 services over TCPROS: serving one connection, and one call.

A client's header names the ``service``; ``probe=1`` (what ``rosservice info/type`` sends)
gets the reply header and the connection closes, no call and no error. Each request is a
length-prefixed unit; each answer is one byte (1 ok, 0 failed) and a length-prefixed
response or error text. A connection serves one call unless the client asked for
``persistent=1``.
"""

from __future__ import annotations

import hashlib
import socket
import struct
from collections.abc import Callable
from dataclasses import dataclass
from urllib.parse import urlsplit

from roverlab.core.transport.ros1.errors import HeaderError, ProtocolError, Ros1Error
from roverlab.core.transport.ros1.framing import (
    MAX_MESSAGE_BYTES,
    frame,
    read_exact,
    read_frame,
    read_header,
    write_header,
)
from roverlab.core.transport.ros1.tcpros import check_md5

__all__ = [
    "ServiceCallError",
    "ServiceSpec",
    "call_once",
    "probe",
    "serve_connection",
    "service_md5",
    "split_rosrpc",
]

# handler(request bytes) -> (ok, response bytes or error text)
Handler = Callable[[bytes], tuple[bool, bytes]]


class ServiceCallError(Ros1Error):
    """A ROS 1 service call failed: the server said so (its text), or the link broke."""


@dataclass(frozen=True)
class ServiceSpec:
    """A ROS 1 service type on the wire: ``std_srvs/SetBool``, its md5sum, and the
    request and response message types."""

    ros_type: str
    md5sum: str
    request_type: str
    response_type: str


def service_md5(
    request_definition: str, response_definition: str, md5_of: Callable[[str], str]
) -> str:
    """A service's md5sum as genpy computes it: md5 of the request's and the response's
    md5 texts (each its own fields, a message-typed field written as that type's md5sum,
    array brackets of message types dropped), concatenated."""

    def md5_text(definition: str) -> str:
        own = definition.split("\n" + "=" * 80 + "\n", 1)[0]
        lines = []
        for raw in own.splitlines():
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            typ, _, rest = line.partition(" ")
            base = typ.split("[", 1)[0]
            if "/" in base or base == "Header":
                full = "std_msgs/Header" if base == "Header" else base
                lines.append(f"{md5_of(full)} {rest.strip()}")
            else:
                lines.append(f"{typ} {rest.strip()}")
        return "\n".join(lines)

    text = md5_text(request_definition) + md5_text(response_definition)
    return hashlib.md5(text.encode()).hexdigest()


def split_rosrpc(uri: str) -> tuple[str, int]:
    """``(host, port)`` of ``rosrpc://host:port``."""
    parts = urlsplit(uri)
    try:
        if parts.scheme != "rosrpc" or not parts.hostname or parts.port is None:
            raise ValueError
        return parts.hostname, parts.port
    except ValueError:
        raise ServiceCallError(f"not a rosrpc URI: {uri!r}") from None


def serve_connection(
    sock: socket.socket, header: dict[str, str], spec: ServiceSpec, callerid: str, handler: Handler
) -> None:
    """Answer one client connection (in its own thread) until it closes, or after one
    call unless ``persistent=1``."""
    theirs = header.get("md5sum")
    if not check_md5(spec.md5sum, theirs):
        write_header(
            sock,
            {
                "error": f"request from [{header.get('callerid')}]: md5sums do not match: "
                f"[{theirs}] vs. [{spec.md5sum}]"
            },
        )
        return
    write_header(
        sock,
        {
            "callerid": callerid,
            "md5sum": spec.md5sum,
            "type": spec.ros_type,
            "request_type": spec.request_type,
            "response_type": spec.response_type,
        },
    )
    if header.get("probe") == "1":
        return
    persistent = header.get("persistent") == "1"
    while True:
        try:
            request = read_frame(sock)
        except (ProtocolError, OSError):
            return  # the client closed (or sent garbage): its connection only
        ok, answer = handler(request)
        sock.sendall((b"\x01" if ok else b"\x00") + frame(answer))
        if not persistent:
            return


def call_once(
    host: str,
    port: int,
    header: dict[str, str],
    request: bytes,
    timeout_s: float = 60.0,
) -> bytes:
    """One call on a fresh connection; the response's bytes.

    Raises:
        ServiceCallError: refused, failed (the server's text), or the link broke.
    """
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock:
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            write_header(sock, header)
            reply = read_header(sock)
            if "error" in reply:
                raise ServiceCallError(f"service refused the call: {reply['error']}")
            sock.sendall(frame(request))
            (ok,) = struct.unpack("<B", read_exact(sock, 1))
            body = read_frame(sock, MAX_MESSAGE_BYTES)
    except HeaderError as err:
        raise ServiceCallError(f"service at {host}:{port}: {err}") from None
    except (ProtocolError, OSError) as err:
        raise ServiceCallError(f"service at {host}:{port}: {err}") from None
    if not ok:
        raise ServiceCallError(body.decode("utf-8", "replace") or "service call failed")
    return body


def probe(uri: str, name: str, callerid: str, timeout_s: float = 2.0) -> dict[str, str]:
    """The header a service's server answers a ``probe=1`` connection with (its ``type``
    and ``md5sum``), as ``rosservice info`` reads it.

    Raises:
        ServiceCallError: no answer, or not TCPROS.
    """
    host, port = split_rosrpc(uri)
    header = {"callerid": callerid, "service": name, "md5sum": "*", "probe": "1"}
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock:
            write_header(sock, header)
            return read_header(sock)
    except (ProtocolError, OSError) as err:
        raise ServiceCallError(f"service [{name}] at {uri}: {err}") from None
