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
from functools import partial
from typing import TYPE_CHECKING, Any

from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.peer import Ros1Peer, TopicSpec
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.core.transport.zenoh_graph import GraphEntity
from roverlab.msgs import normalize_type_name
from roverlab.msgs.ros1 import deserialize_ros1, ros1_definition, ros1_typename, serialize_ros1

if TYPE_CHECKING:
    from roverlab.core.context import Context
    from roverlab.core.graph import Topic
    from roverlab.core.node import Node, Publisher, Subscription

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
            raw = types.get(name, "") if kind != "service" else ""
            tname = normalize_type_name(raw) if raw and raw != "*" else raw
            for node in members:
                if node in skip:
                    continue
                nodes.add(node)
                out.append(GraphEntity("ros1", kind, node, name, tname))
    out.extend(GraphEntity("ros1", "node", n) for n in sorted(nodes))
    return out


def topic_spec(typename: str) -> TopicSpec:
    definition, md5 = ros1_definition(typename)
    return TopicSpec(ros1_typename(typename), md5, definition)


class Ros1Transport:
    """Mirrors a context's nodes and topics into the ROS 1 graph of ``master_uri``.

    Raises:
        MasterError: no master answers at ``master_uri``.
    """

    def __init__(self, master_uri: str) -> None:
        self.master_uri = master_uri
        self.peer = Ros1Peer(master_uri)
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
            self.peer.remove_node(fq)

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
        ctx = self._context
        if ctx is not None:
            ctx.executor.call_soon_threadsafe(partial(self._deliver, topic, data))

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

    def close(self) -> None:
        self.peer.close()
