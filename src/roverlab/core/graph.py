"""Names and topics of one process's node graph."""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from roverlab.core.errors import InvalidTopicNameError, TopicTypeError

if TYPE_CHECKING:
    from roverlab.core.node import Publisher, Subscription
    from roverlab.core.services import Service

__all__ = ["Topic", "TopicGraph", "resolve_name", "validate_node_name"]

_TOKEN = re.compile(r"^[A-Za-z0-9_]+$")
_NODE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


def validate_node_name(name: str) -> str:
    if not _NODE.match(name):
        raise InvalidTopicNameError(
            f"invalid node name {name!r}: use letters, digits and '_', not starting with a digit"
        )
    return name


def _normalize_namespace(namespace: str) -> str:
    ns = "/" + namespace.strip("/") if namespace.strip("/") else "/"
    if ns != "/":
        for tok in ns[1:].split("/"):
            if not _TOKEN.match(tok):
                raise InvalidTopicNameError(f"invalid namespace {namespace!r}")
    return ns


def resolve_name(name: str, namespace: str = "/", node_name: str = "") -> str:
    """Expand a topic name as ROS does: ``/abs``, ``rel`` -> ``/ns/rel``, ``~/p`` -> ``/ns/node/p``.

    Raises InvalidTopicNameError for empty names, ``//``, trailing ``/`` or bad characters.
    """
    if not isinstance(name, str) or not name:
        raise InvalidTopicNameError(f"invalid topic name {name!r}: empty")
    ns = _normalize_namespace(namespace)
    base = ns.rstrip("/")
    if name.startswith("~"):
        if not node_name:
            raise InvalidTopicNameError(f"invalid topic name {name!r}: '~' needs a node")
        rest = name[1:].lstrip("/")
        full = f"{base}/{node_name}" + (f"/{rest}" if rest else "")
    elif name.startswith("/"):
        full = name
    else:
        full = f"{base}/{name}"
    tokens = full[1:].split("/")
    if full.endswith("/") or any(not t for t in tokens):
        raise InvalidTopicNameError(f"invalid topic name {name!r}: empty token or trailing '/'")
    for tok in tokens:
        if not _TOKEN.match(tok):
            raise InvalidTopicNameError(
                f"invalid topic name {name!r}: token {tok!r} may only hold letters, digits and '_'"
            )
    if full[1].isdigit():
        raise InvalidTopicNameError(f"invalid topic name {name!r}: must not start with a digit")
    return full


@dataclass(eq=False)
class Topic:
    """One topic: its type and the local publishers and subscriptions on it.

    ``remote_send`` is set by a transport while someone outside this process listens; the
    publish path calls it after local delivery.
    """

    name: str
    typename: str
    publishers: list[Publisher] = field(default_factory=list)
    subscriptions: list[Subscription] = field(default_factory=list)
    remote_send: Callable[[Any], None] | None = None
    published: int = 0
    listener_watchers: list[Callable[[], None]] = field(default_factory=list)

    def notify_listeners(self) -> None:
        """Someone started listening: wake the publishers that paused (executor thread)."""
        watchers, self.listener_watchers = self.listener_watchers, []
        for watcher in watchers:
            watcher()

    def latched_history(self) -> list[Any]:
        """Messages of transient-local publishers, oldest first, for a late subscriber."""
        return [msg for _, msg in self.latched_history_numbered()]

    def latched_history_numbered(self) -> list[tuple[int, Any]]:
        """:meth:`latched_history` with each message's number in the topic's order
        (``published`` when it was published), oldest first across publishers."""
        # list() copies a deque atomically: another thread (Zenoh's) may read this
        out = [entry for pub in list(self.publishers) if pub.history for entry in list(pub.history)]
        out.sort(key=lambda entry: entry[0])
        return out


class TopicGraph:
    """Topics of one context, keyed by resolved name, each with one message type; and
    its service servers, one per resolved service name."""

    def __init__(self) -> None:
        self.topics: dict[str, Topic] = {}
        self.services: dict[str, Service] = {}
        self._shadowed: dict[str, list[Service]] = {}

    def add_service(self, service: Service) -> Service | None:
        """Make ``service`` the server of its name; returns the one it takes over from
        (ROS 1's master does the same: the newest registration serves, with a warning)."""
        other = self.services.get(service.srv_name)
        if other is not None:
            self._shadowed.setdefault(service.srv_name, []).append(other)
        self.services[service.srv_name] = service
        return other

    def remove_service(self, service: Service) -> None:
        name = service.srv_name
        older = self._shadowed.get(name, [])
        if service in older:
            older.remove(service)
        elif self.services.get(name) is service:
            if older:
                self.services[name] = older.pop()
            else:
                del self.services[name]
        if not older:
            self._shadowed.pop(name, None)

    def get(self, name: str, typename: str) -> Topic:
        topic = self.topics.get(name)
        if topic is None:
            topic = Topic(name, typename)
            self.topics[name] = topic
        elif topic.typename != typename:
            raise TopicTypeError(
                f"topic '{name}' carries {topic.typename}, cannot use it as {typename}"
            )
        return topic

    def prune(self, topic: Topic) -> None:
        if not topic.publishers and not topic.subscriptions:
            self.topics.pop(topic.name, None)
