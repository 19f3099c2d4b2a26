"""A Foxglove WebSocket server (foxglove_bridge's role) for a roverlab context.

The Foxglove SDK serves its WebSocket protocol (``foxglove.sdk.v1``). Every topic with a
publisher here or in another process becomes a channel with ROS 2 CDR messages and its
``ros2msg`` schema, so Foxglove's app decodes them as it does a ROS 2 system's. A channel is
only subscribed in roverlab while a client subscribes to it. Clients may publish (the
``clientPublish`` capability) in ``cdr`` or ``json``: teleop on /cmd_vel, a goal on
/move_base_simple/goal or /goal_pose, an estimate on /initialpose.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from typing import Any

import foxglove
from foxglove.websocket import Capability, ChannelView, Client, ClientChannel, ServerListener

from roverlab.core import Context, Publisher, QoSProfile, Subscription
from roverlab.core.transport.zenoh import GraphEntity
from roverlab.errors import RoverlabError
from roverlab.msgs import deserialize, from_dict, message_definition, normalize_type_name, serialize

__all__ = ["FoxgloveBridge", "FoxgloveError"]

_DISCOVERY_PERIOD_S = 1.0


class FoxgloveError(RoverlabError):
    """The Foxglove server cannot start or a client sent something unusable."""


class FoxgloveBridge(ServerListener):
    """Serves ``context``'s topics (and those of ``remote_graph``) to Foxglove clients.

    Args:
        context: a context spinning in some thread (the bridge queues its work there).
        host, port: where the SDK's server listens (port 0: any free port).
        remote_graph: the other processes' graph (``Connection.graph``), polled every second.
    """

    def __init__(
        self,
        context: Context,
        host: str = "127.0.0.1",
        port: int = 8765,
        *,
        remote_graph: Callable[[], list[GraphEntity]] | None = None,
    ) -> None:
        self.context = context
        self._remote_graph = remote_graph
        self._node = context.create_node("foxglove_bridge")
        self._fox = foxglove.Context()
        self._channels: dict[str, tuple[foxglove.Channel, str]] = {}  # topic -> (channel, type)
        self._by_id: dict[int, str] = {}
        self._subs: dict[str, Subscription] = {}
        self._sub_clients: dict[str, set[int]] = {}
        self._client_pubs: dict[tuple[int, int], tuple[Publisher, str, str]] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.received = 0
        try:
            self.server = foxglove.start_server(
                name="roverlab",
                host=host,
                port=port,
                capabilities=[Capability.ClientPublish, Capability.Time],
                supported_encodings=["cdr", "json"],
                server_listener=self,
                context=self._fox,
            )
        except Exception as err:
            raise FoxgloveError(f"cannot serve Foxglove on {host}:{port}: {err}") from err
        self.port = self.server.port
        self._discover()
        self._thread = threading.Thread(target=self._discovery_loop, daemon=True)
        self._thread.start()

    # ------------------------------------------------------------------ topics
    def _graph(self) -> list[tuple[str, str]]:
        out = [
            (name, t.typename)
            for name, t in list(self.context.graph.topics.items())
            if any(p.node is not self._node for p in t.publishers)
        ]
        if self._remote_graph is not None:
            out += [(e.topic, e.typename) for e in self._remote_graph() if e.kind == "publisher"]
        return out

    def _discover(self) -> None:
        for topic, typename in self._graph():
            if topic not in self._channels:
                self.add_channel(topic, typename)

    def _discovery_loop(self) -> None:
        while not self._stop.wait(_DISCOVERY_PERIOD_S):
            try:
                self._discover()
            except Exception:  # a graph query can fail while the network changes
                continue

    def add_channel(self, topic: str, typename: str) -> None:
        """Advertise ``topic`` to Foxglove clients."""
        try:
            text = message_definition(typename)
        except RoverlabError:
            return  # a type without a definition here cannot be decoded by clients
        schema = foxglove.Schema(name=typename, encoding="ros2msg", data=text.encode())
        channel = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self._fox)
        with self._lock:
            self._channels[topic] = (channel, typename)
            self._by_id[channel.id()] = topic

    # ------------------------------------------------------------------ ServerListener
    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        topic = channel.topic
        with self._lock:
            clients = self._sub_clients.setdefault(topic, set())
            first = not clients
            clients.add(client.id)
            entry = self._channels.get(topic)
        if first and entry is not None:
            self.context.executor.call_soon_threadsafe(lambda: self._subscribe(topic, *entry))

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        topic = channel.topic
        with self._lock:
            clients = self._sub_clients.get(topic, set())
            clients.discard(client.id)
            last = not clients
        if last:
            self.context.executor.call_soon_threadsafe(lambda: self._unsubscribe(topic))

    def _subscribe(self, topic: str, channel: foxglove.Channel, typename: str) -> None:
        if topic in self._subs:
            return
        ex = self.context.executor
        wall = not self.context.uses_sim_time

        def forward(msg: Any) -> None:
            channel.log(serialize(msg), log_time=time.time_ns() if wall else ex.now_ns)

        self._subs[topic] = self._node.create_subscription(
            normalize_type_name(typename), topic, forward, QoSProfile(depth=10)
        )

    def _unsubscribe(self, topic: str) -> None:
        sub = self._subs.pop(topic, None)
        if sub is not None and not self._sub_clients.get(topic):
            self._node.destroy_subscription(sub)
        elif sub is not None:
            self._subs[topic] = sub

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        if channel.encoding not in ("cdr", "json"):
            return
        typename = channel.schema_name
        topic = channel.topic
        key = (client.id, channel.id)

        def make() -> None:
            try:
                tname = normalize_type_name(typename)
                pub = self._node.create_publisher(tname, topic, 10)
            except RoverlabError:
                return  # an unknown type: its messages are dropped
            self._client_pubs[key] = (pub, tname, channel.encoding)

        self.context.executor.call_soon_threadsafe(make)

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        key = (client.id, client_channel_id)

        def drop() -> None:
            entry = self._client_pubs.pop(key, None)
            if entry is not None:
                self._node.destroy_publisher(entry[0])

        self.context.executor.call_soon_threadsafe(drop)

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        key = (client.id, client_channel_id)

        def publish() -> None:
            entry = self._client_pubs.get(key)
            if entry is None:
                return
            pub, tname, encoding = entry
            try:
                if encoding == "cdr":
                    msg = deserialize(data, tname)
                else:
                    msg = from_dict(tname, json.loads(data))
            except (RoverlabError, ValueError):
                return  # a malformed message from a client is dropped, as foxglove_bridge does
            self.received += 1
            pub.publish(msg)

        self.context.executor.call_soon_threadsafe(publish)

    # ------------------------------------------------------------------ lifetime
    @property
    def topics(self) -> list[str]:
        with self._lock:
            return sorted(self._channels)

    def stop(self) -> None:
        self._stop.set()
        self.server.stop()
