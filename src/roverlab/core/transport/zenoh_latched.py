"""Latched (transient-local) topics over Zenoh: every message once, and in order.

A subscriber that joins late asks each latched publisher's process for its history (a
query), while the same publishers' new messages already reach it live. The two paths do
not keep each other's order: under load the reply can arrive after newer live messages,
or repeat one of them. A ROS 1 latched connection delivers the last message once, then
the new ones in order, and actionlib relies on it: a stale status array delivered after a
newer one makes a client drop an active goal as LOST.

So a process with a latched publisher tags each message it sends on that topic, live or
in a reply, with its Zenoh id, the message's number in the topic's order
(``Topic.published`` when it was published) and the history depth; the receiving process
delivers a tagged message only if it is newer than the last one it delivered from that
process (:class:`LatchedInbox`), and keeps the last ``depth`` of them for its own late
subscriptions.
"""

from __future__ import annotations

from collections import deque
from typing import Any, NamedTuple

__all__ = ["LatchedInbox", "Source", "parse_tag", "tag"]


class Source(NamedTuple):
    """Where a latched message came from, and its place there."""

    zid: str
    number: int
    depth: int


def tag(zid: str, number: int, depth: int) -> bytes:
    """The attachment of a message sent on a latched topic."""
    return f"{zid} {number} {depth}".encode()


def parse_tag(data: bytes | None) -> Source | None:
    """The :class:`Source` in an attachment, or None (untagged or not ours)."""
    if not data:
        return None
    try:
        zid, number, depth = data.decode("ascii").split(" ")
        return Source(zid, int(number), max(1, int(depth)))
    except (UnicodeDecodeError, ValueError):
        return None


class LatchedInbox:
    """One topic's latched messages received from other processes (executor thread)."""

    def __init__(self) -> None:
        self._last: dict[str, int] = {}
        self._kept: dict[str, deque[Any]] = {}

    def accept(self, source: Source, msg: Any) -> bool:
        """Whether ``msg`` is new (then it is kept for later local subscriptions)."""
        if source.number <= self._last.get(source.zid, -1):
            return False
        self._last[source.zid] = source.number
        kept = self._kept.get(source.zid)
        if kept is None or kept.maxlen != source.depth:
            kept = self._kept[source.zid] = deque(kept or (), maxlen=source.depth)
        kept.append(msg)
        return True

    def replay(self) -> list[Any]:
        """The kept messages, for a subscription made in this process later."""
        return [msg for kept in list(self._kept.values()) for msg in list(kept)]
