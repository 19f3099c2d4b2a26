"""Finding the map again on a revisit: a wide search, taken once several scans agree on it.

hector has no loop closure. When the robot comes back to a part of the map it made long ago
(a ring corridor driven round), the estimate is off by what it drifted on the way, often
more than the matcher's basin (a few coarse cells): the local match then holds on to the
nearest surfaces the map has (often the ones it has just mapped from the drifted pose), the
scan fits poorly and, mapped from there, writes a second, shifted copy of the walls that the
following scans follow.

With odometry, roverlab checks each match for it (:class:`Revisit`): when the accepted
match puts fewer than ``revisit_trigger`` of the endpoints on occupied cells, the map is
searched over ``+-revisit_search`` (m) and ``+-revisit_angle_search`` (rad) around it on the
coarsest level (every pose of the grid, :func:`wide_search`) and refined by hector's
Gauss-Newton. A candidate that fits much better (its cost ``sum (1 - M)^2`` at most
``revisit_fit_ratio`` of the match's) and lies elsewhere is a correction of the accumulated
estimate; it is taken only when ``revisit_confirmations`` scans in a row find it at places
that agree with the odometry's increments between them (within ``_AGREE_M`` /
``_AGREE_RAD``). A glitched scan (one scan from elsewhere) finds no such series; a loop
correction does, scan after scan. While a candidate waits, the scan is not mapped (it fits
two places; mapping it from the wrong one is what splits the map). Along a direction the
scan cannot fix (a bare corridor) the candidate keeps the match's position, as the corridor
check does (:mod:`roverlab.slam.degeneracy`).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.slam.degeneracy import odometry_along, scan_constraint
from roverlab.slam.hector.degeneracy import map_values
from roverlab.slam.hector.grid import MultiResGrid
from roverlab.slam.hector.matcher import _cost, _cost_below, match
from roverlab.slam.hector.params import HectorParams

__all__ = ["OCCUPIED_ABOVE", "SEARCH_EVERY", "Revisit", "differs", "wide_search"]

#: Two candidates agree when, moved by the odometry between their scans, they lie within
#: this distance (m) ...
_AGREE_M = 0.15
#: ... and heading (rad) of each other.
_AGREE_RAD = 0.03
#: A candidate nearer than this (m) to the match, and turned less than ``_SAME_TURN``
#: (rad), is within the matcher's own reach (its pre-search spans 0.2 m): the same place.
_SAME_PLACE = 0.25
_SAME_TURN = 0.1
#: With no candidate waiting, the wide search runs on every this many-th scan only (it
#: costs about as much as the match); a candidate is then followed scan by scan.
SEARCH_EVERY = 4
#: A cell the map holds occupied has a value above this (one hit: 0.9), as the corridor
#: check counts it.
OCCUPIED_ABOVE = 0.6
#: The wide search scores about this many of a scan's endpoints.
_SEARCH_POINTS = 90


@numba.njit(cache=True, nogil=True)
def _wide_search(
    prob: NDArray[np.float32],
    off: int,
    size: int,
    k: float,
    mx: float,
    my: float,
    theta: float,
    points: NDArray[np.float64],
    cells: int,
    turns: int,
    turn_step: float,
) -> NDArray[np.float64]:
    best = np.empty(4)
    best[0] = _cost(prob, off, size, k, mx, my, theta, points)
    best[1] = mx
    best[2] = my
    best[3] = theta
    for qa in range(-turns, turns + 1):
        t = theta + qa * turn_step
        for qx in range(-cells, cells + 1):
            for qy in range(-cells, cells + 1):
                # hector's cost, abandoned once it exceeds the best so far
                total = _cost_below(prob, off, size, k, mx + qx, my + qy, t, points, best[0])
                if total < best[0]:
                    best[0] = total
                    best[1] = mx + qx
                    best[2] = my + qy
                    best[3] = t
    return best


def wide_search(
    grid_prob: NDArray[np.float32],
    offset: int,
    size: int,
    inv_res: float,
    center: tuple[float, float],
    points: NDArray[np.float64],
    start: NDArray[np.float64],
    *,
    cells: int,
    angle_search: float,
    angle_step: float,
) -> NDArray[np.float64]:
    """The pose of lowest hector cost among every whole-cell shift within ``+-cells`` and
    every heading step within ``+-angle_search`` of ``start``, on one map level.

    Args:
        grid_prob: flat map values of every level (:class:`MultiResGrid`'s ``prob``).
        offset, size, inv_res, center: the level's place in ``grid_prob``, cells per side,
            cells per metre and the map coordinates of the world origin.
        points: (N, 2) endpoints in the robot frame (m).
        start: (3,) pose ``x, y, theta`` in the map frame.
        cells: half-width of the translational search in cells of the level.
        angle_search: half-width of the heading search (rad).
        angle_step: its step (rad).

    Returns:
        (3,) the best pose ``x, y, theta`` (``start`` wins ties).
    """
    turns = int(angle_search / angle_step + 1e-9) if angle_step > 0.0 else 0
    # a coarse cell spans several beams' endpoints: every few of them are enough
    stride = max(1, len(points) // _SEARCH_POINTS)
    best = _wide_search(
        grid_prob,
        int(offset),
        int(size),
        float(inv_res),
        float(start[0]) * inv_res + center[0],
        float(start[1]) * inv_res + center[1],
        float(start[2]),
        np.ascontiguousarray(points[::stride], dtype=np.float64),
        int(cells),
        turns,
        float(angle_step),
    )
    return np.array([(best[1] - center[0]) / inv_res, (best[2] - center[1]) / inv_res, best[3]])


class Revisit:
    """The candidate corrections of the last scans (see the module docstring).

    Attributes:
        count: how many scans in a row have found agreeing candidates.
    """

    def __init__(self) -> None:
        self._last: NDArray[np.float64] | None = None
        self.count = 0

    def reset(self) -> None:
        """No candidate (this scan's match is good, or found none)."""
        self._last = None
        self.count = 0

    def offer(self, candidate: NDArray[np.float64], odom_step: NDArray[np.float64]) -> int:
        """Add this scan's candidate; ``odom_step`` is the odometry's increment since the
        previous scan (robot frame). Returns how many scans in a row agree on it."""
        if self._last is not None and _agrees(
            (SE2(*self._last) * SE2(*odom_step)).as_array(), candidate
        ):
            self.count += 1
        else:
            self.count = 1
        self._last = candidate.copy()
        return self.count

    def search(
        self,
        grid: MultiResGrid,
        params: HectorParams,
        points: NDArray[np.float64],
        pose: NDArray[np.float64],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
        """This scan's candidate, or None: the match ``pose`` fits well enough, or the
        wide search finds no place that fits much better and lies elsewhere.

        Args:
            grid: the map pyramid.
            params: the parameters (``revisit_*``, the matcher's, the corridor check's).
            points: (N, 2) the scan's endpoints in the robot frame (m).
            pose: (3,) the guarded match.

        Returns:
            The candidate pose and the matcher's Hessian there.
        """
        p = params
        prob, k = grid.level_view(0), float(grid.inv_res[0])
        centre = (float(grid.centers[0, 0]), float(grid.centers[0, 1]))
        values = map_values(prob, k, centre, pose, points)
        if np.count_nonzero(values > OCCUPIED_ABOVE) >= p.revisit_trigger * points.shape[0]:
            return None
        top = p.map_multi_res_levels - 1
        start = wide_search(
            grid.prob,
            int(grid.offsets[top]),
            int(grid.sizes[top]),
            float(grid.inv_res[top]),
            (float(grid.centers[top, 0]), float(grid.centers[top, 1])),
            points,
            pose,
            cells=round(p.revisit_search / p.level_resolution(top)),
            angle_search=p.revisit_angle_search,
            angle_step=p.scan_match_angle_search_step,
        )
        found, hessian = match(
            grid.prob,
            grid.offsets,
            grid.sizes,
            grid.inv_res,
            grid.centers,
            points,
            start,
            iters_coarse=p.scan_match_iterations_coarse,
            iters_fine=p.scan_match_iterations_fine,
            damped=p.scan_match_damping,
        )
        found_values = map_values(prob, k, centre, found, points)
        ratio, weak = scan_constraint(points, found_values > OCCUPIED_ABOVE)
        if ratio < p.degenerate_eigen_ratio:
            found = odometry_along(found, pose, weak)
            found_values = map_values(prob, k, centre, found, points)
        fits = np.sum((1.0 - found_values) ** 2) <= p.revisit_fit_ratio * np.sum(
            (1.0 - values) ** 2
        )
        return (found, hessian) if fits and differs(found, pose, weak) else None


def differs(a: NDArray[np.float64], b: NDArray[np.float64], weak: NDArray[np.float64]) -> bool:
    """Whether pose ``a`` is a different place from ``b``: turned more than ``_SAME_TURN``
    or moved more than ``_SAME_PLACE`` across ``weak`` (the direction the scan constrains
    least, robot frame at ``a``'s heading). Along a corridor held only by far walls, a
    corridor its first pass mapped a little stretched looks the same shifted; a revisit
    shows across it."""
    c, s = math.cos(a[2]), math.sin(a[2])
    wx, wy = c * weak[0] - s * weak[1], s * weak[0] + c * weak[1]
    across = abs(wx * (a[1] - b[1]) - wy * (a[0] - b[0]))
    return across > _SAME_PLACE or abs(wrap_angle(float(a[2] - b[2]))) > _SAME_TURN


def _agrees(a: NDArray[np.float64], b: NDArray[np.float64]) -> bool:
    return (
        math.hypot(a[0] - b[0], a[1] - b[1]) <= _AGREE_M
        and abs(wrap_angle(float(a[2] - b[2]))) <= _AGREE_RAD
    )
