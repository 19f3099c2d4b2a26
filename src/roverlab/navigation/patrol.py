"""Seed 002's patrol (slam.py) as an algorithm: places, their random order, the statistics.

slam.py visits its places in random rounds (each round a random permutation; a round
whose first place is the one just visited starts at its second), logs where it goes, and
keeps the success count, the distance between the places it reached and the running time.
The runner (``roverlab patrol``) sends the goals through the move_base action.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from roverlab.errors import RoverlabError, yaml_reason

__all__ = ["PatrolError", "PatrolSequence", "PatrolStats", "Place", "load_places", "trunc"]


class PatrolError(RoverlabError):
    """A malformed locations file or an unusable patrol setting."""


@dataclass(frozen=True)
class Place:
    """A named goal pose in the patrol's frame (m, rad)."""

    name: str
    x: float
    y: float
    yaw: float


def _place(name: str, value: Any, where: str) -> Place:
    if not isinstance(value, Mapping):
        raise PatrolError(f"{where}: location {name!r} must be a mapping")
    try:
        if "position" in value:  # a geometry_msgs/Pose, as slam.py writes them
            p, q = value["position"], value.get("orientation", {"w": 1.0})
            x, y = float(p.get("x", 0.0)), float(p.get("y", 0.0))
            qz, qw = float(q.get("z", 0.0)), float(q.get("w", 1.0))
            qx, qy = float(q.get("x", 0.0)), float(q.get("y", 0.0))
            if math.hypot(math.hypot(qx, qy), math.hypot(qz, qw)) < 1e-9:
                raise PatrolError(f"{where}: location {name!r} has a zero quaternion")
            yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
        else:
            x, y = float(value["x"]), float(value["y"])
            yaw = float(value.get("yaw", 0.0))
    except (KeyError, TypeError, ValueError, AttributeError) as err:
        raise PatrolError(
            f"{where}: location {name!r} needs x, y (and yaw) or position/orientation: {err}"
        ) from None
    if not all(math.isfinite(v) for v in (x, y, yaw)):
        raise PatrolError(f"{where}: location {name!r} is not finite")
    return Place(name, x, y, yaw)


def load_places(path: str | os.PathLike[str]) -> tuple[str, list[Place]]:
    """``(frame_id, places)`` from a YAML file::

        frame_id: map
        locations:
          kitchen: {x: 2.0, y: 0.0, yaw: 0.0}
          "2": {position: {x: 4.231, y: -6.05}, orientation: {z: -0.847, w: 0.532}}

    Raises:
        PatrolError: an unreadable or malformed file (one line naming it).
    """
    p = Path(path)
    try:
        data = yaml.safe_load(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise PatrolError(f"{p}: cannot read: {err.strerror}") from err
    except yaml.YAMLError as err:
        raise PatrolError(f"{p}: malformed YAML: {yaml_reason(err)}") from err
    if not isinstance(data, Mapping) or not isinstance(data.get("locations"), Mapping):
        raise PatrolError(f"{p}: expected a mapping with 'locations: {{name: pose, ...}}'")
    places = [_place(str(k), v, str(p)) for k, v in data["locations"].items()]
    if len(places) < 2:
        raise PatrolError(f"{p}: a patrol needs at least two locations")
    return str(data.get("frame_id", "map")), places


@dataclass
class PatrolSequence:
    """slam.py's order: random rounds, never the same place twice in a row."""

    places: list[Place]
    rng: np.random.Generator
    _round: list[Place] = field(default_factory=list)
    _i: int = 0
    last: Place | None = None

    def __post_init__(self) -> None:
        if len(self.places) < 2:
            raise PatrolError("a patrol needs at least two locations")
        self._i = len(self.places)

    def next(self) -> Place:
        n = len(self.places)
        if self._i == n:
            self._i = 0
            self._round = [self.places[k] for k in self.rng.permutation(n)]
            if self._round[0] == self.last:
                self._i = 1
        place = self._round[self._i]
        self._i += 1
        self.last = place
        return place


def trunc(f: float, n: int) -> float:
    """slam.py's ``trunc``: ``f`` cut (not rounded) to ``n`` decimals."""
    text = f"{f:.{n}f}"
    return float(repr(float(f))[: len(text)]) if "e" not in repr(float(f)) else float(text)


@dataclass
class PatrolStats:
    """What slam.py counts and prints."""

    goals: int = 0
    successes: int = 0
    distance_m: float = 0.0

    def success_line(self) -> str:
        pct = 100 * self.successes // self.goals if self.goals else 0
        return f"Success so far: {self.successes}/{self.goals} = {pct}%"

    def time_line(self, running_s: float) -> str:
        minutes = int(running_s) / 60.0  # slam.py: Duration.secs / 60.0
        return f"Running time: {trunc(minutes, 1)} min Distance: {trunc(self.distance_m, 1)} m"
