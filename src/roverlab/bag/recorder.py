"""Record a context's topics to an MCAP file, as ``ros2 bag record -a -s mcap``.

The file holds ROS 2 CDR messages with ``ros2msg`` schemas, so rosbags
(``AnyReader([path])``), Foxglove Studio and ``ros2 bag`` read it. It is written to
``NAME.part`` and renamed when closed: an interrupted run never leaves a file that looks
complete. Chunks are closed and flushed about every second (``flush_period_s``): a
process killed with SIGKILL loses at most that much, and ``roverlab bag recover NAME.part``
(:func:`roverlab.bag.recover`) turns what is on disk into a readable file.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO, Any

from mcap.writer import CompressionType, Writer

from roverlab.core import Context, Node, Publisher, QoSProfile, Subscription
from roverlab.errors import RoverlabError
from roverlab.msgs import message_definition, serialize

__all__ = ["BagError", "McapRecorder"]


class BagError(RoverlabError):
    """A bag could not be written or read."""


class McapRecorder:
    """Subscribes to every topic of a context (present and future) and writes MCAP.

    Attach it with ``context.add_transport(recorder)``; ``context.shutdown()`` (or
    :meth:`close`) finishes the file.

    Args:
        path: the ``.mcap`` file to write.
        topics: record only these topics (default: all).
        exclude: topics never recorded.
        compression: ``"zstd"`` (default), ``"lz4"`` or ``"none"``.
        flush_period_s: close the chunk in progress and flush the file this often (wall
            seconds), so a killed process loses at most about that much.
        clock: ``None``: stamp messages with the context's clock (sim time in a
            simulation); else a callable giving nanoseconds (e.g. the wall clock).
    """

    def __init__(
        self,
        path: str | Path,
        *,
        topics: Iterable[str] | None = None,
        exclude: Iterable[str] = (),
        compression: str = "zstd",
        flush_period_s: float = 1.0,
        clock: Callable[[], int] | None = None,
    ) -> None:
        self.path = Path(path)
        self._part = self.path.with_name(self.path.name + ".part")
        self.only = set(topics) if topics is not None else None
        self.exclude = set(exclude)
        try:
            comp = {
                "zstd": CompressionType.ZSTD,
                "lz4": CompressionType.LZ4,
                "none": CompressionType.NONE,
            }[compression]
        except KeyError:
            raise BagError(
                f"unknown MCAP compression {compression!r} (zstd, lz4 or none)"
            ) from None
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fh: IO[bytes] | None = open(self._part, "wb")  # noqa: SIM115 - closed in close()
        except OSError as err:
            raise BagError(f"{self.path}: cannot write: {err.strerror}") from err
        self._writer = Writer(self._fh, compression=comp)
        self._writer.start(profile="ros2", library="roverlab")
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
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
        self._node = Node("rosbag2_recorder", context=context)

        # flush even while nothing arrives (wall period; the executor's clock may be sim)
        assert self._node is not None
        self._node.create_timer(min(max(self.flush_period_s, 0.05), 0.5), self._maybe_flush)

    def on_node(self, node: Node, added: bool) -> None:
        pass

    def on_publisher(self, pub: Publisher, added: bool) -> None:
        if added and pub.node is not self._node:
            self._record(pub.topic.name, pub.topic.typename)

    def on_subscription(self, sub: Subscription, added: bool) -> None:
        # a topic only subscribed here still carries messages from other processes
        if added and sub.node is not self._node:
            self._record(sub.topic.name, sub.topic.typename)

    def close(self) -> None:
        if self._fh is None:
            return
        self._writer.finish()
        self._fh.flush()
        os.fsync(self._fh.fileno())
        self._fh.close()
        self._fh = None
        os.replace(self._part, self.path)

    # ------------------------------------------------------------- recording
    @property
    def topics(self) -> list[str]:
        """The topics recorded so far."""
        return sorted(self._channels)

    def record(self, topic: str, typename: str) -> None:
        """Record ``topic`` (e.g. one found in another process) from now on."""
        self._record(topic, typename)

    def _maybe_flush(self) -> None:
        now = time.monotonic()
        if self._fh is not None and now - self._last_flush >= self.flush_period_s:
            self._last_flush = now
            self._writer.flush()  # ends the chunk in progress: complete on disk

    def _record(self, topic: str, typename: str) -> None:
        if self._fh is None or topic in self._channels or topic in self.exclude:
            return
        if self.only is not None and topic not in self.only:
            return
        schema = self._schemas.get(typename)
        if schema is None:
            text = message_definition(typename)
            schema = self._writer.register_schema(
                name=typename, encoding="ros2msg", data=text.encode()
            )
            self._schemas[typename] = schema
        channel = self._writer.register_channel(
            topic=topic, message_encoding="cdr", schema_id=schema
        )
        self._channels[topic] = channel
        assert self._node is not None and self._context is not None
        ex = self._context.executor
        clock = self._clock
        writer = self._writer
        counts = self.counts
        counts[topic] = 0

        def write(msg: Any) -> None:
            if self._fh is None:
                return
            t = ex.now_ns if clock is None else clock()
            writer.add_message(channel_id=channel, log_time=t, publish_time=t, data=serialize(msg))
            self.messages += 1
            counts[topic] += 1
            if time.monotonic() - self._last_flush >= self.flush_period_s:
                self._maybe_flush()

        self._subs.append(
            self._node.create_subscription(typename, topic, write, QoSProfile(depth=1000))
        )

    def abort(self) -> None:
        """Drop the partial file (for errors before anything useful was recorded)."""
        if self._fh is not None:
            self._fh.close()
            self._fh = None
        with contextlib.suppress(OSError):
            self._part.unlink()
