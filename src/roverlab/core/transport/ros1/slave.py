"""The slave (node) XML-RPC API of one ROS 1 node: what the master and other nodes call.

Each node of a process gets its own server (its own URI: ``rosnode kill`` and the
master's "same name registered again" shutdown must reach one node, not all); the
process-wide :class:`~.peer.Ros1Peer` answers for all of them through :class:`Bus`.
"""

from __future__ import annotations

import os
import threading
from typing import Any, Protocol

from roverlab.core.transport.ros1.xmlrpc import XmlRpcServer

__all__ = ["Bus", "SlaveServer"]


class Bus(Protocol):
    master_uri: str

    def request_topic(self, node: str, topic: str) -> tuple[str, int] | None: ...
    def publisher_update(self, node: str, topic: str, uris: list[str]) -> None: ...
    def bus_info(self, node: str) -> list[list[Any]]: ...
    def bus_stats(self, node: str) -> list[Any]: ...
    def publications(self, node: str) -> list[list[str]]: ...
    def subscriptions(self, node: str) -> list[list[str]]: ...
    def param_update(self, node: str, key: str, value: Any) -> None: ...
    def shutdown_node(self, node: str, reason: str) -> None: ...


class SlaveServer:
    """``requestTopic``, ``publisherUpdate``, ``getBusInfo``, ``getBusStats``, ``getPid``,
    ``getMasterUri``, ``getPublications``, ``getSubscriptions``, ``paramUpdate``,
    ``shutdown`` for node ``name``, served on ``host`` (a free port)."""

    def __init__(self, name: str, bus: Bus, host: str, advertise: str) -> None:
        self.name = name
        self.bus = bus
        self.server = XmlRpcServer(host, 0, advertise)
        for method in [
            "requestTopic",
            "publisherUpdate",
            "getBusInfo",
            "getBusStats",
            "getPid",
            "getMasterUri",
            "getPublications",
            "getSubscriptions",
            "paramUpdate",
            "shutdown",
        ]:
            self.server.add(method, getattr(self, method))
        self._thread = threading.Thread(
            target=self.server.serve_forever, daemon=True, name=f"slave{name}"
        )
        self._thread.start()

    @property
    def uri(self) -> str:
        return self.server.uri

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()

    # ------------------------------------------------------------------ API
    def requestTopic(self, caller_id: str, topic: str, protocols: list[Any]) -> list[Any]:
        if not any(isinstance(p, list) and p and p[0] == "TCPROS" for p in protocols):
            return [0, "no supported protocol (this node speaks TCPROS)", []]
        where = self.bus.request_topic(self.name, topic)
        if where is None:
            return [-1, f"not a publisher of [{topic}]", []]
        return [1, f"ready on {where[0]}:{where[1]}", ["TCPROS", where[0], where[1]]]

    def publisherUpdate(self, caller_id: str, topic: str, publishers: list[str]) -> list[Any]:
        self.bus.publisher_update(self.name, topic, [str(p) for p in publishers])
        return [1, "", 0]

    def getBusInfo(self, caller_id: str) -> list[Any]:
        return [1, "bus info", self.bus.bus_info(self.name)]

    def getBusStats(self, caller_id: str) -> list[Any]:
        return [1, "bus stats", self.bus.bus_stats(self.name)]

    def getPid(self, caller_id: str) -> list[Any]:
        return [1, "", os.getpid()]

    def getMasterUri(self, caller_id: str) -> list[Any]:
        return [1, "", self.bus.master_uri]

    def getPublications(self, caller_id: str) -> list[Any]:
        return [1, "publications", self.bus.publications(self.name)]

    def getSubscriptions(self, caller_id: str) -> list[Any]:
        return [1, "subscriptions", self.bus.subscriptions(self.name)]

    def paramUpdate(self, caller_id: str, key: str, value: Any) -> list[Any]:
        self.bus.param_update(self.name, key, value)
        return [1, "", 0]

    def shutdown(self, caller_id: str, msg: str = "") -> list[Any]:
        self.bus.shutdown_node(self.name, f"{caller_id}: {msg}")
        return [1, "shutdown", 0]
