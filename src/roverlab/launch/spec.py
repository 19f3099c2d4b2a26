"""What a launch file asks for: its nodes and parameters, read by :mod:`.xml`."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["LaunchSpec", "NodeSpec"]


@dataclass
class NodeSpec:
    """One ``<node>``: what to run, with its private parameters and remappings."""

    pkg: str
    type: str
    name: str
    namespace: str = "/"
    args: str = ""
    params: dict[str, Any] = field(default_factory=dict)
    remaps: dict[str, str] = field(default_factory=dict)
    source: str = ""
    output: str = "log"  # roslaunch's default: INFO to the node's log file, WARN+ to screen
    respawn: bool = False
    respawn_delay: float = 0.0  # wall seconds
    required: bool = False
    env: dict[str, str] = field(default_factory=dict)  # <env> of its scope
    clear_params: bool = False
    cwd: str | None = None  # a script node's working directory: ROS_HOME (None) or node
    launch_prefix: str = ""  # put before a script node's command (xterm -e, nice, ...)

    @property
    def fq_name(self) -> str:
        return self.namespace.rstrip("/") + "/" + self.name


@dataclass
class LaunchSpec:
    """Everything a launch file (with its includes) asks for."""

    nodes: list[NodeSpec] = field(default_factory=list)
    params: dict[str, Any] = field(default_factory=dict)  # global (absolute) names
    # global name -> where its value came from, for messages about it: the file a
    # <param command="xacro FILE"> or textfile= read, else the launch file's element
    param_sources: dict[str, str] = field(default_factory=dict)
    files: list[Path] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # what roslaunch would warn about
