"""A global plan the footprint can follow (roverlab's addition to move_base's planning).

navfn and global_planner treat the robot as a disc of the footprint's **inscribed** radius:
a cell is passable when it is not within that radius of an obstacle. A rectangular robot
is wider than that disc along its diagonal and, sideways, by the padding and the cells a
laser hit marks; the planners then send it into gaps it cannot pass, where the local
planner wedges it (ROS's move_base does the same; the usual workaround, a bigger
inflation or padding, also closes the doors the robot does fit through).

:func:`plan_clear_of_footprint` plans as usual, then places the footprint at every pose of
the plan, heading along the path, and looks for lethal cells under its outline. Around
each pose that touches one it blocks a disc of the inscribed radius and plans again (a
few rounds); a plan with no such pose is returned. When blocking leaves no plan, or the
rounds run out, the first plan is returned, so the check never makes a goal unreachable
that the planner alone could reach. Poses within the circumscribed radius of the start
and of the goal are not checked: the robot is where it is, and the goal is the user's.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.navigation.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D
from roverlab.navigation.costmap.footprint import footprint_radii, pad_footprint
from roverlab.navigation.costmap.footprint_kernels import outline_cells
from roverlab.navigation.errors import PlannerError
from roverlab.navigation.planners.base import Path2D, PlannerProtocol

__all__ = ["colliding_poses", "path_headings", "plan_clear_of_footprint"]

#: re-plans after the first plan
MAX_ROUNDS = 6
#: the room the footprint needs beyond its padded outline, each side, in cells
MARGIN_CELLS = 0.5
#: half the number of path points over which a pose's heading is taken
HEADING_SPAN = 3


def path_headings(path: NDArray[np.float64], span: int = HEADING_SPAN) -> NDArray[np.float64]:
    """The direction of travel at each point of an ``(N, 2+)`` path: the chord from ``span``
    points back to ``span`` points ahead (clipped at the ends); 0 for a one-point path."""
    n = len(path)
    if n < 2:
        return np.zeros(n)
    idx = np.arange(n)
    a = path[np.maximum(idx - span, 0), :2]
    b = path[np.minimum(idx + span, n - 1), :2]
    d = b - a
    return np.arctan2(d[:, 1], d[:, 0])


@numba.njit(cache=True, nogil=True)
def _infeasible(
    costs: NDArray[np.uint8],
    geometry: tuple[float, float, float],
    path: NDArray[np.float64],
    check: NDArray[np.bool_],
    fp: NDArray[np.float64],
    moves: tuple[NDArray[np.float64], NDArray[np.float64]],
    hits: NDArray[np.bool_],
) -> int:
    """Mark the checked poses (rows ``x, y, heading``) at which no placement, shifted
    sideways by one of ``moves[0]`` (m) and turned by one of ``moves[1]`` (rad), keeps the
    outline of ``fp`` off the lethal cells of ``costs`` (``geometry``: resolution and
    origin); returns how many."""
    res, ox, oy = geometry
    shifts, turns = moves
    lethal = LETHAL_OBSTACLE
    h, w = costs.shape
    flat = costs.reshape(-1)
    buf = np.empty(fp.shape[0] * 2 * (w + h) + 8, dtype=np.int64)
    count = 0
    for i in range(path.shape[0]):
        hits[i] = False
        if not check[i]:
            continue
        th = path[i, 2]
        nx = -math.sin(th)
        ny = math.cos(th)
        free = False
        for a in range(shifts.shape[0]):
            px = path[i, 0] + shifts[a] * nx
            py = path[i, 1] + shifts[a] * ny
            for b in range(turns.shape[0]):
                n = outline_cells(w, h, res, ox, oy, px, py, th + turns[b], fp, buf)
                free = True
                for q in range(n):
                    if flat[buf[q]] == lethal:
                        free = False
                        break
                if free:
                    break
            if free:
                break
        if not free:
            hits[i] = True
            count += 1
    return count


def colliding_poses(
    path: Path2D,
    costmap: Costmap2D,
    footprint: NDArray[np.float64],
    *,
    skip_radius: float = 0.0,
    shifts: ArrayLike = (0.0,),
    turns: ArrayLike = (0.0,),
) -> NDArray[np.bool_]:
    """Which poses of ``path`` leave no room for ``footprint``: its outline, heading along
    the path, crosses a lethal cell of ``costmap`` in every placement shifted sideways by
    one of ``shifts`` (m) and turned by one of ``turns`` (rad). Poses within
    ``skip_radius`` of the path's first or last point are not checked."""
    p = np.asarray(path, dtype=np.float64)
    hits = np.zeros(len(p), dtype=np.bool_)
    if len(p) == 0:
        return hits
    poses = np.column_stack([p[:, 0], p[:, 1], path_headings(p)])
    d0 = np.hypot(poses[:, 0] - poses[0, 0], poses[:, 1] - poses[0, 1])
    d1 = np.hypot(poses[:, 0] - poses[-1, 0], poses[:, 1] - poses[-1, 1])
    check = (d0 > skip_radius) & (d1 > skip_radius)
    geometry = (costmap.resolution, costmap.origin_x, costmap.origin_y)
    moves = (np.asarray(shifts, dtype=np.float64), np.asarray(turns, dtype=np.float64))
    fp = np.ascontiguousarray(footprint, dtype=np.float64)
    _infeasible(costmap.costs, geometry, poses, check, fp, moves, hits)
    return hits


