"""TCPROS connections: one listening server per process, and one object per link.

An incoming connection's header names a ``topic`` (a subscriber wants our messages) or a
``service`` (a client wants to call us); the server routes it by that field. Each link to
a subscriber owns a bounded queue and a writer thread: a subscriber that stops reading
fills its own queue (oldest dropped and counted, as rospy's publisher does) and never
stalls the publisher or the other links.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import socket
import threading
from collections import deque
from collections.abc import Callable

from roverlab.core.transport.ros1.errors import HeaderError, ProtocolError
from roverlab.core.transport.ros1.framing import (
    FrameReader,
    frame,
    read_header,
    write_header,
)

__all__ = [
    "HANDSHAKE_TIMEOUT_S",
    "InboundLink",
    "OutboundLink",
    "TcprosServer",
    "check_md5",
]

HANDSHAKE_TIMEOUT_S = 10.0
_log = logging.getLogger("roverlab.ros1")
_conn_ids = itertools.count(1)  # getBusInfo connection ids (XML-RPC ints: 32 bits)


def check_md5(ours: str, theirs: str | None) -> bool:
    """Two md5sums match, or either side is ``*`` (AnyMsg, ``rostopic hz``) or missing."""
    return not theirs or theirs == "*" or ours == "*" or theirs == ours


def _nodelay(sock: socket.socket) -> None:
    with contextlib.suppress(OSError):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


def _close(sock: socket.socket) -> None:
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)
    with contextlib.suppress(OSError):
        sock.close()


Router = Callable[[socket.socket, dict[str, str]], None]


class TcprosServer:
    """Accepts TCPROS connections on ``(host, port)`` and hands each one, with its
    header, to ``route`` (in the connection's own thread, which ``route`` may keep)."""

    def __init__(self, host: str, route: Router, advertise: str | None = None) -> None:
        self.route = route
        self.sock = socket.create_server((host, 0))
        self.host = advertise or host
        self.port: int = self.sock.getsockname()[1]
        self._closed = False
        self._conns: set[socket.socket] = set()
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True, name="tcpros-accept").start()

    def _accept(self) -> None:
        while not self._closed:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn: socket.socket) -> None:
        with self._lock:
            self._conns.add(conn)
        try:
            conn.settimeout(HANDSHAKE_TIMEOUT_S)
            try:
                header = read_header(conn)
            except (ProtocolError, OSError) as err:
                _log.debug("dropped a TCPROS connection before its header: %s", err)
                return
            conn.settimeout(None)  # the handshake deadline does not hold the link
            self.route(conn, header)
        except Exception as err:  # one bad connection never takes the server down
            _log.warning("TCPROS connection failed: %s", err)
            _close(conn)
        finally:
            with self._lock:
                self._conns.discard(conn)

    def close(self) -> None:
        self._closed = True
        _close(self.sock)
        with self._lock:
            conns = list(self._conns)
        for c in conns:
            _close(c)


