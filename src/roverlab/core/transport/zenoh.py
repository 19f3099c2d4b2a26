"""Zenoh transport: the same nodes across processes and machines.

Key layout (``D`` is the domain, ``ROVERLAB_DOMAIN_ID``, default 0; like ``ROS_DOMAIN_ID``):

=====================================  ================================================
``rl/D/t/<topic>``                     messages: topic ``/scan`` -> ``rl/0/t/scan``;
                                       payload = ROS 2 CDR bytes (with the 4-byte
                                       encapsulation header); encoding
                                       ``application/cdr;<type name>``
``rl/D/l/<topic>/<zid>``               queryable of a latched (transient-local)
                                       publisher's history, read by late subscribers
``rl/D/g/<zid>/<kind>/<node>/...``     liveliness tokens of the graph: ``n`` nodes,
                                       ``p`` publishers and ``s`` subscriptions
                                       (``.../<topic>/<type>``); ``/`` in names is
                                       written ``%``
``rl/D/p/<node>``                      parameter service of a node (JSON queries)
``rl/D/v/<service>``                   a service server's queryable (CDR request and
                                       response): :mod:`.zenoh_services`
``rl/D/stats/<zid>``                   messages published per topic by a process
                                       (ROS 1's ``getBusStats``): :mod:`.zenoh_stats`
=====================================  ================================================

Messages that stay inside a process never touch Zenoh: a topic is serialised only while
a subscriber in another process matches it.
"""

from __future__ import annotations

import contextlib
import json
import os
import socket
import tempfile
import threading
from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Any

import zenoh

from roverlab.core.errors import ParameterError, TransportError
from roverlab.core.transport.zenoh_graph import (
    GraphEntity,
    decode_name,
    encode_name,
    parse_graph_key,
    query_graph,
    query_parameters,
)
from roverlab.core.transport.zenoh_latched import LatchedInbox, Source, parse_tag, tag
from roverlab.core.transport.zenoh_services import ZenohServices
from roverlab.core.transport.zenoh_stats import declare_stats
from roverlab.msgs import deserialize, serialize

if TYPE_CHECKING:
    from roverlab.core.context import Context
    from roverlab.core.node import Node, Publisher, Subscription
    from roverlab.core.services import Client, Future, Service

__all__ = [
    "DEFAULT_DAEMON_ENDPOINT",
    "GraphEntity",
    "ZenohOptions",
    "ZenohTransport",
    "daemon_endpoint",
    "decode_name",
    "encode_name",
    "open_session",
    "query_graph",
    "query_parameters",
    "topic_key",
]

DEFAULT_DAEMON_ENDPOINT = "tcp/127.0.0.1:7447"


def daemon_endpoint() -> str:
    """The roverlab daemon's endpoint: ``ROVERLAB_DAEMON`` or tcp/127.0.0.1:7447."""
    return os.environ.get("ROVERLAB_DAEMON", DEFAULT_DAEMON_ENDPOINT)


def domain_id() -> int:
    raw = os.environ.get("ROVERLAB_DOMAIN_ID", "0")
    try:
        return int(raw)
    except ValueError:
        raise TransportError(f"ROVERLAB_DOMAIN_ID must be an integer, got {raw!r}") from None


def topic_key(topic: str, domain: int = 0) -> str:
    return f"rl/{domain}/t/{topic.lstrip('/')}"


