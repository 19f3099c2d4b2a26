"""A Foxglove WebSocket server (foxglove_bridge's role) for a roverlab context.

The Foxglove SDK serves its WebSocket protocol (``foxglove.sdk.v1``). Every topic with a
publisher here or in another process becomes a channel with ROS 2 CDR messages and its
``ros2msg`` schema, so Foxglove's app decodes them as it does a ROS 2 system's. A channel is
only subscribed in roverlab while a client subscribes to it. Clients may publish (the
``clientPublish`` capability) in ``cdr`` or ``json``: teleop on /cmd_vel, a goal on
/move_base_simple/goal or /goal_pose, an estimate on /initialpose.

Services (``services``): every service served here or in another process is advertised
with its ``ros2msg`` request and response schemas; a client's call (CDR, or JSON) is
made with a roverlab client and answered in CDR, a failure (no answer within
:data:`SERVICE_TIMEOUT_S`, a server error) as the protocol's call failure with the reason.
Parameters (``parameters``): the nodes' parameters as ``/node.param``
(:mod:`roverlab.foxglove.params`), read and set by clients; a set is published to the
clients subscribed to the parameter.
"""

from __future__ import annotations

import json
import struct
import threading
import time
from collections.abc import Callable
from typing import Any

import foxglove
from foxglove.websocket import Capability, ChannelView, Client, ClientChannel, ServerListener

from roverlab.core import Client as ServiceClient
from roverlab.core import Context, Publisher, QoSProfile, Subscription
from roverlab.core.transport.zenoh import GraphEntity
from roverlab.errors import RoverlabError
from roverlab.foxglove.params import NodeParameters
from roverlab.msgs import (
    deserialize,
    from_dict,
    get_service_type,
    message_definition,
    normalize_type_name,
    serialize,
)

__all__ = ["SERVICE_TIMEOUT_S", "FoxgloveBridge", "FoxgloveError"]

_DISCOVERY_PERIOD_S = 1.0
SERVICE_TIMEOUT_S = 10.0
"""How long a client's service call waits for the server (then it fails)."""


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
        self._services: dict[str, str] = {}  # advertised service -> its type
        self._service_clients: dict[str, ServiceClient] = {}
        self.parameters = NodeParameters(context, self._node, remote_graph)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.received = 0
        try:
            self.server = foxglove.start_server(
                name="roverlab",
                host=host,
                port=port,
                capabilities=[
                    Capability.ClientPublish,
                    Capability.Time,
                    Capability.Services,
                    Capability.Parameters,
                ],
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
    def _graph(self, remote: list[GraphEntity]) -> list[tuple[str, str]]:
        out = [
            (name, t.typename)
            for name, t in list(self.context.graph.topics.items())
            if any(p.node is not self._node for p in t.publishers)
        ]
        out += [(e.topic, e.typename) for e in remote if e.kind == "publisher"]
        return out

    def _discover(self) -> None:
        remote = self._remote_graph() if self._remote_graph is not None else []
        for topic, typename in self._graph(remote):
            if topic not in self._channels:
                self.add_channel(topic, typename)
        services = {
            name: srv.srv_type.typename
            for name, srv in list(self.context.graph.services.items())
            if srv.node is not self._node
        }
        services.update({e.topic: e.typename for e in remote if e.kind == "service"})
        gone = [name for name in self._services if name not in services]
        if gone:
            self.server.remove_services(gone)
            for name in gone:
                del self._services[name]
        for name, typename in sorted(services.items()):
            if name not in self._services:
                self.add_service(name, typename)

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

    # ------------------------------------------------------------------ services
    def add_service(self, name: str, typename: str) -> None:
        """Advertise the service ``name`` (of type ``typename``) to Foxglove clients."""
        try:
            tname = normalize_type_name(typename)
            parts = [
                foxglove.MessageSchema(
                    encoding="cdr",
                    schema=foxglove.Schema(
                        name=f"{tname}{suffix}",
                        encoding="ros2msg",
                        data=message_definition(f"{tname}{suffix}").encode(),
                    ),
                )
                for suffix in ("_Request", "_Response")
            ]
        except RoverlabError:
            return  # a type without a definition here cannot be called by clients
        schema = foxglove.ServiceSchema(name=tname, request=parts[0], response=parts[1])
        service = foxglove.Service(name, schema=schema, handler=self._service_handler(name, tname))
        try:
            self.server.add_services([service])
        except Exception:  # already advertised (a race with the discovery thread)
            return
        self._services[name] = tname

    def _service_handler(self, name: str, typename: str) -> Callable[[Any], bytes]:
        empty = not message_definition(f"{typename}_Request").strip()

        def handle(request: Any) -> bytes:
            # runs on one of the SDK's threads: the call waits here, the executor serves it
            try:
                if request.encoding == "json":
                    payload = from_dict(f"{typename}_Request", json.loads(request.payload))
                elif empty and len(request.payload) <= 4:
                    # a request without fields: Foxglove writes the CDR header alone
                    payload = get_service_type(typename).Request()
                else:
                    payload = deserialize(request.payload, f"{typename}_Request")
            except (RoverlabError, ValueError, struct.error) as err:
                raise FoxgloveError(f"{name}: bad {request.encoding} request: {err}") from err
            with self._lock:
                client = self._service_clients.get(name)
                if client is None:
                    client = self._node.create_client(typename, name)
                    self._service_clients[name] = client
            if not client.wait_for_service(SERVICE_TIMEOUT_S):  # a new client learns servers
                raise FoxgloveError(f"{name}: no server within {SERVICE_TIMEOUT_S:g} s")
            try:
                response = client.call(payload, timeout_sec=SERVICE_TIMEOUT_S)
            except RoverlabError as err:
                raise FoxgloveError(f"{name}: {err}") from err
            if response is None:
                raise FoxgloveError(f"{name}: no answer within {SERVICE_TIMEOUT_S:g} s")
            return bytes(serialize(response))

        return handle

    @property
    def services(self) -> list[str]:
        """The services advertised to clients."""
        return sorted(self._services)

    # ------------------------------------------------------------------ parameters
    def on_get_parameters(
        self, client: Client, param_names: list[str], request_id: str | None = None
    ) -> list[foxglove.Parameter]:
        return self.parameters.get(param_names)

    def on_set_parameters(
        self,
        client: Client,
        parameters: list[foxglove.Parameter],
        request_id: str | None = None,
    ) -> list[foxglove.Parameter]:
        for p in parameters:
            try:
                self.parameters.set(p.name, p.get_value())
            except RoverlabError as err:
                self.server.publish_status(str(err), foxglove.StatusLevel.Warning)
        # the values now in force (a refused set shows the old value)
        return self.parameters.get([p.name for p in parameters])

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