class OutboundLink:
    """Our messages to one subscriber: a bounded queue drained by a writer thread."""

    def __init__(
        self,
        sock: socket.socket,
        *,
        callerid: str,
        queue_size: int = 100,
        on_close: Callable[[OutboundLink], None] | None = None,
    ) -> None:
        self.sock = sock
        self.callerid = callerid
        self.id = next(_conn_ids)
        self.queue: deque[bytes] = deque(maxlen=max(1, queue_size))
        self.dropped = 0
        self.sent = 0
        self.bytes_sent = 0
        self.closed = False
        self._cond = threading.Condition()
        self._writing = False  # the writer thread is in sendall (outside the lock)
        self._rest = b""  # the unsent tail of a message the publisher began (framed)
        self._on_close = on_close
        threading.Thread(target=self._write, daemon=True, name="tcpros-out").start()

    def send(self, data: bytes) -> None:
        with self._cond:
            if self.closed:
                return
            if not self.queue and not self._writing and not self._rest:
                # Idle link: write in the caller's thread without blocking (no thread
                # hand-off on the way out); what the socket does not take now, the
                # writer thread finishes, so a subscriber that stops reading never
                # stalls the publisher.
                framed = frame(data)
                try:
                    n = self.sock.send(framed, socket.MSG_DONTWAIT)
                except BlockingIOError:
                    n = 0
                except OSError:
                    n = 0  # the writer meets the error and closes the link
                if n == len(framed):
                    self.bytes_sent += n
                    self.sent += 1
                    return
                if n:
                    self._rest = framed[n:]
                    self.bytes_sent += n
                    self.sent += 1
                    self._cond.notify()
                    return
            if len(self.queue) == self.queue.maxlen:
                self.dropped += 1
            self.queue.append(data)
            self._cond.notify()

    def _write(self) -> None:
        sock = self.sock
        while True:
            with self._cond:
                while not self.queue and not self._rest and not self.closed:
                    self._cond.wait()
                if self.closed:
                    break
                rest, self._rest = self._rest, b""
                batch = list(self.queue)
                self.queue.clear()
                self._writing = True
            try:
                # one system call for what queued meanwhile (a flood sends in bursts)
                parts = [rest, *map(frame, batch)] if rest else list(map(frame, batch))
                sock.sendall(parts[0] if len(parts) == 1 else b"".join(parts))
                self.bytes_sent += len(rest) + sum(len(d) + 4 for d in batch)
                self.sent += len(batch)
            except OSError:
                break
            finally:
                with self._cond:
                    self._writing = False
        self.close()

    def close(self) -> None:
        with self._cond:
            if self.closed and self._on_close is None:
                return
            self.closed = True
            self._cond.notify()
            on_close, self._on_close = self._on_close, None
        _close(self.sock)
        if on_close is not None:
            on_close(self)


class InboundLink:
    """Messages from one publisher: connects, exchanges headers, reads until closed.

    ``check(header)`` sees the publisher's header and raises :class:`HeaderError` to
    refuse it; ``deliver(bytes)`` gets each message (in the link's thread).
    """

    def __init__(
        self,
        host: str,
        port: int,
        header: dict[str, str],
        *,
        check: Callable[[dict[str, str]], None],
        deliver: Callable[[bytes], None],
        on_close: Callable[[InboundLink, str | None], None] | None = None,
        publisher_uri: str = "",
    ) -> None:
        self.host, self.port = host, port
        self.id = next(_conn_ids)
        self.publisher_uri = publisher_uri
        self.header = header
        self.peer_header: dict[str, str] = {}
        self.received = 0
        self.bytes_received = 0
        self.closed = False
        self.sock: socket.socket | None = None
        self._check, self._deliver, self._on_close = check, deliver, on_close
        threading.Thread(target=self._run, daemon=True, name="tcpros-in").start()

    def _run(self) -> None:
        error: str | None = None
        try:
            sock = socket.create_connection((self.host, self.port), timeout=HANDSHAKE_TIMEOUT_S)
            self.sock = sock
            if self.closed:
                raise OSError("closed")
            _nodelay(sock)
            write_header(sock, self.header)
            peer = read_header(sock)
            if "error" in peer:
                ours = f"{self.header.get('type')}/{self.header.get('md5sum')}"
                raise HeaderError(
                    f"publisher refused the connection: {peer['error']} "
                    f"(this node subscribes with [{ours}])"
                )
            self._check(peer)
            self.peer_header = peer
            sock.settimeout(None)
            read = FrameReader(sock).read
            while not self.closed:
                data = read()
                self.received += 1
                self.bytes_received += len(data) + 4
                self._deliver(data)
        except (OSError, ProtocolError) as err:
            if not self.closed:
                error = str(err)
        finally:
            self.close(error)

    def close(self, error: str | None = None) -> None:
        self.closed = True
        if self.sock is not None:
            _close(self.sock)
        on_close, self._on_close = self._on_close, None
        if on_close is not None:
            on_close(self, error)