@dataclass(frozen=True)
class ZenohOptions:
    """How a process joins the Zenoh network.

    Defaults are safe: peer mode, listening on 127.0.0.1 only, multicast scouting off.
    Two machines need an explicit ``listen`` on one (``tcp/0.0.0.0:7447``) and
    ``connect`` on the other (``tcp/192.168.1.41:7447``).

    Args:
        mode: ``peer`` (default), ``client`` or ``router``.
        listen: endpoints to listen on.
        connect: endpoints to connect to.
        multicast_scouting: let Zenoh find peers by UDP multicast on the LAN.
        user, password: user/password authentication (both sides must use the same).
        tls_root_ca, tls_cert, tls_key: files for ``tls/`` endpoints (server cert and
            key where this side listens; the CA that signed the other side's cert).
        present_credentials: offer ``user``/``password`` to the endpoints this side
            connects to (False: only check them on sessions that come in, so a robot
            that listens with a password can still join its machine's daemon).
        connect_timeout_s: fail opening the session when no ``connect`` endpoint accepts
            it within this time (a wrong password, nobody listening) instead of retrying
            in the background; None retries forever.
    """

    mode: str = "peer"
    listen: tuple[str, ...] = ("tcp/127.0.0.1:0",)
    connect: tuple[str, ...] = ()
    multicast_scouting: bool = False
    user: str | None = None
    password: str | None = None
    tls_root_ca: str | None = None
    tls_cert: str | None = None
    tls_key: str | None = None
    present_credentials: bool = True
    connect_timeout_s: float | None = None
    domain: int = field(default_factory=domain_id)

    def to_config(self) -> tuple[zenoh.Config, list[str]]:
        """The Zenoh config, plus temporary files it refers to (to delete at close)."""
        if self.mode not in ("peer", "client", "router"):
            raise TransportError(f"unknown Zenoh mode {self.mode!r} (peer, client or router)")
        if (self.user is None) != (self.password is None):
            raise TransportError("Zenoh authentication needs both --user and --password")
        cfg = zenoh.Config()
        temps: list[str] = []

        def put(key: str, value: Any) -> None:
            try:
                cfg.insert_json5(key, json.dumps(value))
            except Exception as err:
                raise TransportError(f"invalid Zenoh setting {key}={value!r}: {err}") from err

        put("mode", self.mode)
        put("listen/endpoints", list(self.listen))
        put("connect/endpoints", list(self.connect))
        put("scouting/multicast/enabled", self.multicast_scouting)
        if self.user is not None:
            fd, path = tempfile.mkstemp(prefix="roverlab-zenoh-auth-", text=True)
            with os.fdopen(fd, "w") as fh:
                fh.write(f"{self.user}:{self.password}\n")
            temps.append(path)
            if self.present_credentials:
                put("transport/auth/usrpwd/user", self.user)
                put("transport/auth/usrpwd/password", self.password)
            put("transport/auth/usrpwd/dictionary_file", path)
        if self.connect_timeout_s is not None and self.connect:
            ms = int(self.connect_timeout_s * 1000)
            put("connect/timeout_ms", {"router": -1, "peer": ms, "client": ms})
            put("connect/exit_on_failure", {"router": False, "peer": True, "client": True})
        if self.tls_root_ca is not None:
            put("transport/link/tls/root_ca_certificate", self.tls_root_ca)
        if self.tls_cert is not None:
            put("transport/link/tls/listen_certificate", self.tls_cert)
        if self.tls_key is not None:
            put("transport/link/tls/listen_private_key", self.tls_key)
        return cfg, temps


def open_session(options: ZenohOptions) -> tuple[zenoh.Session, list[str]]:
    """Open a Zenoh session; an explicit ``connect`` that no endpoint accepts (within
    ``connect_timeout_s``) is one clear error saying whether nothing answers there or the
    other side refused the session. An endpoint that starts listening while this side
    waits (a robot still booting) gets a second attempt before it counts as refusing."""
    answered_before = options.connect_timeout_s is not None and any(
        endpoint_reachable(ep, timeout_s=1.0) for ep in options.connect
    )
    for attempt in (1, 2):
        cfg, temps = options.to_config()
        try:
            return zenoh.open(cfg), temps
        except Exception as err:
            for path in temps:
                os.unlink(path)
            if not (options.connect and "Unable to connect" in str(err)):
                raise TransportError(f"cannot open Zenoh session: {err}") from err
            answers = any(endpoint_reachable(ep, timeout_s=1.0) for ep in options.connect)
            if answers and not answered_before and attempt == 1:
                answered_before = True  # it came up meanwhile: try once more
                continue
            raise TransportError(_connect_failure(options, answers)) from err
    raise AssertionError("unreachable")  # pragma: no cover


def _connect_failure(options: ZenohOptions, answers: bool) -> str:
    """Why no ``connect`` endpoint took the session: nothing listening, or refused."""
    endpoints = ", ".join(options.connect)
    if answers and all(ep.startswith("tls/") for ep in options.connect):
        if options.tls_root_ca is None:
            return (
                f"{endpoints}: no TLS session: give --tls-root-ca, the CA that signed "
                "that side's certificate"
            )
        also = ", or wrong --user/--password" if options.user is not None else ""
        return (
            f"{endpoints} refused the TLS session: its certificate is not signed by "
            f"--tls-root-ca {options.tls_root_ca} or does not name that host{also}"
        )
    if answers:
        auth = (
            "wrong --user/--password"
            if options.user is not None
            else "it requires --user and --password"
        )
        return f"{endpoints} refused the session: {auth} (or another TLS setup)"
    return (
        f"cannot connect to {endpoints}: nothing answers there (is roverlab running on that "
        "machine with --listen on that address and port?)"
    )


