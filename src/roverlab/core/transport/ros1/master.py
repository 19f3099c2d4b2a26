"""The ROS 1 master: the master API and the parameter server over XML-RPC.

Methods, arguments and answers follow ros_comm's rosmaster (``[code, statusMessage,
value]``; code 1 success, -1 a caller error, 0 a failure). Callbacks to nodes
(``publisherUpdate``, ``paramUpdate``, ``shutdown``) go out one in flight per node. A node
name registered again from another URI shuts the old node down and takes its place.
This module imports nothing above ``core``.
"""

from __future__ import annotations

import functools
import logging
import os
import threading
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from roverlab.core.transport.ros1.names import canonical, resolve_name
from roverlab.core.transport.ros1.notify import Notifier
from roverlab.core.transport.ros1.params import ParamTree, compute_updates
from roverlab.core.transport.ros1.xmlrpc import XmlRpcServer, proxy

__all__ = ["DEFAULT_MASTER_PORT", "Master"]

DEFAULT_MASTER_PORT = 11311
_log = logging.getLogger("roverlab.roscore")

Reply = list[Any]


def _api(fn: Callable[..., Reply]) -> Callable[..., Reply]:
    """A master API method: bad arguments give code -1 instead of an XML-RPC fault."""

    @functools.wraps(fn)
    def wrapper(self: Master, *args: Any) -> Reply:
        for arg in args:
            if isinstance(arg, str) and not arg and fn.__name__ not in _EMPTY_OK:
                return [-1, f"{fn.__name__}: empty name", 0]
        try:
            with self._lock:
                return fn(self, *args)
        except (TypeError, ValueError) as err:
            return [-1, f"{fn.__name__}: {err}", 0]

    return wrapper


_EMPTY_OK = {"getPublishedTopics", "setParam", "shutdown"}
_API_METHODS = [
    "getPid",
    "getUri",
    "shutdown",
    "registerService",
    "lookupService",
    "unregisterService",
    "registerSubscriber",
    "unregisterSubscriber",
    "registerPublisher",
    "unregisterPublisher",
    "lookupNode",
    "getPublishedTopics",
    "getTopicTypes",
    "getSystemState",
    "setParam",
    "getParam",
    "deleteParam",
    "hasParam",
    "searchParam",
    "getParamNames",
    "subscribeParam",
    "unsubscribeParam",
]


def _callback(api: str, method: str, *args: Any) -> Any:
    """Call a node's slave API as the master (its answer is not needed)."""
    return getattr(proxy(api, 10.0), method)("/master", *args)


@dataclass
class _NodeRef:
    api: str
    topics_pub: set[str] = field(default_factory=set)
    topics_sub: set[str] = field(default_factory=set)
    services: set[str] = field(default_factory=set)
    params: set[str] = field(default_factory=set)

    def empty(self) -> bool:
        return not (self.topics_pub or self.topics_sub or self.services or self.params)


