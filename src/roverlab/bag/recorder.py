"""Record a context's topics to a bag, as ``rosbag record -a`` / ``ros2 bag record -a``.

The path's extension decides the format (:mod:`roverlab.bag.writers`): ``NAME.bag`` is a ROS 1
bag that Debian's ``rosbag`` reads and plays (latched topics with ``latching=1``), ``NAME.mcap``
an MCAP file with ROS 2 CDR messages (rosbags, Foxglove Studio, ``ros2 bag``), a folder or
``NAME.db3`` a ROS 2 bag. It is written to ``NAME.part`` and renamed when closed: an
interrupted run never leaves a file that looks complete. Chunks are closed and flushed about
every second (``flush_period_s``): a process killed with SIGKILL loses at most that much, and
``roverlab bag recover NAME.part`` turns what is on disk into a readable bag.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from roverlab.bag.errors import BagError
from roverlab.bag.reader import LATCHED_TOPICS
from roverlab.bag.writers import BagWriter, open_writer
from roverlab.core import Context, Node, Publisher, QoSProfile, Subscription

__all__ = ["BagError", "BagRecorder"]


class BagRecorder:
    """Subscribes to every topic of a context (present and future) and writes a bag.

    Attach it with ``context.add_transport(recorder)``; ``context.shutdown()`` (or
    :meth:`close`) finishes the file.

    Args:
        path: The bag to write; its extension decides the format.
        topics: record only these topics (default: all).
        exclude: topics never recorded.
        compression: chunk compression (default: the format's: ``zstd`` for MCAP, none for
            ROS 1 and ROS 2 bags); ``bz2``/``lz4`` for ROS 1, ``zstd``/``lz4`` for MCAP.
        flush_period_s: close the chunk in progress and flush the file this often (wall
            seconds), so a killed process loses at most about that much.
        clock: ``None``: stamp messages with the context's clock (sim time in a
            simulation); else a callable giving nanoseconds (e.g. the wall clock).

    Raises:
        BagError: Unknown extension or compression, or the file cannot be written.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        topics: Iterable[str] | None = None,
        exclude: Iterable[str] = (),
        compression: str | None = None,
        flush_period_s: float = 1.0,
        clock: Callable[[], int] | None = None,
    ) -> None:
        self.only = set(topics) if topics is not None else None
        self.exclude = set(exclude)
        self._writer: BagWriter | None = open_writer(path, compression)
        self.path = self._writer.path
        self._part = self._writer.part
        self._handles: dict[str, int] = {}
        self._node: Node | None = None
        self._context: Context | None = None
        self._subs: list[Subscription] = []
        self.messages = 0
        self.flush_period_s = flush_period_s
        self._clock = clock
        self._last_flush = time.monotonic()
        self.counts: dict[str, int] = {}

    # ------------------------------------------------------------- Transport protocol
    def attach(self, context: Context) -> None:
        self._context = context
        self._node = Node("rosbag_record", context=context)
        # flush even while nothing arrives (wall period; the executor's clock may be sim)
        self._node.create_timer(min(max(self.flush_period_s, 0.05), 0.5), self._maybe_flush)

    def on_node(self, node: Node, added: bool) -> None:
        pass

    def on_publisher(self, pub: Publisher, added: bool) -> None:
        if added and pub.node is not self._node:
            node = pub.node.get_fully_qualified_name()
            self._record(pub.topic.name, pub.topic.typename, pub.qos.latched, node)

    def on_subscription(self, sub: Subscription, added: bool) -> None:
        # a topic only subscribed here still carries messages from other processes
        if added and sub.node is not self._node:
            self._record(sub.topic.name, sub.topic.typename, None, "")

    def close(self) -> None:
        if self._writer is None:
            return
        writer, self._writer = self._writer, None
        writer.finish()

    # ------------------------------------------------------------- recording
    @property
    def topics(self) -> list[str]:
        """The topics recorded so far."""
        return sorted(self._handles)

    def record(self, topic: str, typename: str) -> None:
        """Record ``topic`` (e.g. one found in another process) from now on."""
        self._record(topic, typename, None, "")

    def _maybe_flush(self) -> None:
        now = time.monotonic()
        if self._writer is not None and now - self._last_flush >= self.flush_period_s:
            self._last_flush = now
            self._writer.flush()

    def _record(self, topic: str, typename: str, latched: bool | None, callerid: str) -> None:
        writer = self._writer
        if writer is None or topic in self._handles or topic in self.exclude:
            return
        if self.only is not None and topic not in self.only:
            return
        if latched is None:
            latched = topic in LATCHED_TOPICS
        handle = writer.add_topic(
            topic, typename, latched=latched, callerid=callerid or "/rosbag_record"
        )
        self._handles[topic] = handle
        assert self._node is not None and self._context is not None
        ex = self._context.executor
        clock = self._clock
        counts = self.counts
        counts[topic] = 0

        def write(msg: Any) -> None:
            if self._writer is None:
                return
            t = ex.now_ns if clock is None else clock()
            writer.write(handle, t, msg)
            self.messages += 1
            counts[topic] += 1
            if time.monotonic() - self._last_flush >= self.flush_period_s:
                self._maybe_flush()

        # latched history reaches every new subscription (see core.node)
        self._subs.append(
            self._node.create_subscription(typename, topic, write, QoSProfile(depth=1000))
        )

    def abort(self) -> None:
        """Drop the partial file (for errors before anything useful was recorded)."""
        if self._writer is not None:
            writer, self._writer = self._writer, None
            writer.abort()
