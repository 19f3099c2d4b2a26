"""Is a map bent? The directions of its long corridors, from the scans, at the estimate.

A log without ground-truth relations (mit-csail) can still tell a bent or split map: the
stretches of the log where the robot drives along one long straight corridor must put that
corridor at one heading in the map, however far apart in time or along the corridor they
are, and corridors the building has at right angles to it must stay at right angles. A map
bent at a junction turns every corridor after the bend against those before it.

The direction of a corridor in one scan comes from the scan alone, not from the map: the
weak direction of the scan's surface normals (:func:`roverlab.slam.degeneracy.
scan_constraint`) is the direction along the walls, in the robot frame; at the estimated
pose it is the corridor's direction in the map frame (modulo 180 degrees). A stretch's
direction is the mean over its corridor scans (those whose eigenvalue ratio is below
``max_ratio``: two parallel walls and little else). So the check compares headings the
estimate gives to scans it saw minutes apart, which no tuning on one stretch can fake.

:data:`STRAIGHT_CORRIDORS` holds, per log, stretches of scans along one corridor or
corridors crossing it at right angles. For mit-csail they were read off the maps of three
independent methods (gmapping, hector without odometry, graph SLAM), which agree on every
one of them to within 3 degrees of a common axis, while the map that docs/slam.md shows
bent turns the later stretches by 10-15 degrees.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.data.errors import EvaluationError
from roverlab.slam.data.scans import LaserLog
from roverlab.slam.degeneracy import scan_constraint

__all__ = [
    "STRAIGHT_CORRIDORS",
    "Straightness",
    "corridor_axes",
    "corridor_stretches",
    "straightness",
]

#: A corridor scan: normals' eigenvalue ratio below this (a room's is above 0.2).
CORRIDOR_RATIO = 0.1

#: Per log (file name without ``.clf[.bz2]``): inclusive scan-index stretches (in the log's
#: order, as :func:`roverlab.slam.data.load_log` reads it) along mit-csail's long
#: north-west corridor (five passes over ~20 m of it, the last 15 minutes after the
#: first) and along the six corridors and doors crossing it at right angles.
STRAIGHT_CORRIDORS: dict[str, tuple[tuple[int, int], ...]] = {
    "mit-csail": (
        (579, 589),
        (628, 634),
        (654, 671),
        (1037, 1048),
        (1562, 1596),
        (719, 721),
        (991, 994),
        (1063, 1065),
        (1366, 1370),
        (1518, 1529),
        (1605, 1611),
    ),
}


class Straightness(NamedTuple):
    """How far the stretches' corridor directions are from one set of right angles.

    Attributes:
        axes_deg: each stretch's corridor direction in the map frame, degrees in
            ``[-90, 90)``.
        bend_deg: the largest angle (degrees) between two stretches' directions, modulo
            90 degrees: 0 for a straight map; a map bent by 10 degrees between two
            stretches gives 10.
        worst: the indices of those two stretches.
    """

    axes_deg: NDArray[np.float64]
    bend_deg: float
    worst: tuple[int, int]


def corridor_axes(
    log: LaserLog,
    poses: NDArray[np.float64],
    stretches: Sequence[tuple[int, int]],
    *,
    max_ratio: float = CORRIDOR_RATIO,
) -> NDArray[np.float64]:
    """The direction (rad, modulo pi, in ``[-pi/2, pi/2)``) of the corridor along each
    stretch in the map frame of ``poses``.

    Args:
        log: the log the poses were estimated from.
        poses: ``(N, 3)`` robot poses, one per scan of ``log`` (or of its first N scans).
        stretches: inclusive ``(first, last)`` scan indices.
        max_ratio: the corridor scans of a stretch are those whose normals' eigenvalue
            ratio is below this.

    Raises:
        EvaluationError: a stretch beyond the poses, or one without a corridor scan.
    """
    poses = np.asarray(poses, dtype=np.float64)
    axes = np.zeros(len(stretches))
    for j, (first, last) in enumerate(stretches):
        if not 0 <= first <= last < min(len(log), poses.shape[0]):
            raise EvaluationError(
                f"stretch {first}-{last} is not within the {poses.shape[0]} poses of "
                f"{log.source or 'the log'}"
            )
        doubled = []
        for i in range(first, last + 1):
            rec = log[i]
            ratio, weak = scan_constraint(rec.points())
            if ratio < max_ratio:
                along = math.atan2(weak[1], weak[0]) + rec.laser_offset.theta + poses[i, 2]
                doubled.append(np.exp(2j * along))
        if not doubled:
            raise EvaluationError(f"stretch {first}-{last} has no corridor scan")
        axes[j] = 0.5 * float(np.angle(np.mean(doubled)))
    return axes


def straightness(
    log: LaserLog,
    poses: NDArray[np.float64],
    stretches: Sequence[tuple[int, int]],
    *,
    max_ratio: float = CORRIDOR_RATIO,
) -> Straightness:
    """Compare the stretches' corridor directions modulo 90 degrees (see
    :func:`corridor_axes` for the arguments)."""
    axes = corridor_axes(log, poses, stretches, max_ratio=max_ratio)
    quad = np.exp(4j * axes)
    apart = np.abs(np.angle(quad[:, None] * np.conj(quad[None, :]))) / 4.0
    i, j = np.unravel_index(int(np.argmax(apart)), apart.shape)
    return Straightness(np.degrees(axes), math.degrees(float(apart[i, j])), (int(i), int(j)))


def corridor_stretches(
    log: LaserLog, *, max_ratio: float = CORRIDOR_RATIO, max_gap: int = 8, min_scans: int = 3
) -> list[tuple[int, int]]:
    """The stretches of corridor scans in a log, from the scans alone: runs of at least
    ``min_scans`` scans whose normals' eigenvalue ratio is below ``max_ratio``, broken
    where more than ``max_gap`` scans in a row are not (inclusive index pairs). Stretches
    from different corridors are at right angles only in a building whose corridors are
    (the simulated ones are; mit-csail's are not all: :data:`STRAIGHT_CORRIDORS`)."""
    corridor = [i for i, rec in enumerate(log) if scan_constraint(rec.points()).ratio < max_ratio]
    runs: list[list[int]] = []
    for i in corridor:
        if runs and i - runs[-1][-1] <= max_gap:
            runs[-1].append(i)
        else:
            runs.append([i])
    return [(r[0], r[-1]) for r in runs if len(r) >= min_scans]
