"""The dashboard's status tree: rviz's per-display status, as the page's Displays panel shows it.

:class:`DisplayStatus`, a base class of :class:`~roverlab.viz.bridge.VizBridge`, builds the
tree (:meth:`DisplayStatus.status`): the fixed frame and unsupported displays globally, and
per display whether its topic has the right type, publishers and messages, its transforms,
the robot description's links, and what its handler reported. :class:`TopicInfo` is one
topic of the running system, as the topic list shows it and the status checks it;
:class:`RateMeter` turns message counts (this process's and the others', see
:mod:`roverlab.core.transport.zenoh_stats`) into each topic's rate.

A display's topic row follows rviz: messages arriving is OK (``N messages received``),
whatever the graph says (another process's publishers may not be known yet). It warns only
when nothing arrived: nothing at all :data:`QUIET_AFTER_S` (``quiet_after_s``) after
subscribing, or, for a streaming display (scan, cloud, image, odometry), nothing for that
long since the last message, and it names the cause it can see: another type on the topic
(an error), no publisher, or a publisher that sends nothing.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from roverlab.tf import Buffer
from roverlab.viz.config import DISPLAY_KINDS, DashboardConfig
from roverlab.viz.handlers import DisplayState
from roverlab.viz.protocol import VisualOutline

__all__ = ["QUIET_AFTER_S", "STREAMING_KINDS", "DisplayStatus", "RateMeter", "TopicInfo"]

QUIET_AFTER_S: Final = 5.0
"""Wall seconds without a message before a display's topic row warns."""
STREAMING_KINDS: Final = frozenset({"laser_scan", "point_cloud2", "image", "odometry"})
"""Displays of topics published continuously: a stream that stops is a warning (a map, a
plan or a marker that came once and stays is not)."""
_RATE_MIN_SPAN_S: Final = 0.5


class RateMeter:
    """Messages per second of each topic from cumulative counts of several sources
    (this process, other processes), each sampled when it was read.

    Args:
        window_s: the rate is measured over about this many seconds.
    """

    def __init__(self, window_s: float = 3.0) -> None:
        self.window_s = window_s
        self._samples: dict[tuple[str, str], deque[tuple[float, int]]] = {}

    def observe(self, source: str, now: float, counts: Mapping[str, int]) -> None:
        """The cumulative message count of each topic of ``source`` at ``now``; a count
        that went down (the process restarted) starts the topic's samples again."""
        for topic, count in counts.items():
            samples = self._samples.setdefault((source, topic), deque())
            if samples and count < samples[-1][1]:
                samples.clear()
            samples.append((now, count))
            while len(samples) > 2 and now - samples[1][0] >= self.window_s:
                samples.popleft()

    def rates(self, now: float) -> dict[str, float]:
        """Each measurable topic's rate (sum over its sources); sources not heard from
        for two windows are forgotten."""
        out: dict[str, float] = {}
        for key, samples in list(self._samples.items()):
            if now - samples[-1][0] > 2 * self.window_s:
                del self._samples[key]
                continue
            (t0, c0), (t1, c1) = samples[0], samples[-1]
            if t1 - t0 >= _RATE_MIN_SPAN_S:
                out[key[1]] = out.get(key[1], 0.0) + (c1 - c0) / (t1 - t0)
        return out


@dataclass(frozen=True)
class TopicInfo:
    """One topic of the running system, as the topic list shows it."""

    name: str
    typename: str
    publishers: int
    subscribers: int


