"""One process as ROS 1 participants: its nodes' slave APIs, one TCPROS server, and the
topic links, on raw message bytes (serialisation is the caller's business).

A topic is published or subscribed once per process, whichever of the process's nodes
uses it; each node is registered with the master under its own name and slave URI, so
``rosnode info`` and ``rostopic info`` show ROS 1 what it expects. Messages between the
process's own nodes never touch TCPROS: links to the process's own slave URIs are skipped.
"""

from __future__ import annotations

import itertools
import logging
import socket
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roverlab.core.transport.ros1.errors import HeaderError, MasterError
from roverlab.core.transport.ros1.framing import write_header
from roverlab.core.transport.ros1.service_link import (
    Handler,
    ServiceCallError,
    ServiceSpec,
    call_once,
    serve_connection,
    split_rosrpc,
)
from roverlab.core.transport.ros1.slave import SlaveServer
from roverlab.core.transport.ros1.tcpros import (
    InboundLink,
    OutboundLink,
    TcprosServer,
    check_md5,
)
from roverlab.core.transport.ros1.xmlrpc import (
    advertised_host,
    bind_host,
    call,
    wait_for_master,
)

__all__ = ["Ros1Peer", "ServiceSpec", "TopicSpec"]

_log = logging.getLogger("roverlab.ros1")
_ids = itertools.count(1)


@dataclass(frozen=True)
class TopicSpec:
    """A ROS 1 message type on the wire: ``std_msgs/String``, its md5sum, its full
    definition (``*`` md5: any type, as rospy's AnyMsg)."""

    ros_type: str
    md5sum: str
    definition: str = ""


@dataclass
class _Pub:
    spec: TopicSpec
    latched: bool
    queue_size: int
    nodes: set[str] = field(default_factory=set)
    active: dict[str, OutboundLink] = field(default_factory=dict)  # subscriber callerid ->
    spare: list[OutboundLink] = field(default_factory=list)
    latched_out: deque[bytes] = field(default_factory=lambda: deque(maxlen=1))
    on_links: Callable[[bool], None] | None = None


@dataclass
class _Sub:
    spec: TopicSpec
    deliver: Callable[[bytes], None]
    nodes: set[str] = field(default_factory=set)
    links: dict[str, InboundLink] = field(default_factory=dict)  # publisher uri ->
    wanted: set[str] = field(default_factory=set)


@dataclass
class _Srv:
    node: str
    spec: ServiceSpec
    handler: Handler


