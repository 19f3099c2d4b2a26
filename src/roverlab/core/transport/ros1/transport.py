"""The ROS 1 transport: a context's nodes as ROS 1 nodes of the graph ``ROS_MASTER_URI``
names, beside (instead of) Zenoh.

Each node registers with the master under its own name; topics go over TCPROS in ROS 1's
serialisation with Noetic's md5sums and full definitions (:mod:`roverlab.msgs.ros1`), so
real rostopic, rospy and roscpp nodes read and feed them. Messages between the process's
own nodes stay in the process. A topic is serialised only while a ROS 1 subscriber is
connected (a latched one always, to repeat it to late subscribers).
"""

from __future__ import annotations

import logging
import os
import threading
from collections.abc import Callable
from functools import partial
from typing import TYPE_CHECKING, Any

from roverlab.core.errors import ServiceError
from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.node_params import ParamMirror
from roverlab.core.transport.ros1.peer import Ros1Peer, TopicSpec
from roverlab.core.transport.ros1.service_link import (
    ServiceCallError,
    ServiceSpec,
    probe,
    service_md5,
)
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.core.transport.zenoh_graph import GraphEntity
from roverlab.msgs import normalize_type_name
from roverlab.msgs.ros1 import deserialize_ros1, ros1_definition, ros1_typename, serialize_ros1

if TYPE_CHECKING:
    from roverlab.core.context import Context
    from roverlab.core.graph import Topic
    from roverlab.core.node import Node, Publisher, Subscription
    from roverlab.core.parameters import Parameter
    from roverlab.core.services import Client, Future, Service

_MISSING: Any = object()
#: Latched topics of roverlab that ROS 1 keeps as parameters of the same name.
_PARAM_TOPICS = frozenset({"/robot_description"})
#: How long a ROS 1 service call may take (either way) before it fails.
CALL_TIMEOUT_S = 60.0

__all__ = ["Ros1Transport", "ros1_graph", "ros_master_uri"]

_log = logging.getLogger("roverlab.ros1")


def ros_master_uri(explicit: str | None = None) -> str | None:
    """The ROS 1 master to join: ``explicit`` (``--ros-master``), else ``ROS_MASTER_URI``,
    else None (no ROS 1: roverlab keeps to its own transports)."""
    return explicit or os.environ.get("ROS_MASTER_URI") or None


def ros1_graph(master_uri: str, exclude: set[str] | None = None) -> list[GraphEntity]:
    """The nodes, publishers, subscriptions and services of a ROS 1 graph (from the
    master's getSystemState and getTopicTypes), as the CLI reads a Zenoh graph; type
    names in roverlab's form (``std_msgs/msg/String``). Nodes in ``exclude`` are left out.
    """
    skip = exclude or set()
    pubs, subs, srvs = call(master_uri, "getSystemState", "/roverlab_cli", timeout_s=5.0)
    types = dict(call(master_uri, "getTopicTypes", "/roverlab_cli", timeout_s=5.0))
    out: list[GraphEntity] = []
    nodes: set[str] = set()
    for kind, table in (("publisher", pubs), ("subscription", subs), ("service", srvs)):
        for name, members in table:
            if kind == "service":
                tname = _probe_service_type(master_uri, name)
            else:
                raw = types.get(name, "")
                tname = normalize_type_name(raw) if raw and raw != "*" else raw
            for node in members:
                if node in skip:
                    continue
                nodes.add(node)
                out.append(GraphEntity("ros1", kind, node, name, tname))
    out.extend(GraphEntity("ros1", "node", n) for n in sorted(nodes))
    return out


def _probe_service_type(master_uri: str, name: str) -> str:
    """A service's type (``pkg/srv/Name``) from its server's probe header; "" unknown."""
    try:
        uri = str(call(master_uri, "lookupService", "/roverlab_cli", name, timeout_s=2.0))
        raw = probe(uri, name, "/roverlab_cli").get("type", "")
    except (MasterError, ServiceCallError):
        return ""
    pkg, sep, short = raw.partition("/")
    return f"{pkg}/srv/{short}" if sep and "/" not in short else ""