class DisplayStatus:
    """The status tree of the dashboard's displays; the subclass
    (:class:`~roverlab.viz.bridge.VizBridge`) provides the state below, the fixed frame
    and the topic list."""

    config: DashboardConfig
    tf_buffer: Buffer
    displays: list[DisplayState]
    quiet_after_s: float = QUIET_AFTER_S

    @property
    def fixed_frame(self) -> str:
        raise NotImplementedError

    def topics(self) -> list[TopicInfo]:
        raise NotImplementedError

    def status(
        self, frames: dict[str, list[float]], outlines: list[VisualOutline]
    ) -> dict[str, Any]:
        """The status tree: ``{"global": [[level, name, text], ...], "displays": [...]}``."""
        infos = {t.name: t for t in self.topics()}
        now = time.monotonic()
        want = self.config.fixed_frame
        glob: list[list[str]] = []
        if self.tf_buffer.has_frame(want):
            glob.append(["ok", "Fixed Frame", "OK"])
        elif self.fixed_frame != want:
            glob.append(
                ["warn", "Fixed Frame", f"Fixed Frame [{want}] does not exist; drawing in [odom]"]
            )
        else:
            glob.append(["error", "Fixed Frame", f"Fixed Frame [{want}] does not exist"])
        for item in self.config.unsupported:
            glob.append(["warn", "Unsupported display", f"{item} is not supported; skipped"])
        rows: list[list[list[str]]] = []
        for d in self.displays:
            cfg = d.config
            entries: list[list[str]] = []
            if not cfg.enabled:
                rows.append([["disabled", "Status", "disabled"]])
                continue
            if d.sub_key[0]:
                entries.append(self._topic_row(d, infos.get(cfg.topic), now))
            elif cfg.kind == "robot_model":
                if not outlines:
                    entries.append(["warn", "URDF", f"No robot description on {cfg.topic}"])
                else:
                    missing = sorted({o.link for o in outlines} - set(frames) - {self.fixed_frame})
                    if missing:
                        entries.append(
                            ["error", "Transform", f"No transform for link(s) {', '.join(missing)}"]
                        )
                    else:
                        entries.append(["ok", "URDF", f"{len(outlines)} visuals"])
            elif cfg.kind == "grid":
                ref = str(cfg.option("reference_frame"))
                if ref and ref not in frames and ref != self.fixed_frame:
                    entries.append(["error", "Transform", f"Frame [{ref}] does not exist"])
                else:
                    entries.append(["ok", "Status", "OK"])
            elif cfg.kind == "tf":
                entries.append(["ok", "Frames", f"{len(frames)} frames"])
            frame = d.info.get("frame") if cfg.kind == "map" else None
            if frame and frame not in frames and frame != self.fixed_frame:
                entries.append(
                    ["error", "Transform", f"No transform from [{frame}] to [{self.fixed_frame}]"]
                )
            elif frame:
                entries.append(["ok", "Transform", "Transform OK"])
            for name, (level, text) in d.status.items():
                entries.append([level, name, text])
            if d.error:
                entries.append(["error", "Message", d.error])
            rows.append(entries)
        return {"global": glob, "displays": rows}

    def _topic_row(self, d: DisplayState, info: TopicInfo | None, now: float) -> list[str]:
        """The Topic row of a display: see the module's doc."""
        cfg = d.config
        types = DISPLAY_KINDS[cfg.kind].types
        if info is not None and info.typename not in types:
            return ["error", "Topic", f"{cfg.topic} carries {info.typename}, not {types[0]}"]
        since = d.last_message_s if d.received else d.subscribed_s
        quiet = now - since if since is not None else 0.0
        if d.received and (cfg.kind not in STREAMING_KINDS or quiet < self.quiet_after_s):
            return ["ok", "Topic", f"{d.received} messages received"]
        if d.received == 0 and quiet < self.quiet_after_s:
            return ["ok", "Topic", f"Subscribed to {cfg.topic}; waiting for messages"]
        cause = (
            "no publisher"
            if info is None or info.publishers == 0
            else f"{info.publishers} publisher(s) sent nothing"
        )
        if d.received:
            text = f"No messages on {cfg.topic} for {quiet:.0f} s ({cause}; "
            return ["warn", "Topic", text + f"{d.received} messages received before)"]
        if cause == "no publisher":
            return ["warn", "Topic", f"No publisher on {cfg.topic}"]
        return ["warn", "Topic", f"No messages received on {cfg.topic} for {quiet:.0f} s ({cause})"]
