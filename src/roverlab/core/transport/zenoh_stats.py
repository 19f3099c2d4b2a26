"""Per-process topic statistics over Zenoh, as ROS 1's slave API ``getBusStats``: how many
messages each process has published on each topic, so a tool in another process (the
dashboard's topic list) can show every flowing topic's rate without subscribing to it
(subscribing would make every publisher serialise and send its images and clouds).

Key: ``rl/D/stats/<zid>``, a queryable answering JSON ``{"/scan": 1234, ...}`` (the
cumulative count of messages published on each topic with a publisher in that process).
"""

from __future__ import annotations

import json
from collections.abc import Callable

import zenoh

__all__ = ["declare_stats", "query_topic_counts", "stats_key"]


def stats_key(domain: int, zid: str) -> str:
    """The statistics queryable's key of the process ``zid``."""
    return f"rl/{domain}/stats/{zid}"


def declare_stats(
    session: zenoh.Session, domain: int, zid: str, counts: Callable[[], dict[str, int]]
) -> zenoh.Queryable[None]:
    """Answer statistics queries with ``counts()`` (called on Zenoh's thread: it must only
    read)."""

    key = stats_key(domain, zid)

    def on_query(query: zenoh.Query) -> None:
        query.reply(key, json.dumps(counts()))  # its own key: the asker tells them apart

    return session.declare_queryable(key, on_query)


def query_topic_counts(
    session: zenoh.Session, domain: int = 0, timeout_s: float = 1.0
) -> dict[str, dict[str, int]]:
    """``{zid: {topic: messages published}}`` of every process that answers."""
    out: dict[str, dict[str, int]] = {}
    for reply in session.get(f"rl/{domain}/stats/*", timeout=timeout_s):
        if reply.ok is None:
            continue
        zid = str(reply.ok.key_expr).rsplit("/", 1)[-1]
        try:
            data = json.loads(reply.ok.payload.to_bytes())
        except ValueError:
            continue
        if isinstance(data, dict):
            out[zid] = {str(k): int(v) for k, v in data.items() if isinstance(v, int)}
    return out