def service_spec(srv_type: Any) -> ServiceSpec:
    """The ROS 1 wire description of a roverlab service type (``std_srvs/srv/SetBool``)."""
    req_def, _ = ros1_definition(srv_type.Request.typename)
    res_def, _ = ros1_definition(srv_type.Response.typename)
    md5 = service_md5(req_def, res_def, lambda t: ros1_definition(t)[1])
    pkg, _, name = str(srv_type.typename).split("/")
    return ServiceSpec(f"{pkg}/{name}", md5, f"{pkg}/{name}Request", f"{pkg}/{name}Response")


def topic_spec(typename: str) -> TopicSpec:
    definition, md5 = ros1_definition(typename)
    return TopicSpec(ros1_typename(typename), md5, definition)


class Ros1Transport:
    """Mirrors a context's nodes and topics into the ROS 1 graph of ``master_uri``.

    Args:
        master_uri: the master's XML-RPC URI.
        on_wait: None for a one-shot tool (an unreachable master is an error at once);
            for a node, where it hears that the master is not up yet while the
            transport waits for it, as a rospy node does.

    Raises:
        MasterError: no master answers at ``master_uri`` and ``on_wait`` is None.
    """

    def __init__(self, master_uri: str, *, on_wait: Callable[[str], None] | None = None) -> None:
        self.master_uri = master_uri
        self.peer = Ros1Peer(master_uri, on_wait=on_wait)
        self.params = ParamMirror(master_uri)
        self.peer.on_param = self._on_param
        self._watches: dict[str, list[tuple[str, Callable[[Any], None]]]] = {}
        self._context: Context | None = None
        self._specs: dict[str, TopicSpec] = {}
        self.received = 0
        self.sent = 0
        self.dropped_bad = 0

    @property
    def context(self) -> Context | None:
        return self._context

    def _spec(self, typename: str) -> TopicSpec:
        spec = self._specs.get(typename)
        if spec is None:
            spec = self._specs[typename] = topic_spec(typename)
        return spec

    # ----------------------------------------------------------------- Transport protocol
    def attach(self, context: Context) -> None:
        self._context = context
        for node in list(context.nodes.values()):  # declared before the transport came
            uri = self.peer.add_node(node.get_fully_qualified_name())
            for param in list(node.parameters.values()):
                self.params.declared(node, param, uri, running=True)
        if context.uses_sim_time:  # as Gazebo does: ROS 1 nodes follow our /clock
            try:
                call(self.master_uri, "setParam", "/roverlab", "/use_sim_time", True)
            except MasterError as err:
                _log.warning("could not set /use_sim_time on %s: %s", self.master_uri, err)

    def on_node(self, node: Node, added: bool) -> None:
        fq = node.get_fully_qualified_name()
        if added:
            self.peer.add_node(fq)
        else:
            uri = self.peer.add_node(fq)
            self.params.forget(fq, uri)
            for key, _ in self._watches.pop(fq, []):
                try:
                    call(self.master_uri, "unsubscribeParam", fq, uri, key, timeout_s=2.0)
                except MasterError as err:
                    _log.debug("unsubscribeParam %s: %s", key, err)
            self.peer.remove_node(fq)

    def on_parameter(self, node: Node, param: Parameter) -> None:
        """A parameter declared on ``node``: mirrored to the master's parameter server."""
        self.params.declared(node, param, self.peer.add_node(node.get_fully_qualified_name()))

    def on_publisher(self, pub: Publisher, added: bool) -> None:
        topic = pub.topic
        fq = pub.node.get_fully_qualified_name()
        if not added:
            self.peer.unadvertise(fq, topic.name)
            if topic.name not in self.peer.pubs:
                topic.remote_send = None
            return
        latched = pub.qos.latched
        send = partial(self._send, topic)
        self.peer.advertise(
            fq,
            topic.name,
            self._spec(topic.typename),
            latched=latched,
            latch_depth=pub.qos.depth,
            queue_size=max(pub.qos.depth, 100),
            on_links=partial(self._links_changed, topic, send),
        )
        if latched:
            for msg in topic.latched_history():  # published before the transport came
                self.peer.publish(topic.name, serialize_ros1(msg, topic.typename))
                if topic.name in _PARAM_TOPICS:
                    self._mirror_param(topic.name, msg)
            topic.remote_send = send  # kept for late ROS 1 subscribers

    def _links_changed(self, topic: Topic, send: Any, connected: bool) -> None:
        pub = self.peer.pubs.get(topic.name)
        if connected or (pub is not None and pub.latched):
            topic.remote_send = send
            ctx = self._context
            if ctx is not None and topic.listener_watchers:
                ctx.executor.call_soon_threadsafe(topic.notify_listeners)
        else:
            topic.remote_send = None

    def _send(self, topic: Topic, msg: Any) -> None:
        self.peer.publish(topic.name, serialize_ros1(msg, topic.typename, seq=topic.published))
        self.sent += 1
        if topic.name in _PARAM_TOPICS:
            self._mirror_param(topic.name, msg)

    def _mirror_param(self, name: str, msg: Any) -> None:
        """``/robot_description`` is a parameter in ROS 1 (robot_state_publisher and rviz
        read it there), a latched topic in roverlab: set the parameter too."""
        text = getattr(msg, "data", None)
        if not isinstance(text, str):
            return

        def put() -> None:
            try:
                call(self.master_uri, "setParam", "/roverlab", name, text, timeout_s=10.0)
            except MasterError as err:
                _log.warning("could not set %s on %s: %s", name, self.master_uri, err)

        threading.Thread(target=put, daemon=True, name="ros1-param").start()

    def on_subscription(self, sub: Subscription, added: bool) -> None:
        topic = sub.topic
        fq = sub.node.get_fully_qualified_name()
        if added:
            self.peer.subscribe(
                fq, topic.name, self._spec(topic.typename), partial(self._on_bytes, topic)
            )
        else:
            self.peer.unsubscribe(fq, topic.name)

    def _on_bytes(self, topic: Topic, data: bytes) -> None:
        """A message from a link's thread: decoded and handed to the callbacks in that
        thread when the executor is idle (as rospy runs a callback in its connection's
        thread; still one callback at a time), else queued for the executor."""
        ctx = self._context
        if ctx is not None:
            ctx.executor.run_now_or_soon(partial(self._deliver, topic, data))

    def _deliver(self, topic: Topic, data: bytes) -> None:
        try:
            msg = deserialize_ros1(data, topic.typename)
        except Exception as err:  # a peer's bad bytes cost one message, not the node
            self.dropped_bad += 1
            _log.warning(
                "dropped a message on %s that is not a %s: %s", topic.name, topic.typename, err
            )
            return
        self.received += 1
        for sub in topic.subscriptions:
            sub._enqueue(msg)

    def get_param(self, name: str, default: Any = _MISSING) -> Any:
        """A parameter of the master's parameter server (a namespace as a dictionary).

        Raises:
            KeyError: not set there (and no ``default``).
        """
        try:
            return call(self.master_uri, "getParam", "/roverlab", name, timeout_s=10.0)
        except MasterError:
            if default is _MISSING:
                raise KeyError(name) from None
            return default

    def watch_param(self, node: Node, name: str, callback: Callable[[Any], None]) -> Any:
        """Subscribe ``node`` to the master's parameter ``name`` (subscribeParam, as
        roscpp's ``getParamCached``): ``callback(value)`` runs on the executor thread each
        time someone sets it. Returns its value now (None when it is not set)."""
        fq = node.get_fully_qualified_name()
        uri = self.peer.add_node(fq)
        key = name.rstrip("/")
        self._watches.setdefault(fq, []).append((key, callback))
        try:
            value = call(self.master_uri, "subscribeParam", fq, uri, key, timeout_s=10.0)
        except MasterError as err:
            _log.warning("could not watch %s on %s: %s", key, self.master_uri, err)
            return None
        return None if value == {} else value  # the master answers {} for "not set"

    def _on_param(self, node: str, key: str, value: Any) -> None:
        """The master's paramUpdate to one of our nodes (a slave thread)."""
        self.params.update(self._context, node, key, value)
        ctx = self._context
        changed = key.rstrip("/")
        for watched, callback in self._watches.get(node, []):
            if ctx is not None and changed == watched:
                ctx.executor.call_soon_threadsafe(partial(callback, value))

    def set_param(self, name: str, value: Any) -> None:
        """Set a parameter on the master (as rospy.set_param does for a global name)."""
        call(self.master_uri, "setParam", "/roverlab", name, value, timeout_s=10.0)

    def set_params(self, params: dict[str, Any]) -> list[str]:
        """Set global parameters on the master, as roslaunch does with a launch file's
        ``<param>`` and ``<rosparam>`` values; the names it refused (a value XML-RPC
        cannot carry, such as an integer over 32 bits), each with the reason."""
        refused = []
        for name, value in params.items():
            try:
                call(self.master_uri, "setParam", "/roslaunch", name, value, timeout_s=10.0)
            except (MasterError, OverflowError, TypeError) as err:
                refused.append(f"{name}: {err}")
        return refused

    # ----------------------------------------------------------------- services
    def on_service(self, service: Service, added: bool) -> None:
        fq = service.node.get_fully_qualified_name()
        if added:
            spec = service_spec(service.srv_type)
            self.peer.advertise_service(fq, service.srv_name, spec, partial(self._serve, service))
        else:
            self.peer.unadvertise_service(fq, service.srv_name)

    def _serve(self, service: Service, data: bytes) -> tuple[bool, bytes]:
        """A ROS 1 client's call (a connection thread): served on the executor thread,
        as every callback; the answer goes back from here."""
        ctx = self._context
        if ctx is None:
            return False, f"service '{service.srv_name}' is shutting down".encode()
        try:
            request = deserialize_ros1(data, service.srv_type.Request.typename)
        except Exception as err:
            return (
                False,
                f"service '{service.srv_name}': a request that will not decode: {err}".encode(),
            )
        done = threading.Event()
        answer: list[tuple[bool, bytes]] = []

        def serve() -> None:
            try:
                response = service.serve(request)
                answer.append((True, serialize_ros1(response, service.srv_type.Response.typename)))
            except Exception as err:  # the callback's error: the caller gets its text
                answer.append((False, str(err).encode()))
            finally:
                done.set()

        ctx.executor.run_now_or_soon(serve)
        if not done.wait(CALL_TIMEOUT_S):
            return (
                False,
                f"service '{service.srv_name}' did not answer within {CALL_TIMEOUT_S:g} s".encode(),
            )
        return answer[0]

    def on_client(self, client: Client, added: bool) -> None:
        pass  # ROS 1 does not register service clients with the master

    def service_available(self, name: str) -> bool:
        return self.peer.lookup_service(name) is not None

    def call_service(self, client: Client, request: Any, future: Future) -> bool:
        name = client.srv_name
        if self.peer.lookup_service(name) is None:
            return False
        node = client.node.get_fully_qualified_name()
        spec = service_spec(client.srv_type)
        response_type = client.srv_type.Response.typename
        data = serialize_ros1(request, client.srv_type.Request.typename)

        def run() -> None:
            try:
                raw = self.peer.call_service(node, name, spec, data, CALL_TIMEOUT_S)
                future.set_result(deserialize_ros1(raw, response_type))
            except ServiceCallError as err:
                future.set_exception(ServiceError(f"service '{name}': {err}"))
            except Exception as err:  # an answer that is not a response of this type
                future.set_exception(
                    ServiceError(
                        f"service '{name}': an answer that is not a {response_type}: {err}"
                    )
                )

        threading.Thread(target=run, daemon=True, name=f"ros1-call{name}").start()
        return True

    def close(self) -> None:
        self.params.close()
        self.peer.close()
