"""XML-RPC for the ROS 1 master and slave APIs, on the standard library.

:mod:`xmlrpc.client` already reads what ROS peers send (``<int>``, ``<i4>``, a bare
``<value>text</value>``, ``nan``/``inf`` doubles, empty strings); this module adds what the
standard library leaves out: a timeout on calls, the ``[code, statusMessage, value]``
convention, a threaded server that answers on any request path (roscpp posts to the full
URI) and refuses bodies over a cap, and the address a node advertises.
"""

from __future__ import annotations

import http.client
import os
import socket
import socketserver
import time
import xmlrpc.client
from collections.abc import Callable
from typing import Any
from urllib.parse import urlsplit
from xmlrpc.server import SimpleXMLRPCRequestHandler, SimpleXMLRPCServer

from roverlab.core.transport.ros1.errors import MasterError

__all__ = [
    "MAX_BODY_BYTES",
    "XmlRpcServer",
    "advertised_host",
    "bind_host",
    "call",
    "parse_reply",
    "proxy",
    "split_uri",
    "wait_for_master",
]

MAX_BODY_BYTES = 64 << 20  # a /robot_description of a big robot is a few MB


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout_s: float) -> None:
        super().__init__()
        self.timeout_s = timeout_s

    def make_connection(self, host: Any) -> http.client.HTTPConnection:
        conn = super().make_connection(host)
        conn.timeout = self.timeout_s
        return conn


def proxy(uri: str, timeout_s: float = 10.0) -> xmlrpc.client.ServerProxy:
    """A proxy to an XML-RPC server whose calls give up after ``timeout_s``."""
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout_s))


def call(uri: str, method: str, *args: Any, timeout_s: float = 10.0) -> Any:
    """Call a ROS API method and return its value.

    Raises:
        MasterError: the peer is unreachable, answered a fault, or answered a code other
            than 1 (its status message is the error's text).
    """
    try:
        reply = getattr(proxy(uri, timeout_s), method)(*args)
    except (OverflowError, TypeError) as err:  # an argument XML-RPC cannot carry
        raise MasterError(f"{method}: {err}") from None
    except (OSError, http.client.HTTPException) as err:
        raise MasterError(f"cannot reach {uri} ({method}): {err}") from None
    except xmlrpc.client.Fault as err:
        raise MasterError(f"{uri} {method}: {err.faultString}") from None
    except xmlrpc.client.ProtocolError as err:
        raise MasterError(f"{uri} {method}: HTTP {err.errcode} {err.errmsg}") from None
    except Exception as err:  # expat errors and odd replies from a broken peer
        raise MasterError(f"{uri} {method}: unreadable reply: {err}") from None
    return _unpack(reply, uri, method)


def _unpack(reply: Any, uri: str, method: str) -> Any:
    if not isinstance(reply, (list, tuple)) or len(reply) != 3:
        raise MasterError(f"{uri} {method}: reply is not [code, status, value]: {reply!r:.80}")
    code, status, value = reply
    if code != 1:
        raise MasterError(str(status).strip().replace("\n", " ") or f"{method} failed")
    return value


def parse_reply(body: bytes, uri: str = "", method: str = "") -> Any:
    """The value of a ROS API reply's XML body (what :func:`call` returns).

    Raises:
        MasterError: not XML-RPC, a fault, or not a successful ``[code, status, value]``.
    """
    try:
        (reply,), _ = xmlrpc.client.loads(body)
    except xmlrpc.client.Fault as err:
        raise MasterError(f"{uri} {method}: {err.faultString}".strip()) from None
    except Exception as err:  # expat, bad numbers, wrong shapes: one line
        raise MasterError(f"{uri} {method}: unreadable reply: {err}".strip()) from None
    return _unpack(reply, uri, method)