class Ros1Peer:
    """The ROS 1 side of a process, talking to the master at ``master_uri``.

    Args:
        master_uri: the master's XML-RPC URI.
        check_master: make sure the master answers before anything else.
        on_wait: None: an unreachable master is an error (a one-shot tool); else the
            peer waits for it as a ROS node does, telling ``on_wait`` (see
            :func:`wait_for_master`).

    Raises:
        MasterError: no master answers at ``master_uri`` (checked once at start) and
            ``on_wait`` is None.
    """

    def __init__(
        self,
        master_uri: str,
        *,
        check_master: bool = True,
        on_wait: Callable[[str], None] | None = None,
    ) -> None:
        self.master_uri = master_uri
        self.host = advertised_host()
        self.bind = bind_host(self.host)
        if check_master:
            wait_for_master(master_uri, on_wait)
        self._lock = threading.RLock()
        self.slaves: dict[str, SlaveServer] = {}
        self.pubs: dict[str, _Pub] = {}
        self.subs: dict[str, _Sub] = {}
        self.services: dict[str, _Srv] = {}
        self._told: set[tuple[str, str, str]] = set()  # link errors already logged
        self.tcpros = TcprosServer(self.bind, self._route, self.host)
        self.on_shutdown: Callable[[str, str], None] | None = None
        self.on_param: Callable[[str, str, Any], None] | None = None
        self.closed = False
        self._master_down = False
        self._master_pid: int | None = None
        self._watch = threading.Event()
        threading.Thread(target=self._watch_master, daemon=True, name="ros1-master").start()

    # ------------------------------------------------------------------ nodes
    def add_node(self, name: str) -> str:
        """Serve the slave API of node ``name``; its URI."""
        with self._lock:
            slave = self.slaves.get(name)
            if slave is None:
                slave = self.slaves[name] = SlaveServer(name, self, self.bind, self.host)
            return slave.uri

    def remove_node(self, name: str) -> None:
        with self._lock:
            for topic in [t for t, p in self.pubs.items() if name in p.nodes]:
                self.unadvertise(name, topic)
            for topic in [t for t, s in self.subs.items() if name in s.nodes]:
                self.unsubscribe(name, topic)
            for srv in [n for n, s in self.services.items() if s.node == name]:
                self.unadvertise_service(name, srv)
            slave = self.slaves.pop(name, None)
        if slave is not None:
            slave.close()

    def _own_uris(self) -> set[str]:
        return {s.uri for s in self.slaves.values()}

    def _master(self, method: str, *args: Any) -> Any:
        if self.closed and self._master_down:
            raise MasterError(f"{self.master_uri} did not answer")
        try:
            # closing: unregister quickly, and give up on a master that went first
            return call(self.master_uri, method, *args, timeout_s=2.0 if self.closed else 10.0)
        except MasterError:
            self._master_down = self.closed
            raise

    # ------------------------------------------------------------------ publishing
    def advertise(
        self,
        node: str,
        topic: str,
        spec: TopicSpec,
        *,
        latched: bool = False,
        latch_depth: int = 1,
        queue_size: int = 100,
        on_links: Callable[[bool], None] | None = None,
    ) -> None:
        """Register ``node`` as a publisher of ``topic``. ``on_links(True)`` is called when
        the first subscriber connects, ``on_links(False)`` when the last one leaves. A
        latched topic repeats its last ``latch_depth`` messages to each new subscriber
        (ROS 1 latches one per publisher; a roverlab topic may gather several nodes')."""
        uri = self.add_node(node)
        with self._lock:
            pub = self.pubs.get(topic)
            if pub is None:
                pub = self.pubs[topic] = _Pub(spec, latched, queue_size, on_links=on_links)
            pub.latched = pub.latched or latched
            if latched and (pub.latched_out.maxlen or 1) < latch_depth:
                pub.latched_out = deque(pub.latched_out, maxlen=latch_depth)
            pub.nodes.add(node)
        self._master("registerPublisher", node, topic, spec.ros_type, uri)

    def unadvertise(self, node: str, topic: str) -> None:
        with self._lock:
            pub = self.pubs.get(topic)
            if pub is None or node not in pub.nodes:
                return
            pub.nodes.discard(node)
            uri = self.slaves[node].uri
            gone = not pub.nodes
            if gone:
                del self.pubs[topic]
        try:
            self._master("unregisterPublisher", node, topic, uri)
        except MasterError as err:
            _log.debug("unregisterPublisher %s: %s", topic, err)
        if gone:
            for link in [*pub.active.values(), *pub.spare]:
                link.close()

    def publish(self, topic: str, data: bytes) -> None:
        pub = self.pubs.get(topic)
        if pub is None:
            return
        if pub.latched:
            pub.latched_out.append(data)
        for link in list(pub.active.values()):
            link.send(data)

    def has_subscribers(self, topic: str) -> bool:
        pub = self.pubs.get(topic)
        return pub is not None and bool(pub.active)

    def request_topic(self, node: str, topic: str) -> tuple[str, int] | None:
        pub = self.pubs.get(topic)
        if pub is None or node not in pub.nodes:
            return None
        return self.tcpros.host, self.tcpros.port

    def _route(self, sock: socket.socket, header: dict[str, str]) -> None:
        if "topic" in header:
            self._accept_subscriber(sock, header)
            return
        try:
            name = header.get("service")
            srv = self.services.get(name or "")
            if srv is None:
                write_header(sock, {"error": f"no service [{name}] here"})
            else:
                serve_connection(sock, header, srv.spec, srv.node, srv.handler)
        finally:
            sock.close()

    # ------------------------------------------------------------------ services
    @property
    def service_uri(self) -> str:
        return f"rosrpc://{self.tcpros.host}:{self.tcpros.port}"

    def advertise_service(self, node: str, name: str, spec: ServiceSpec, handler: Handler) -> None:
        """Serve ``name`` for ``node``: ``handler(request bytes) -> (ok, bytes)`` runs in the
        connection's thread."""
        uri = self.add_node(node)
        with self._lock:
            self.services[name] = _Srv(node, spec, handler)
        self._master("registerService", node, name, self.service_uri, uri)

    def unadvertise_service(self, node: str, name: str) -> None:
        with self._lock:
            srv = self.services.get(name)
            if srv is None or srv.node != node:
                return
            del self.services[name]
        try:
            self._master("unregisterService", node, name, self.service_uri)
        except MasterError as err:
            _log.debug("unregisterService %s: %s", name, err)

    def lookup_service(self, name: str) -> str | None:
        """The rosrpc URI of ``name``'s server in another process, or None."""
        try:
            uri = str(self._master("lookupService", "/roverlab", name))
        except MasterError:
            return None
        return None if uri == self.service_uri else uri

    def call_service(
        self, node: str, name: str, spec: ServiceSpec, request: bytes, timeout_s: float = 60.0
    ) -> bytes:
        """Call ``name`` once (a fresh connection, as rospy's ServiceProxy does).

        Raises:
            ServiceCallError: no server, refused, failed, or the link broke.
        """
        uri = self.lookup_service(name)
        if uri is None:
            raise ServiceCallError(f"service [{name}] is not available")
        host, port = split_rosrpc(uri)
        header = {"callerid": node, "service": name, "md5sum": spec.md5sum, "persistent": "0"}
        return call_once(host, port, header, request, timeout_s)

    def _accept_subscriber(self, sock: socket.socket, header: dict[str, str]) -> None:
        topic = header["topic"]
        callerid = header.get("callerid", f"/unnamed_{next(_ids)}")
        pub = self.pubs.get(topic)
        if pub is None:
            write_header(sock, {"error": f"no publisher of [{topic}] here"})
            sock.close()
            return
        spec = pub.spec
        theirs = header.get("md5sum")
        if not check_md5(spec.md5sum, theirs):
            msg = (
                f"Client [{callerid}] wants topic [{topic}] to have datatype/md5sum "
                f"[{header.get('type')}/{theirs}], but our version has "
                f"[{spec.ros_type}/{spec.md5sum}] Dropping connection."
            )
            _log.warning(msg)
            write_header(sock, {"error": msg})
            sock.close()
            return
        node = sorted(pub.nodes)[0] if pub.nodes else "/roverlab"
        write_header(
            sock,
            {
                "callerid": node,
                "topic": topic,
                "type": spec.ros_type,
                "md5sum": spec.md5sum,
                "message_definition": spec.definition,
                "latching": "1" if pub.latched else "0",
            },
        )
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        link = OutboundLink(
            sock, callerid=callerid, queue_size=pub.queue_size, on_close=self._link_closed(topic)
        )
        first = False
        with self._lock:
            if callerid in pub.active:
                pub.spare.append(link)  # a second of our nodes publishing the topic
            else:
                first = not pub.active
                for data in pub.latched_out:
                    link.send(data)
                pub.active[callerid] = link
        if first and pub.on_links is not None:
            pub.on_links(True)

    def _link_closed(self, topic: str) -> Callable[[OutboundLink], None]:
        def closed(link: OutboundLink) -> None:
            with self._lock:
                pub = self.pubs.get(topic)
                if pub is None:
                    return
                if link in pub.spare:
                    pub.spare.remove(link)
                    return
                if pub.active.get(link.callerid) is not link:
                    return
                del pub.active[link.callerid]
                for spare in pub.spare:
                    if spare.callerid == link.callerid and not spare.closed:
                        pub.spare.remove(spare)
                        pub.active[link.callerid] = spare
                        break
                last = not pub.active
            if last and pub.on_links is not None:
                pub.on_links(False)

        return closed

    # ------------------------------------------------------------------ subscribing
    def subscribe(
        self, node: str, topic: str, spec: TopicSpec, deliver: Callable[[bytes], None]
    ) -> None:
        """Register ``node`` as a subscriber of ``topic``; ``deliver`` gets each message's
        bytes (in a link thread)."""
        uri = self.add_node(node)
        with self._lock:
            sub = self.subs.get(topic)
            if sub is None:
                sub = self.subs[topic] = _Sub(spec, deliver)
            sub.nodes.add(node)
        pubs = self._master("registerSubscriber", node, topic, spec.ros_type, uri)
        self.publisher_update(node, topic, [str(p) for p in pubs])

    def unsubscribe(self, node: str, topic: str) -> None:
        with self._lock:
            sub = self.subs.get(topic)
            if sub is None or node not in sub.nodes:
                return
            sub.nodes.discard(node)
            uri = self.slaves[node].uri
            gone = not sub.nodes
            if gone:
                del self.subs[topic]
                sub.wanted.clear()
        try:
            self._master("unregisterSubscriber", node, topic, uri)
        except MasterError as err:
            _log.debug("unregisterSubscriber %s: %s", topic, err)
        if gone:
            for link in list(sub.links.values()):
                link.close()

    def publisher_update(self, node: str, topic: str, uris: list[str]) -> None:
        with self._lock:
            sub = self.subs.get(topic)
            if sub is None:
                return
            own = self._own_uris()
            sub.wanted = {u for u in uris if u not in own}
            stale = [u for u in sub.links if u not in sub.wanted]
            new = [u for u in sub.wanted if u not in sub.links]
            callerid = sorted(sub.nodes)[0]
        for u in stale:
            link = sub.links.pop(u, None)
            if link is not None:
                link.close()
        for u in new:
            threading.Thread(
                target=self._connect, args=(topic, u, callerid, 0.1), daemon=True
            ).start()

    def _connect(self, topic: str, uri: str, callerid: str, backoff_s: float) -> None:
        with self._lock:
            sub = self.subs.get(topic)
            if sub is None or uri not in sub.wanted or uri in sub.links:
                return
        try:
            proto = call(uri, "requestTopic", callerid, topic, [["TCPROS"]], timeout_s=5.0)
            host, port = str(proto[1]), int(proto[2])
        except (MasterError, IndexError, TypeError, ValueError) as err:
            _log.debug("requestTopic %s at %s: %s", topic, uri, err)
            self._retry(topic, uri, callerid, backoff_s)
            return
        spec = sub.spec

        def check(peer: dict[str, str]) -> None:
            if not check_md5(spec.md5sum, peer.get("md5sum")):
                raise HeaderError(
                    f"[{topic}]: publisher {peer.get('callerid', uri)} sends "
                    f"[{peer.get('type')}/{peer.get('md5sum')}], this node expects "
                    f"[{spec.ros_type}/{spec.md5sum}]"
                )

        def on_close(link: InboundLink, error: str | None) -> None:
            with self._lock:
                if sub.links.get(uri) is link:
                    del sub.links[uri]
            if error is not None:
                # a publisher that closes between messages has usually gone (the master
                # will say so); anything else is worth a line
                # worth a line, once per publisher and reason (a refused type would
                # otherwise repeat at every reconnection)
                quiet = error == "connection closed" or (topic, uri, error) in self._told
                self._told.add((topic, uri, error))
                level = logging.DEBUG if quiet else logging.WARNING
                _log.log(level, "link to %s on %s ended: %s", uri, topic, error)
                self._retry(topic, uri, callerid, backoff_s)

        header = {
            "callerid": callerid,
            "topic": topic,
            "type": spec.ros_type,
            "md5sum": spec.md5sum,
            "message_definition": spec.definition,
            "tcp_nodelay": "1",
        }
        with self._lock:
            if uri not in sub.wanted or uri in sub.links or self.subs.get(topic) is not sub:
                return
            sub.links[uri] = InboundLink(
                host,
                port,
                header,
                check=check,
                deliver=sub.deliver,
                on_close=on_close,
                publisher_uri=uri,
            )

    def _retry(self, topic: str, uri: str, callerid: str, backoff_s: float) -> None:
        """Reconnect later while the master still lists the publisher (100 ms doubling
        to 20 s, as roslibrust does); a refused md5 is retried too, slowly."""
        if self.closed:
            return
        delay = min(backoff_s * 2, 20.0)
        timer = threading.Timer(backoff_s, self._connect, args=(topic, uri, callerid, delay))
        timer.daemon = True
        timer.start()

    # ------------------------------------------------------------------ slave API
    def bus_info(self, node: str) -> list[list[Any]]:
        out: list[list[Any]] = []
        with self._lock:
            for topic, pub in self.pubs.items():
                if node in pub.nodes:
                    for cid, link in pub.active.items():
                        out.append([link.id, cid, "o", "TCPROS", topic, not link.closed])
            for topic, sub in self.subs.items():
                if node in sub.nodes:
                    for uri, inb in sub.links.items():
                        out.append([inb.id, uri, "i", "TCPROS", topic, not inb.closed])
        return out

    def bus_stats(self, node: str) -> list[Any]:
        with self._lock:
            pubs = [
                [t, sum(lk.bytes_sent for lk in p.active.values()), []]
                for t, p in self.pubs.items()
                if node in p.nodes
            ]
            subs = [
                [t, [[lk.id, lk.bytes_received, -1, not lk.closed] for lk in s.links.values()]]
                for t, s in self.subs.items()
                if node in s.nodes
            ]
        return [pubs, subs, [0, 0, 0]]

    def publications(self, node: str) -> list[list[str]]:
        return [[t, p.spec.ros_type] for t, p in self.pubs.items() if node in p.nodes]

    def subscriptions(self, node: str) -> list[list[str]]:
        return [[t, s.spec.ros_type] for t, s in self.subs.items() if node in s.nodes]

    def param_update(self, node: str, key: str, value: Any) -> None:
        if self.on_param is not None:
            self.on_param(node, key, value)

    def shutdown_node(self, node: str, reason: str) -> None:
        _log.warning("node %s asked to shut down: %s", node, reason)
        if self.on_shutdown is not None:
            self.on_shutdown(node, reason)

    # ------------------------------------------------------------------ master restarts
    def _watch_master(self, period_s: float = 1.0) -> None:
        """A master that restarts (another pid) has forgotten this process: register its
        nodes' publishers, subscribers and services again. Links between nodes run on
        meanwhile; a master that is away only costs a debug line per second."""
        while not self._watch.wait(period_s):
            try:
                pid = int(call(self.master_uri, "getPid", "/roverlab", timeout_s=2.0))
            except (MasterError, TypeError, ValueError) as err:
                _log.debug("master %s: %s", self.master_uri, err)
                continue
            if self._master_pid is not None and pid != self._master_pid and not self.closed:
                _log.warning("the master at %s restarted: registering again", self.master_uri)
                self._register_again()
            self._master_pid = pid

    def _register_again(self) -> None:
        with self._lock:
            pubs = [(n, t, p.spec.ros_type) for t, p in self.pubs.items() for n in p.nodes]
            subs = [(n, t, s.spec.ros_type) for t, s in self.subs.items() for n in s.nodes]
            srvs = [(s.node, name) for name, s in self.services.items()]
            uris = {n: slave.uri for n, slave in self.slaves.items()}
        try:
            for node, topic, typ in pubs:
                self._master("registerPublisher", node, topic, typ, uris[node])
            for node, topic, typ in subs:
                found = self._master("registerSubscriber", node, topic, typ, uris[node])
                self.publisher_update(node, topic, [str(u) for u in found])
            for node, name in srvs:
                self._master("registerService", node, name, self.service_uri, uris[node])
        except (MasterError, KeyError) as err:
            _log.warning("registering again with %s failed: %s", self.master_uri, err)

    # ------------------------------------------------------------------ lifecycle
    def close(self) -> None:
        """Unregister everything from the master (best effort) and close all links."""
        self.closed = True
        self._watch.set()
        for node in list(self.slaves):
            self.remove_node(node)
        self.tcpros.close()
