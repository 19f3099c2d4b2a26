"""Play a bag into a running system, as ``ros2 bag play`` / ``rosbag play``.

Messages keep their recorded spacing (scaled by ``rate``). With ``clock`` the player also
publishes ``/clock`` at 100 Hz with the bag's time, so nodes with ``use_sim_time`` (a
``roverlab run ... --clock auto``) follow the bag, as ``rosbag play --clock`` does.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from roverlab.bag.errors import BagError
from roverlab.bag.reader import LATCHED_TOPICS, BagConnection, BagReader
from roverlab.core import Context, Publisher, QoSProfile
from roverlab.core.time import Time
from roverlab.msgs import MessageError
from roverlab.msgs import classes as mc

__all__ = ["PlayOptions", "Player", "parse_remaps"]

CLOCK_PERIOD_S = 0.01
#: latched /tf_static messages kept for late subscribers (each holds some static transforms)
STATIC_TF_DEPTH = 100


def parse_remaps(items: list[str]) -> dict[str, str]:
    """``from:=to`` pairs."""
    out: dict[str, str] = {}
    for item in items:
        a, sep, b = item.partition(":=")
        if not sep or not a or not b:
            raise BagError(f"--remap expects from:=to, got {item!r}")
        out["/" + a.lstrip("/")] = "/" + b.lstrip("/")
    return out


@dataclass
class PlayOptions:
    rate: float = 1.0
    clock: bool = False
    loop: bool = False
    topics: list[str] | None = None
    start_offset_s: float = 0.0
    remaps: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not (self.rate > 0 and math.isfinite(self.rate)):
            raise BagError(f"--rate must be a positive number, got {self.rate}")
        if not (self.start_offset_s >= 0 and math.isfinite(self.start_offset_s)):
            raise BagError(f"--start-offset must be >= 0 seconds, got {self.start_offset_s}")


class Player:
    """Publishes a bag's messages on ``context`` (spinning in another thread).

    A ROS 1 bag's latched connections (``latching=1``), and the topics ROS latches in other
    formats, are published latched. A connection whose type cannot be decoded (unknown and
    without a definition in the bag, or another version of a known type) is skipped and
    ``warn`` is told once, with the type and the reason.
    """

    def __init__(
        self,
        context: Context,
        path: str | Path,
        options: PlayOptions,
        warn: Callable[[str], None] | None = None,
    ) -> None:
        self.context = context
        self.warn = warn
        self.path = Path(path)
        self.options = options
        self.node = context.create_node("rosbag2_player")
        self._pubs: dict[tuple[str, str], Publisher] = {}
        self._clock_pub = (
            self.node.create_publisher(mc.Clock, "/clock", 10) if options.clock else None
        )
        self.published = 0
        self.loops = 0

    def _publisher(self, conn: BagConnection) -> Publisher:
        """One publisher per topic and recorded publisher (``callerid``), as rosbag play
        advertises them: a latched one keeps its newest message for late subscribers (the
        newest /map, not the first ones); /tf_static keeps every static transform."""
        key = (conn.topic, conn.callerid)
        pub = self._pubs.get(key)
        if pub is None:
            name = self.options.remaps.get(conn.topic, conn.topic)
            if conn.latched or name in LATCHED_TOPICS:
                depth = STATIC_TF_DEPTH if name == "/tf_static" else 1
                qos = QoSProfile(depth=depth, durability="transient_local")
            else:
                qos = QoSProfile(depth=100)
            pub = self.node.create_publisher(conn.typename, name, qos)
            self._pubs[key] = pub
        return pub

    def _publish_clock(self, bag_ns: int) -> None:
        if self._clock_pub is not None:
            self._clock_pub.publish(mc.Clock(clock=Time(bag_ns).to_msg()))

    def run(self, stop: threading.Event, on_start: Callable[[int, int], None] | None = None) -> int:
        """Play until the end (every loop with ``loop``) or ``stop``; returns the number of
        messages published. ``on_start(start_ns, end_ns)`` is told the bag's span."""
        opts = self.options
        while not stop.is_set():
            with BagReader(self.path) as reader:
                if reader.message_count == 0:
                    raise BagError(f"{self.path}: the bag holds no message")
                t0 = reader.start_ns + round(opts.start_offset_s * 1e9)
                if on_start is not None and self.loops == 0:
                    on_start(reader.start_ns, reader.end_ns)
                if self.loops == 0:
                    self._warn_skipped(reader)
                self._play_once(reader, t0, stop)
            self.loops += 1
            if not opts.loop:
                break
        return self.published

    def _warn_skipped(self, reader: BagReader) -> None:
        topics = self.options.topics
        for conn in reader.connections:
            if conn.problem and self.warn is not None and (topics is None or conn.topic in topics):
                self.warn(
                    f"{self.path}: skipping {conn.topic} [{conn.typename}], "
                    f"{conn.count} messages: {conn.problem}"
                )

    def _play_once(self, reader: BagReader, t0: int, stop: threading.Event) -> None:
        opts = self.options
        wall0 = time.monotonic()
        self._publish_clock(t0)

        def bag_now() -> int:
            return t0 + round((time.monotonic() - wall0) * opts.rate * 1e9)

        next_clock = wall0
        for msg in reader.messages(opts.topics, start_ns=t0):
            if msg.connection.problem:
                continue
            due = wall0 + (msg.log_time_ns - t0) / 1e9 / opts.rate
            while True:
                if stop.is_set():
                    return
                now = time.monotonic()
                if self._clock_pub is not None and now >= next_clock:
                    self._publish_clock(min(bag_now(), msg.log_time_ns))
                    next_clock = now + CLOCK_PERIOD_S
                if now >= due:
                    break
                wake = min(due, next_clock) if self._clock_pub is not None else due
                stop.wait(max(0.0, min(wake - now, 0.05)))
            try:
                data = msg.decode()
            except MessageError as err:  # bad bytes
                raise BagError(
                    f"{self.path}: cannot decode a {msg.typename} on {msg.topic} at "
                    f"{msg.log_time_ns / 1e9:.9f} s: {err}"
                ) from err
            self._publisher(msg.connection).publish(data)
            self.published += 1
        self._publish_clock(reader.end_ns)