class _Handler(SimpleXMLRPCRequestHandler):
    rpc_paths = ()  # any path: roscpp posts to "http://host:port/", rospy to "/RPC2"

    def do_POST(self) -> None:
        try:
            size = int(self.headers.get("content-length", "-1"))
        except ValueError:
            size = -1
        if size < 0 or size > MAX_BODY_BYTES:
            self.send_response(413 if size > 0 else 411)
            self.send_header("Content-length", "0")
            self.end_headers()
            return
        super().do_POST()

    def log_message(self, format: str, *args: Any) -> None:
        pass


class XmlRpcServer(socketserver.ThreadingMixIn, SimpleXMLRPCServer):
    """A threaded XML-RPC server on ``(host, port)``; port 0 picks a free one."""

    daemon_threads = True
    allow_reuse_address = True

    def __init__(self, host: str, port: int, advertise: str | None = None) -> None:
        super().__init__((host, port), requestHandler=_Handler, logRequests=False)
        self.advertise = advertise or host

    @property
    def uri(self) -> str:
        return f"http://{self.advertise}:{self.server_address[1]}/"

    def add(self, name: str, fn: Callable[..., Any]) -> None:
        self.register_function(fn, name)


def split_uri(uri: str) -> tuple[str, int]:
    """``(host, port)`` of ``http://host:port/`` (the ROS default port 11311 when none)."""
    parts = urlsplit(uri)
    if not parts.hostname:
        raise MasterError(f"not a ROS URI: {uri!r} (expected http://host:port/)")
    try:
        port = parts.port or 11311
    except ValueError:
        raise MasterError(f"not a ROS URI: {uri!r} (bad port)") from None
    return parts.hostname, port


def advertised_host() -> str:
    """The address peers are told to use: ``ROS_HOSTNAME``, then ``ROS_IP``, else
    127.0.0.1 (roverlab stays on loopback unless told otherwise)."""
    return os.environ.get("ROS_HOSTNAME") or os.environ.get("ROS_IP") or "127.0.0.1"


def bind_host(advertise: str) -> str:
    """Where to listen to be reachable at ``advertise``: that address itself."""
    try:
        return socket.gethostbyname(advertise)
    except OSError:
        return "0.0.0.0"


#: How often a node retries an unreachable master (rospy: 0.2 s), and how often it says
#: it is still waiting.
MASTER_RETRY_S = 0.5
MASTER_REMIND_S = 10.0


def wait_for_master(
    master_uri: str,
    report: Callable[[str], None] | None,
    *,
    retry_s: float = MASTER_RETRY_S,
    remind_s: float = MASTER_REMIND_S,
) -> None:
    """Return once the master at ``master_uri`` answers.

    With ``report`` None (a one-shot tool, as rostopic) an unreachable master is an error
    at once. Else (a node, as rospy's and roscpp's) it is asked again every ``retry_s``
    until it answers: ``report`` gets one line at the first failure, one every
    ``remind_s`` after, and one when the master answers.

    Raises:
        MasterError: no master answers and ``report`` is None.
    """
    start = time.monotonic()
    remind = start + remind_s
    waited = False
    while True:
        try:
            call(master_uri, "getUri", "/roverlab", timeout_s=3.0)
            if waited and report is not None:
                report(f"reached the ROS master at {master_uri}")
            return
        except MasterError as err:
            if report is None:
                raise MasterError(
                    f"no ROS master at {master_uri} ({err}); start one (roscore or "
                    "roverlab roscore) or fix ROS_MASTER_URI"
                ) from None
            now = time.monotonic()
            if not waited:
                report(
                    f"unable to register with the ROS master at {master_uri} ({err}): it may "
                    f"not be running yet; trying again every {retry_s:g} s"
                )
                waited = True
            elif now >= remind:
                report(
                    f"still no ROS master at {master_uri} after {now - start:.0f} s; "
                    "still trying (start roscore, or fix ROS_MASTER_URI)"
                )
                remind = now + remind_s
        time.sleep(retry_s)
