"""Test fixtures of amcl: a small asymmetric room as an occupancy grid, and scans in it."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.localization.amcl import AmclMap
from roverlab.raycast import cast_grid

RES = 0.05
ORIGIN = (-1.0, -0.5)
BEARINGS = np.linspace(-math.pi, math.pi, 361)[:-1]


def room_grid() -> NDArray[np.int8]:
    """An 8 m x 5 m room (5 cm cells) with two boxes and a partition, nothing symmetric;
    outside the walls is unknown."""
    h, w = 100, 160
    d = np.full((h, w), -1, dtype=np.int8)
    d[10:90, 20:140] = 0
    d[10, 20:140] = d[89, 20:140] = 100
    d[10:90, 20] = d[10:90, 139] = 100
    d[30:42, 40:50] = 100  # box
    d[60:89, 90] = 100  # partition from the top wall
    d[20:26, 110:130] = 100  # long low box
    return d


def room_map(max_dist_m: float = 2.0) -> AmclMap:
    return AmclMap(data=room_grid(), resolution_m=RES, origin_xy=ORIGIN, max_dist_m=max_dist_m)


def scan_at(pose: SE2, *, rng: np.random.Generator | None = None, noise: float = 0.0,
            range_max: float = 10.0) -> NDArray[np.float64]:  # fmt: skip
    """Ranges of a 360-beam laser at the robot's pose (laser at the base), as amcl gets
    them: beams at :data:`BEARINGS` in the base frame; no return is ``inf``."""
    r = cast_grid(room_grid(), RES, ORIGIN, pose.x, pose.y, BEARINGS + pose.theta, range_max)
    if rng is not None and noise > 0.0:
        r = r + rng.normal(0.0, noise, r.shape)
    return np.asarray(r, dtype=np.float64)
