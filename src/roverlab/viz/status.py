"""The dashboard's status tree: rviz's per-display status, as the page's Displays panel shows it.

:class:`DisplayStatus`, a base class of :class:`~roverlab.viz.bridge.VizBridge`, builds the
tree (:meth:`DisplayStatus.status`): the fixed frame and unsupported displays globally, and
per display whether its topic has the right type, publishers and messages, its transforms,
the robot description's links, and what its handler reported. :class:`TopicInfo` is one
topic of the running system, as the topic list shows it and the status checks it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from roverlab.tf import Buffer
from roverlab.viz.config import DISPLAY_KINDS, DashboardConfig
from roverlab.viz.handlers import DisplayState
from roverlab.viz.protocol import VisualOutline

__all__ = ["DisplayStatus", "TopicInfo"]


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
                info = infos.get(cfg.topic)
                types = DISPLAY_KINDS[cfg.kind].types
                if info is not None and info.typename not in types:
                    entries.append(
                        ["error", "Topic", f"{cfg.topic} carries {info.typename}, not {types[0]}"]
                    )
                elif info is None or info.publishers == 0:
                    text = f"No publisher on {cfg.topic}"
                    if d.received:
                        text += f" ({d.received} messages received)"
                    entries.append(["warn", "Topic", text])
                elif d.received == 0:
                    entries.append(["warn", "Topic", f"No messages received on {cfg.topic}"])
                else:
                    entries.append(["ok", "Topic", f"{d.received} messages received"])
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
