"""teb_local_planner's feasibility check: the band's first poses against the costmap with
the costmap's footprint (base_local_planner's CostmapModel, as TEB calls it)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import wrap_angle
from roverlab.navigation.controllers.teb.params import TebParams
from roverlab.navigation.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.costmap.kernels import bresenham, line_cost


class FootprintCheck:
    """``isTrajectoryFeasible`` with a footprint (its outline's cells, as
    ``CostmapModel::footprintCost``; fewer than three points: the centre cell)."""

    def __init__(self, footprint: ArrayLike) -> None:
        self.footprint = np.ascontiguousarray(
            np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        )
        self.inscribed_radius = footprint_radii(self.footprint)[0]
        self._line_buf = np.empty((4096, 2), dtype=np.int64)

    def blocked(self, cm: Costmap2D, x: float, y: float, th: float) -> bool:
        """CostmapModel::footprintCost == -1 (a lethal cell under the footprint's outline;
        for fewer than three points, the centre cell lethal or inscribed)."""
        c = cm.world_to_map(x, y)
        if c is None:
            return False
        fp = self.footprint
        if len(fp) < 3:
            return cm.get_cost(*c) >= 253 and cm.get_cost(*c) != 255
        ct, st = math.cos(th), math.sin(th)
        pts = np.column_stack(
            [x + fp[:, 0] * ct - fp[:, 1] * st, y + fp[:, 0] * st + fp[:, 1] * ct]
        )
        cells = []
        for wx, wy in pts:
            cc = cm.world_to_map(float(wx), float(wy))
            if cc is None:
                return False
            cells.append(cc)
        need = cm.size_x + cm.size_y + 4
        if self._line_buf.shape[0] < need:
            self._line_buf = np.empty((need, 2), dtype=np.int64)
        for k in range(len(cells)):
            a, b = cells[k], cells[(k + 1) % len(cells)]
            # a lethal or unknown cell on the edge; only lethal makes it infeasible
            if line_cost(cm.costs, a[0], a[1], b[0], b[1], self._line_buf) < 0 and (
                self._lethal_on_line(cm, a, b)
            ):
                return True
        return False

    def _lethal_on_line(self, cm: Costmap2D, a: tuple[int, int], b: tuple[int, int]) -> bool:
        n = bresenham(a[0], a[1], b[0], b[1], 1 << 30, self._line_buf)
        cells = self._line_buf[:n]
        return bool(np.any(cm.costs[cells[:, 1], cells[:, 0]] == LETHAL_OBSTACLE))

    def feasible(self, cm: Costmap2D, poses: NDArray[np.float64], p: TebParams) -> bool:
        """TEB's ``isTrajectoryFeasible`` over the band's first
        ``feasibility_check_no_poses`` (or up to ``feasibility_check_lookahead_distance``)."""
        look = p.feasibility_check_no_poses
        if look < 0 or look >= len(poses):
            look = len(poses) - 1
        if p.feasibility_check_lookahead_distance > 0:
            # as TEB: the pose before the first one farther than the distance is the last
            # checked (this replaces feasibility_check_no_poses, as in TEB's code)
            far = np.hypot(poses[1:, 0] - poses[0, 0], poses[1:, 1] - poses[0, 1])
            beyond = np.nonzero(far > p.feasibility_check_lookahead_distance)[0]
            if len(beyond):
                look = int(beyond[0])
        step = self.inscribed_radius if self.inscribed_radius > 0 else cm.resolution
        for i in range(look + 1):
            if self.blocked(cm, *map(float, poses[i])):
                return False
            if i < look:
                rot = wrap_angle(float(wrap_angle(poses[i + 1, 2]) - wrap_angle(poses[i, 2])))
                dd = poses[i + 1, :2] - poses[i, :2]
                dist = float(np.hypot(*dd))
                if abs(rot) > p.min_resolution_collision_check_angular or dist > step:
                    k = (
                        max(
                            math.ceil(abs(rot) / p.min_resolution_collision_check_angular),
                            math.ceil(dist / step),
                        )
                        - 1
                    )
                    q = poses[i].copy()
                    for _ in range(k):
                        q[:2] += dd / (k + 1.0)
                        q[2] = wrap_angle(float(q[2] + rot / (k + 1.0)))
                        if self.blocked(cm, *map(float, q)):
                            return False
        return True