def _block(costmap: Costmap2D, points: NDArray[np.float64], radius: float) -> None:
    """Set every cell whose centre is within ``radius`` of one of ``points`` lethal."""
    res = costmap.resolution
    r = max(radius, res)
    k = int(math.ceil(r / res))
    off = np.arange(-k, k + 1)
    dx, dy = np.meshgrid(off, off)
    disc = (dx * dx + dy * dy) * res * res <= r * r
    dx, dy = dx[disc], dy[disc]
    cx = np.floor((points[:, 0] - costmap.origin_x) / res).astype(np.int64)
    cy = np.floor((points[:, 1] - costmap.origin_y) / res).astype(np.int64)
    gx = (cx[:, None] + dx[None, :]).ravel()
    gy = (cy[:, None] + dy[None, :]).ravel()
    ok = (gx >= 0) & (gy >= 0) & (gx < costmap.size_x) & (gy < costmap.size_y)
    costmap.costs[gy[ok], gx[ok]] = LETHAL_OBSTACLE


def plan_clear_of_footprint(
    planner: PlannerProtocol,
    start: SE2,
    goal: SE2,
    costmap: Costmap2D,
    footprint: ArrayLike,
    *,
    rounds: int = MAX_ROUNDS,
    walls: Costmap2D | None = None,
) -> Path2D:
    """``planner.plan(start, goal, costmap)``, re-planned around places where the footprint
    has no room (see the module docstring) among the lethal cells of ``walls`` (a costmap
    of ``costmap``'s geometry: move_base passes the static layer's map) or, without it, of
    ``costmap``.

    Raises:
        PlannerError: the first plan failed (as ``planner.plan`` raises it).
    """
    first = planner.plan(start, goal, costmap)
    fp = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    if len(fp) < 3 or rounds <= 0:
        return first
    fixed = costmap if walls is None else walls
    res = costmap.resolution
    inscribed, _ = footprint_radii(fp)
    wide = pad_footprint(fp, MARGIN_CELLS * res)
    skip = footprint_radii(wide)[1] + res
    shifts = np.array([0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 2.0, -2.0]) * res
    turns = np.radians([0.0, *(s * a for a in np.arange(7.5, 45.1, 7.5) for s in (1, -1))])

    def stuck(path: Path2D) -> NDArray[np.bool_]:
        return colliding_poses(path, fixed, wide, skip_radius=skip, shifts=shifts, turns=turns)

    path = first
    work: Costmap2D | None = None
    for _ in range(rounds):
        hits = stuck(path)
        if not hits.any():
            return path
        if work is None:
            work = costmap.copy()
        _block(work, np.asarray(path)[hits, :2], inscribed)
        try:
            path = planner.plan(start, goal, work)
        except PlannerError:
            return first
    return first if stuck(path).any() else path