def endpoint_reachable(endpoint: str, timeout_s: float = 0.2) -> bool:
    """True if a TCP endpoint ``tcp/host:port`` accepts connections."""
    proto, _, addr = endpoint.partition("/")
    if proto not in ("tcp", "tls"):
        return False
    host, _, port = addr.rpartition(":")
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s):
            return True
    except (OSError, ValueError):
        return False


class _TopicLink:
    """Zenoh entities of one local topic."""

    def __init__(self) -> None:
        self.publisher: Any = None
        self.matching: Any = None
        self.subscriber: Any = None
        self.latched_queryable: Any = None
        self.latched_watch: Any = None
        self.latched_depth = 0  # the longest history of this process's latched publishers
        self.latched_in = LatchedInbox()  # other processes' latched messages
        self.tokens: dict[object, Any] = {}


class ZenohTransport:
    """Mirrors a context's topics, graph and parameters over a Zenoh session."""

    def __init__(self, options: ZenohOptions | None = None) -> None:
        self.options = options or ZenohOptions()
        self.session, self._temps = open_session(self.options)
        self.zid = str(self.session.zid())
        self.domain = self.options.domain
        self._context: Context | None = None
        self._links: dict[str, _TopicLink] = {}
        self._node_entities: dict[str, list[Any]] = {}
        self._lock = threading.Lock()
        self.received = 0
        self.sent = 0
        self.dropped_wrong_type = 0
        self.latched_repeats = 0
        self._services = ZenohServices(self)
        self._clock_watch: Any = None
        self._clock_sources: dict[str, str] = {}  # zid -> node of other /clock publishers
        self._stats: Any = None

    @property
    def context(self) -> Context | None:
        return self._context

    # ----------------------------------------------------------------- keys
    def graph_key(self, kind: str, *parts: str) -> str:
        """This process's liveliness key of a graph entity (``kind`` n, p, s, v or c)."""
        return f"rl/{self.domain}/g/{self.zid}/{kind}/" + "/".join(encode_name(p) for p in parts)

    def _link(self, topic: str) -> _TopicLink:
        link = self._links.get(topic)
        if link is None:
            link = _TopicLink()
            self._links[topic] = link
        return link

    # ----------------------------------------------------------------- Transport protocol
    def attach(self, context: Context) -> None:
        self._context = context
        if self._stats is None:
            self._stats = declare_stats(self.session, self.domain, self.zid, self._published)

    def _published(self) -> dict[str, int]:
        """Messages published per topic with a publisher here (read on Zenoh's thread)."""
        ctx = self._context
        if ctx is None:
            return {}
        return {n: t.published for n, t in list(ctx.graph.topics.items()) if t.publishers}

    def on_node(self, node: Node, added: bool) -> None:
        fq = node.get_fully_qualified_name()
        with self._lock:
            if added:
                token = self.session.liveliness().declare_token(self.graph_key("n", fq))
                queryable = self.session.declare_queryable(
                    f"rl/{self.domain}/p/{encode_name(fq)}",
                    partial(self._on_param_query, node),
                )
                self._node_entities[fq] = [token, queryable]
            else:
                for ent in self._node_entities.pop(fq, []):
                    ent.undeclare()

    def _watch_clock(self) -> None:
        """Warn when another process publishes /clock on this domain while this one
        publishes or follows it: two clocks would mix silently (a batch run picking up a
        simulator's time, or a node seeing time jump between two simulations)."""
        if self._clock_watch is not None:
            return
        pattern = f"rl/{self.domain}/g/*/p/*/{encode_name('/clock')}/**"

        def on_token(sample: Any) -> None:
            ent = parse_graph_key(str(sample.key_expr))
            if ent is None or ent.zid == self.zid:
                return
            if sample.kind != zenoh.SampleKind.PUT:
                self._clock_sources.pop(ent.zid, None)
                return
            ctx = self._context
            if ent.zid in self._clock_sources or ctx is None:
                return
            self._clock_sources[ent.zid] = ent.node
            topic = ctx.graph.topics.get("/clock")
            publishes = topic is not None and bool(topic.publishers)
            if publishes or len(self._clock_sources) > 1:
                others = ", ".join(sorted(set(self._clock_sources.values())))
                ctx._logger.warning(
                    f"a second /clock source on domain {self.domain}: {others} in another "
                    f"process{' besides this one' if publishes else ''}; their times mix. "
                    "Stop one, or give each run its own ROVERLAB_DOMAIN_ID"
                )

        self._clock_watch = self.session.liveliness().declare_subscriber(
            pattern, on_token, history=True
        )

    def on_publisher(self, pub: Publisher, added: bool) -> None:
        if added and pub.topic.name == "/clock":
            self._watch_clock()
        topic = pub.topic
        with self._lock:
            link = self._link(topic.name)
            if added:
                if link.publisher is None:
                    self._declare_publisher(topic, link)
                if pub.qos.latched:
                    link.latched_depth = max(link.latched_depth, pub.qos.depth)
                # the history's queryable before the token that makes others ask for it
                if pub.qos.latched and link.latched_queryable is None:
                    key = f"rl/{self.domain}/l/{topic.name.lstrip('/')}/{self.zid}"
                    link.latched_queryable = self.session.declare_queryable(
                        key, partial(self._on_latched_query, topic)
                    )
                link.tokens[pub] = self.session.liveliness().declare_token(
                    self.graph_key(
                        "p", pub.node.get_fully_qualified_name(), topic.name, topic.typename
                    )
                    + ("/latched" if pub.qos.latched else "/volatile")
                )
            else:
                tok = link.tokens.pop(pub, None)
                if tok is not None:
                    tok.undeclare()
                if not topic.publishers and link.publisher is not None:
                    topic.remote_send = None
                    link.matching.undeclare()
                    link.publisher.undeclare()
                    link.publisher = link.matching = None
                link.latched_depth = max(
                    (p.qos.depth for p in topic.publishers if p.history is not None), default=0
                )
                if link.latched_queryable is not None and not link.latched_depth:
                    link.latched_queryable.undeclare()
                    link.latched_queryable = None

    def on_subscription(self, sub: Subscription, added: bool) -> None:
        if added and sub.topic.name == "/clock":
            self._watch_clock()
        topic = sub.topic
        with self._lock:
            link = self._link(topic.name)
            if added:
                link.tokens[sub] = self.session.liveliness().declare_token(
                    self.graph_key(
                        "s", sub.node.get_fully_qualified_name(), topic.name, topic.typename
                    )
                )
                if link.subscriber is None:
                    link.subscriber = self.session.declare_subscriber(
                        topic_key(topic.name, self.domain),
                        partial(self._on_sample, topic),
                        allowed_origin=zenoh.Locality.REMOTE,
                    )
                if link.latched_watch is None:
                    link.latched_watch = self._watch_latched(topic, link)
                else:
                    history = link.latched_in.replay()
                    ctx = self._context
                    if history and ctx is not None:
                        ctx.executor.call_soon_threadsafe(partial(_enqueue_all, [sub], history))
            else:
                tok = link.tokens.pop(sub, None)
                if tok is not None:
                    tok.undeclare()
                if not topic.subscriptions and link.subscriber is not None:
                    link.subscriber.undeclare()
                    link.subscriber = None

    # ----------------------------------------------------------------- services
    def on_service(self, service: Service, added: bool) -> None:
        self._services.on_service(service, added)

    def on_client(self, client: Client, added: bool) -> None:
        self._services.on_client(client, added)

    def service_available(self, name: str) -> bool:
        return self._services.service_available(name)

    def call_service(self, client: Client, request: Any, future: Future) -> bool:
        return self._services.call_service(client, request, future)

    def close(self) -> None:
        self._services.close()
        self._clock_watch = None
        self._stats = None
        with self._lock:
            self._links.clear()
            self._node_entities.clear()
        try:
            self.session.close()
        finally:
            for path in self._temps:
                with contextlib.suppress(OSError):
                    os.unlink(path)
            self._temps = []

    # ----------------------------------------------------------------- data path
    def _declare_publisher(self, topic: Any, link: _TopicLink) -> None:
        encoding = zenoh.Encoding.APPLICATION_CDR.with_schema(topic.typename)
        zpub = self.session.declare_publisher(
            topic_key(topic.name, self.domain),
            encoding=encoding,
            allowed_destination=zenoh.Locality.REMOTE,
            congestion_control=zenoh.CongestionControl.BLOCK,
        )

        def send(msg: Any) -> None:
            depth = link.latched_depth
            if depth:  # numbered, so that a late subscriber's history query cannot reorder
                zpub.put(serialize(msg), attachment=tag(self.zid, topic.published, depth))
            else:
                zpub.put(serialize(msg))
            self.sent += 1

        def on_matching(status: Any) -> None:
            topic.remote_send = send if status.matching else None
            ctx = self._context
            if status.matching and ctx is not None and topic.listener_watchers:
                ctx.executor.call_soon_threadsafe(topic.notify_listeners)

        link.publisher = zpub
        link.matching = zpub.declare_matching_listener(on_matching)
        status: Any = zpub.matching_status  # a MatchingStatus (the stubs say bool): always
        if status.matching:  # truthy itself, so its .matching is what tells
            topic.remote_send = send

    def _on_sample(self, topic: Any, sample: Any) -> None:
        # Zenoh's thread only copies the bytes out; the executor thread deserialises, so
        # the two threads hand the GIL over once per message, not twice.
        ctx = self._context
        if ctx is not None:
            att = sample.attachment
            source = None if att is None else parse_tag(att.to_bytes())
            ctx.executor.call_soon_threadsafe(
                partial(self._deliver_bytes, topic, sample.payload.to_bytes(), source)
            )

    def _deliver_bytes(self, topic: Any, data: bytes, source: Source | None = None) -> None:
        try:
            msg = deserialize(data, topic.typename)
        except Exception:
            # another process publishes this topic with a different type: count and
            # drop, as DDS drops samples of a mismatched type
            self.dropped_wrong_type += 1
            return
        if source is not None:
            link = self._links.get(topic.name)
            if link is not None and not link.latched_in.accept(source, msg):
                self.latched_repeats += 1  # a history reply behind the live messages
                return
        self.received += 1
        for sub in topic.subscriptions:
            sub._enqueue(msg)

    def _on_latched_query(self, topic: Any, query: Any) -> None:
        link = self._links.get(topic.name)
        depth = max(1, link.latched_depth) if link is not None else 1
        for number, msg in topic.latched_history_numbered():
            query.reply(query.key_expr, serialize(msg), attachment=tag(self.zid, number, depth))

    def _watch_latched(self, topic: Any, link: _TopicLink) -> Any:
        """Follow the latched publishers of ``topic`` in other processes: each one that
        is (or later becomes) alive is asked for its history, which every subscription of
        the topic receives (and later local subscriptions too)."""
        pattern = (
            f"rl/{self.domain}/g/*/p/*/{encode_name(topic.name)}/{encode_name(topic.typename)}"
            "/latched"
        )
        ctx = self._context

        def on_token(sample: Any) -> None:
            if sample.kind != zenoh.SampleKind.PUT or ctx is None:
                return
            zid = str(sample.key_expr).split("/")[3]
            if zid == self.zid:
                return
            selector = f"rl/{self.domain}/l/{topic.name.lstrip('/')}/{zid}"

            def on_reply(reply: Any) -> None:  # never block in Zenoh's callback threads
                if reply.ok is None:
                    return
                att = reply.ok.attachment
                # an untagged reply (an older roverlab) counts as older than anything live
                source = (None if att is None else parse_tag(att.to_bytes())) or Source(zid, 0, 1)
                ctx.executor.call_soon_threadsafe(
                    partial(self._deliver_bytes, topic, reply.ok.payload.to_bytes(), source)
                )

            self.session.get(selector, on_reply, timeout=2.0)

        return self.session.liveliness().declare_subscriber(pattern, on_token, history=True)

    # ----------------------------------------------------------------- parameters
    def _on_param_query(self, node: Node, query: Any) -> None:
        try:
            request = json.loads(query.payload.to_bytes()) if query.payload is not None else {}
            answer = self._param_answer(node, request)
        except Exception as err:  # any bad request gets an error reply, never a crash
            answer = {"error": str(err)}
        query.reply(query.key_expr, json.dumps(answer))

    def _param_answer(self, node: Node, request: dict[str, Any]) -> dict[str, Any]:
        op = request.get("op")
        if op == "list":
            return {"names": sorted(node.parameters)}
        if op == "get":
            name = str(request.get("name"))
            return {"name": name, "value": node.get_parameter(name).value}
        if op == "dump":
            return {"parameters": {n: p.value for n, p in sorted(node.parameters.items())}}
        if op == "set":
            name = str(request.get("name"))
            value = request.get("value")
            done = threading.Event()
            result: dict[str, Any] = {}

            def apply() -> None:
                try:
                    r = node.set_parameter(name, value)
                    result.update({"ok": r.successful, "reason": r.reason})
                except ParameterError as err:
                    result.update({"error": str(err)})
                done.set()

            ctx = self._context
            if ctx is None:
                return {"error": "no context"}
            ctx.executor.call_soon_threadsafe(apply)
            if not done.wait(5.0):
                return {"error": f"node '{node.get_name()}' did not answer (executor busy?)"}
            return result
        return {"error": f"unknown parameter operation {op!r}"}


def _enqueue_all(subs: list[Any], msgs: list[Any]) -> None:
    for sub in subs:
        for msg in msgs:
            sub._enqueue(msg)
