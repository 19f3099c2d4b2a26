"""base_local_planner's escape and roverlab's ways out for :class:`~.planner.DWAPlanner`,
when every velocity sample is refused (see the planner's module text): the lethal cells
under the footprint's outline scored as inscribed, the samples scored with the robot's
body when only the padding touches, and backing up at ``escape_vel`` until
``escape_reset_dist`` / ``escape_reset_theta``.

:class:`EscapeMixin` is a base class of the planner, which provides the state below and
the scoring.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.navigation.controllers.base import Velocity2D, angle_diff
from roverlab.navigation.controllers.dwa.kernels import rollout
from roverlab.navigation.controllers.dwa.params import DWAParams
from roverlab.navigation.costmap.costmap_2d import (
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    Costmap2D,
)
from roverlab.navigation.costmap.footprint_kernels import footprint_cost, outline_cells

__all__ = ["EscapeMixin"]


class EscapeMixin:
    """The ways out of :class:`~.planner.DWAPlanner`; the planner provides the
    parameters, footprints, oscillation flags, the last trajectory and ``_score``."""

    params: DWAParams
    footprint: NDArray[np.float64]
    body_footprint: NDArray[np.float64]
    escaping: bool
    _escape_from: SE2
    trajectory: NDArray[np.float64]
    _only: NDArray[np.bool_]

    def _score(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64], cm: Costmap2D,
        flags: NDArray[np.bool_], prune: bool = True, footprint: NDArray[np.float64] | None = None,
    ) -> tuple[int, NDArray[np.float64]]:  # fmt: skip
        raise NotImplementedError

    def _roll(
        self, pose: SE2, vel: Velocity2D, cmd: NDArray[np.float64], continued: bool | None = None
    ) -> NDArray[np.float64]:
        """The poses (k, 3) of ``cmd`` from ``pose`` at ``vel`` over ``sim_time``, as the
        scoring rolls a sample out (``continued`` acceleration: TrajectoryPlanner's, i.e.
        not ``dwa``, unless given); empty when the rollout has no step."""
        p = self.params
        traj = np.empty((int(p.sim_time / min(p.sim_granularity, 1.0)) * 4 + 64, 3))
        num, _, _ = rollout(
            pose.as_array(), vel.as_array(), cmd, p.sim_time, p.sim_granularity,
            p.angular_sim_granularity, (not p.use_dwa) if continued is None else continued,
            np.array([p.acc_lim_x, p.acc_lim_y, p.acc_lim_theta]), 0.0, traj,
        )  # fmt: skip
        return traj[:num]

    def _escape(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64], cm: Costmap2D,
        costs: NDArray[np.float64],
    ) -> tuple[int, NDArray[np.float64]]:  # fmt: skip
        """roverlab's way out when every sample was refused because the robot already
        stands over lethal cells: the footprint check (CostmapModel's Bresenham outline)
        can miss a lethal cell a slanted edge crosses, so the robot drives over it, and from
        there every motion's check catches it (and rotate_recovery refuses to turn). The
        lethal cells the footprint's exact outline crosses at the current pose are then
        scored as inscribed, and the cheapest sample whose last pose is clear of them (and
        legal on the costmap as it is) is taken. Any other lethal cell still refuses a
        sample. Returns ``(-1, costs)`` when the robot is not over a lethal cell or no
        sample gets clear."""
        fp = self.footprint
        if len(fp) < 3:
            return -1, costs
        w, h = cm.size_x, cm.size_y
        buf = np.empty((len(fp) + 1) * 2 * (w + h + 2), dtype=np.int64)
        args = (w, h, cm.resolution, cm.origin_x, cm.origin_y)
        n = outline_cells(*args, pose.x, pose.y, pose.theta, fp, buf)
        cells = np.unique(buf[:n])
        stuck = cells[cm.costs.reshape(-1)[cells] == LETHAL_OBSTACLE]
        if len(stuck) == 0:
            return -1, costs
        relaxed = cm.copy()
        relaxed.costs.reshape(-1)[stuck] = INSCRIBED_INFLATED_OBSTACLE
        best, rcosts = self._score(pose, vel, samples, relaxed, self._only, prune=False)
        if best < 0:
            return -1, costs
        line = np.empty((w + h + 4, 2), dtype=np.int64)
        for k in np.argsort(np.where(rcosts >= 0, rcosts, np.inf), kind="stable"):
            if rcosts[k] < 0:
                break
            traj = self._roll(pose, vel, samples[k])
            if len(traj) == 0:
                continue
            x, y, th = (float(v) for v in traj[-1])
            m = outline_cells(*args, x, y, th, fp, buf)
            if np.isin(buf[:m], stuck).any():
                continue
            if footprint_cost(cm.costs, *args[2:], x, y, th, fp, 1.0, line) < 0:
                continue
            return int(k), rcosts
        return -1, costs

    def _body_escape(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64], cm: Costmap2D,
        costs: NDArray[np.float64],
    ) -> tuple[int, NDArray[np.float64]]:  # fmt: skip
        """When the padded footprint is refused where the robot stands but its body is
        clear (an obstacle inside the padding): the samples scored with the body's
        footprint, the cheapest one taken whose last pose is clear with the padded one;
        with each of :meth:`_escape_footprints` in turn that is clear where the robot
        stands, until one gives a sample."""
        fp = self.footprint
        args = (cm.resolution, cm.origin_x, cm.origin_y)
        line = np.empty((cm.size_x + cm.size_y + 4, 2), dtype=np.int64)
        for body in self._escape_footprints():
            if len(body) < 3 or (body.shape == fp.shape and np.array_equal(body, fp)):
                return -1, costs
            if footprint_cost(cm.costs, *args, pose.x, pose.y, pose.theta, body, 1.0, line) < 0:
                continue
            _, bcosts = self._score(pose, vel, samples, cm, self._only, prune=False, footprint=body)
            for k in np.argsort(np.where(bcosts >= 0, bcosts, np.inf), kind="stable"):
                if bcosts[k] < 0:
                    break
                traj = self._roll(pose, vel, samples[k])
                if len(traj) == 0:
                    continue
                x, y, th = (float(v) for v in traj[-1])
                if footprint_cost(cm.costs, *args, x, y, th, fp, 1.0, line) >= 0:
                    return int(k), bcosts
        return -1, costs

    def _escape_footprints(self) -> list[NDArray[np.float64]]:
        """The body's footprints the ways out check, in order: the ``footprint``
        parameter with half the costmap's padding kept (padFootprint moves each vertex
        outwards, so the half-way polygon is the vertices' mean), then the bare
        ``footprint`` when that one finds no way out. The parameter
        may leave out what the padding covers: BARN's Jackal footprint is its 0.33 m
        chassis, its wheels reach 0.42 m, and a robot turning past a pillar on the bare
        chassis touched it with a wheel."""
        body, fp = self.body_footprint, self.footprint
        if body.shape != fp.shape or np.array_equal(body, fp):
            return [body]
        return [np.ascontiguousarray((body + fp) / 2.0), body]

    def _update_escape(self, pose: SE2) -> None:
        """The escape ends once the robot is ``escape_reset_dist`` away from, or
        ``escape_reset_theta`` turned from, where it began."""
        if not self.escaping:
            return
        p, start = self.params, self._escape_from
        if (
            math.hypot(pose.x - start.x, pose.y - start.y) > p.escape_reset_dist
            or abs(angle_diff(pose.theta, start.theta)) > p.escape_reset_theta
        ):
            self.escaping = False

    def _back_up(self, pose: SE2, twist: Velocity2D, cm: Costmap2D) -> Velocity2D | None:
        """TrajectoryPlanner's last resort: straight back at ``escape_vel`` (acceleration
        limited), if the real footprint stays clear of lethal and unknown cells for
        ``escape_reset_dist`` (or the whole ``sim_time`` if that is shorter; the first
        of :meth:`_escape_footprints` that does); None
        otherwise (or with ``escape_vel`` 0)."""
        p = self.params
        if p.escape_vel >= 0.0:
            return None
        traj = self._roll(pose, twist, np.array([p.escape_vel, 0.0, 0.0]), continued=True)
        need = min(p.escape_reset_dist, abs(p.escape_vel) * p.sim_time)
        line = np.empty((cm.size_x + cm.size_y + 4, 2), dtype=np.int64)
        for body in self._escape_footprints():
            if self._clear_backing(pose, traj, need, body, cm, line):
                break
        else:
            return None
        if not self.escaping:
            self.escaping = True
            self._escape_from = pose
        self.trajectory = traj.copy()
        vx = max(p.escape_vel, twist.vx - p.acc_lim_x * p.sim_period)
        return Velocity2D(vx, 0.0, 0.0)

    @staticmethod
    def _clear_backing(
        pose: SE2, traj: NDArray[np.float64], need: float, body: NDArray[np.float64],
        cm: Costmap2D, line: NDArray[np.int64],
    ) -> bool:  # fmt: skip
        """Whether ``body`` stays clear along ``traj`` until ``need`` m from ``pose``."""
        for x, y, th in traj:
            if footprint_cost(
                cm.costs, cm.resolution, cm.origin_x, cm.origin_y, float(x), float(y),
                float(th), body, 1.0, line,
            ) < 0:  # fmt: skip
                return False
            if math.hypot(x - pose.x, y - pose.y) >= need:
                break
        return True