class Master:
    """rosmaster's state and API, served by :meth:`start` on ``host:port``."""

    def __init__(self, host: str = "127.0.0.1", port: int = DEFAULT_MASTER_PORT) -> None:
        self._lock = threading.RLock()
        self.params = ParamTree()
        self.publishers: dict[str, list[tuple[str, str]]] = {}
        self.subscribers: dict[str, list[tuple[str, str]]] = {}
        self.services: dict[str, tuple[str, str, str]] = {}  # name -> (node, srv uri, api)
        self.param_subs: dict[str, list[tuple[str, str]]] = {}
        self.topic_types: dict[str, str] = {}
        self.nodes: dict[str, _NodeRef] = {}
        self.notifier = Notifier(lambda api, err: _log.debug("callback to %s: %s", api, err))
        self.server = XmlRpcServer(host, port)
        self.shutdown_requested = threading.Event()
        for name in _API_METHODS:
            self.server.add(name, getattr(self, name))
        self.server.register_multicall_functions()  # roslaunch uploads parameters so
        self.params.set("/run_id", str(uuid.uuid1()))
        self._thread: threading.Thread | None = None

    @property
    def uri(self) -> str:
        return self.server.uri

    def start(self) -> None:
        self._thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self.notifier.close()
        if self._thread is not None:  # shutdown() waits for a serve_forever that runs
            self.server.shutdown()
        self.server.server_close()

    # ------------------------------------------------------------------ nodes
    def _register_node(self, caller_id: str, caller_api: str) -> _NodeRef:
        ref = self.nodes.get(caller_id)
        if ref is not None and ref.api != caller_api:
            old = ref.api
            _log.info(
                "node %s registered again from %s: shutting down %s", caller_id, caller_api, old
            )
            self._drop_node(caller_id)
            self.notifier.post(
                old,
                "shutdown",
                "",
                lambda: proxy(old, 5.0).shutdown(
                    "/master", f"[{caller_id}] Reason: new node registered with same name"
                ),
            )
            ref = None
        if ref is None:
            ref = self.nodes[caller_id] = _NodeRef(caller_api)
        return ref

    def _drop_node(self, caller_id: str) -> None:
        ref = self.nodes.pop(caller_id, None)
        if ref is None:
            return
        for topic in ref.topics_pub:
            self._remove(self.publishers, topic, caller_id)
            self._publisher_update(topic)
        for topic in ref.topics_sub:
            self._remove(self.subscribers, topic, caller_id)
        for srv in ref.services:
            self.services.pop(srv, None)
        for key in ref.params:
            self._remove(self.param_subs, key, caller_id)

    def _maybe_forget(self, caller_id: str) -> None:
        ref = self.nodes.get(caller_id)
        if ref is not None and ref.empty():
            del self.nodes[caller_id]

    @staticmethod
    def _remove(table: dict[str, list[tuple[str, str]]], key: str, caller_id: str) -> int:
        regs = table.get(key, [])
        keep = [r for r in regs if r[0] != caller_id]
        if keep:
            table[key] = keep
        else:
            table.pop(key, None)
        return len(regs) - len(keep)

    @staticmethod
    def _add(table: dict[str, list[tuple[str, str]]], key: str, caller_id: str, api: str) -> None:
        regs = [r for r in table.get(key, []) if r[0] != caller_id]
        regs.append((caller_id, api))
        table[key] = regs

    def _publisher_update(self, topic: str) -> None:
        pubs = [api for _, api in self.publishers.get(topic, [])]
        for _, api in self.subscribers.get(topic, []):
            self.notifier.post(
                api,
                "publisherUpdate",
                topic,
                functools.partial(_callback, api, "publisherUpdate", topic, pubs),
            )

    # ------------------------------------------------------------------ master API
    @_api
    def getPid(self, caller_id: str) -> Reply:
        return [1, "", os.getpid()]

    @_api
    def getUri(self, caller_id: str) -> Reply:
        return [1, "", self.uri]

    @_api
    def shutdown(self, caller_id: str, msg: str = "") -> Reply:
        _log.info("shutdown request from %s: %s", caller_id, msg)
        self.shutdown_requested.set()
        return [1, "shutdown", 0]

    @_api
    def registerService(
        self, caller_id: str, service: str, service_api: str, caller_api: str
    ) -> Reply:
        service = resolve_name(service, caller_id)
        ref = self._register_node(caller_id, caller_api)
        self.services[service] = (caller_id, service_api, caller_api)
        ref.services.add(service)
        return [1, f"Registered [{caller_id}] as provider of [{service}]", 1]

    @_api
    def lookupService(self, caller_id: str, service: str) -> Reply:
        service = resolve_name(service, caller_id)
        entry = self.services.get(service)
        if entry is None:
            return [-1, f"no provider for [{service}]", ""]
        return [1, f"rosrpc URI: [{entry[1]}]", entry[1]]

    @_api
    def unregisterService(self, caller_id: str, service: str, service_api: str) -> Reply:
        service = resolve_name(service, caller_id)
        entry = self.services.get(service)
        if entry is None or entry[0] != caller_id or entry[1] != service_api:
            return [1, f"[{caller_id}] is not a provider of [{service}]", 0]
        del self.services[service]
        ref = self.nodes.get(caller_id)
        if ref is not None:
            ref.services.discard(service)
            self._maybe_forget(caller_id)
        return [1, f"Unregistered [{caller_id}] as provider of [{service}]", 1]

    @_api
    def registerSubscriber(
        self, caller_id: str, topic: str, topic_type: str, caller_api: str
    ) -> Reply:
        topic = resolve_name(topic, caller_id)
        ref = self._register_node(caller_id, caller_api)
        self._add(self.subscribers, topic, caller_id, caller_api)
        ref.topics_sub.add(topic)
        if topic_type != "*":
            self.topic_types.setdefault(topic, topic_type)
        pubs = [api for _, api in self.publishers.get(topic, [])]
        return [1, f"Subscribed to [{topic}]", pubs]

    @_api
    def unregisterSubscriber(self, caller_id: str, topic: str, caller_api: str) -> Reply:
        topic = resolve_name(topic, caller_id)
        n = self._remove(self.subscribers, topic, caller_id)
        ref = self.nodes.get(caller_id)
        if ref is not None:
            ref.topics_sub.discard(topic)
            self._maybe_forget(caller_id)
        return [1, f"Unregistered [{caller_id}] as subscriber of [{topic}]", min(n, 1)]

    @_api
    def registerPublisher(
        self, caller_id: str, topic: str, topic_type: str, caller_api: str
    ) -> Reply:
        topic = resolve_name(topic, caller_id)
        ref = self._register_node(caller_id, caller_api)
        self._add(self.publishers, topic, caller_id, caller_api)
        ref.topics_pub.add(topic)
        if topic_type != "*":
            self.topic_types[topic] = topic_type
        self._publisher_update(topic)
        subs = [api for _, api in self.subscribers.get(topic, [])]
        return [1, f"Registered [{caller_id}] as publisher of [{topic}]", subs]

    @_api
    def unregisterPublisher(self, caller_id: str, topic: str, caller_api: str) -> Reply:
        topic = resolve_name(topic, caller_id)
        n = self._remove(self.publishers, topic, caller_id)
        ref = self.nodes.get(caller_id)
        if ref is not None:
            ref.topics_pub.discard(topic)
            self._maybe_forget(caller_id)
        if n:
            self._publisher_update(topic)
        return [1, f"Unregistered [{caller_id}] as publisher of [{topic}]", min(n, 1)]

    @_api
    def lookupNode(self, caller_id: str, node_name: str) -> Reply:
        ref = self.nodes.get(resolve_name(node_name, caller_id))
        if ref is None:
            return [-1, f"unknown node [{node_name}]", ""]
        return [1, f"node api for [{node_name}]", ref.api]

    @_api
    def getPublishedTopics(self, caller_id: str, subgraph: str) -> Reply:
        prefix = resolve_name(subgraph, caller_id) if subgraph else "/"
        prefix = prefix.rstrip("/") + "/"
        found = [
            [t, self.topic_types.get(t, "*")]
            for t in self.publishers
            if t.startswith(prefix) or prefix == "/"
        ]
        return [1, "current topics", found]

    @_api
    def getTopicTypes(self, caller_id: str) -> Reply:
        return [1, "current system topic types", [[t, ty] for t, ty in self.topic_types.items()]]

    @_api
    def getSystemState(self, caller_id: str) -> Reply:
        pubs = [[t, [c for c, _ in regs]] for t, regs in self.publishers.items()]
        subs = [[t, [c for c, _ in regs]] for t, regs in self.subscribers.items()]
        srvs = [[s, [entry[0]]] for s, entry in self.services.items()]
        return [1, "current system state", [pubs, subs, srvs]]

    # ------------------------------------------------------------------ parameter server
    def _notify_params(self, key: str, value: Any, ignore: str | None = None) -> None:
        for sub, upd_key, val in compute_updates(list(self.param_subs), key, value):
            for caller_id, api in self.param_subs.get(sub, []):
                if caller_id == ignore:
                    continue
                self.notifier.post(
                    api,
                    "paramUpdate",
                    upd_key,
                    functools.partial(_callback, api, "paramUpdate", upd_key, val),
                )

    @_api
    def setParam(self, caller_id: str, key: str, value: Any) -> Reply:
        key = resolve_name(key, caller_id)
        self.params.set(key, value)
        self._notify_params(key, value, ignore=caller_id)
        return [1, f"parameter {key} set", 0]

    @_api
    def getParam(self, caller_id: str, key: str) -> Reply:
        key = resolve_name(key, caller_id)
        try:
            return [1, f"Parameter [{key}]", self.params.get(key)]
        except KeyError:
            return [-1, f"Parameter [{key}] is not set", 0]

    @_api
    def deleteParam(self, caller_id: str, key: str) -> Reply:
        key = resolve_name(key, caller_id)
        try:
            self.params.delete(key)
        except KeyError:
            return [-1, f"parameter [{key}] is not set", 0]
        self._notify_params(key, {})
        return [1, f"parameter {key} deleted", 0]

    @_api
    def hasParam(self, caller_id: str, key: str) -> Reply:
        key = resolve_name(key, caller_id)
        return [1, key, self.params.has(key)]

    @_api
    def searchParam(self, caller_id: str, key: str) -> Reply:
        found = self.params.search(canonical(caller_id), key)
        if found is None:
            return [-1, f"Cannot find parameter [{key}] in an upwards search", ""]
        return [1, f"Found [{found}]", found]

    @_api
    def getParamNames(self, caller_id: str) -> Reply:
        return [1, "Parameter names", self.params.names()]

    @_api
    def subscribeParam(self, caller_id: str, caller_api: str, key: str) -> Reply:
        key = resolve_name(key, caller_id)
        sub = key if key == "/" else key + "/"
        ref = self._register_node(caller_id, caller_api)
        self._add(self.param_subs, sub, caller_id, caller_api)
        ref.params.add(sub)
        try:
            value = self.params.get(key)
        except KeyError:
            value = {}
        return [1, f"Subscribed to parameter [{key}]", value]

    @_api
    def unsubscribeParam(self, caller_id: str, caller_api: str, key: str) -> Reply:
        key = resolve_name(key, caller_id)
        sub = key if key == "/" else key + "/"
        n = self._remove(self.param_subs, sub, caller_id)
        ref = self.nodes.get(caller_id)
        if ref is not None:
            ref.params.discard(sub)
            self._maybe_forget(caller_id)
        return [1, f"Unsubscribe to parameter [{key}]", min(n, 1)]
