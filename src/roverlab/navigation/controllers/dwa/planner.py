"""dwa_local_planner (``dwa_local_planner/DWAPlannerROS``) as a pure local planner.

Per control cycle, as DWAPlannerROS::computeVelocityCommands:

* the global plan is pruned (``prune_plan``: the points before the first within 1 m of
  the robot go) and cut to the local costmap (base_local_planner's transformGlobalPlan);
* the map grids are computed by a wavefront from the local plan (path distance, cells) and
  from its last point in the costmap (goal distance), and from that point moved
  ``forward_point_distance`` further from the robot (the nose goal);
* within ``xy_goal_tolerance`` of the goal (latched with ``latch_xy_goal_tolerance``) the
  robot stops with its acceleration limits, then rotates in place to the goal's yaw
  (LatchedStopRotateController), each command checked against the costmap;
* otherwise velocities are sampled in the dynamic window (``vx/vy/vth_samples`` between the
  limits and the current velocity -/+ acceleration x ``sim_period``), each simulated for
  ``sim_time`` and scored by the critics of :mod:`.kernels` in one compiled call; the
  cheapest valid sample is the command, and the oscillation flags are updated.

When every sample is refused, base_local_planner's escape (TrajectoryPlanner's
``escape_vel``, ``escape_reset_dist``, ``escape_reset_theta``, here for DWAPlannerROS too):
the robot backs up at ``escape_vel`` and forward samples are left out until it has moved
``escape_reset_dist`` or turned ``escape_reset_theta`` from where the escape began. ROS
backs up blind ("even when the static map shows it as blocked"); roverlab backs up only
while the robot's body stays clear of lethal cells, which is what frees a robot whose
*padded* footprint touches an obstacle its body clears. Before that, when the padded
footprint is refused where the robot stands but its body is clear, the samples are
scored with the body's footprint and the cheapest whose last pose is clear with the
padded one is taken; once backing up is blocked too, forward samples return. The body
there is the ``footprint`` parameter with half the padding kept (it may leave out the
wheels, as BARN's Jackal footprint does), or the bare one when that finds no way out.

Failures raise :class:`NoValidControlError` (the robot must stop) or
:class:`InvalidPathError`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.navigation.controllers.base import (
    Velocity2D,
    angle_diff,
    as_plan,
    local_plan_window,
    prune_plan,
    stopped,
)
from roverlab.navigation.controllers.dwa.escape import EscapeMixin
from roverlab.navigation.controllers.dwa.in_place import (
    InPlaceRotations,
    ProgressCheck,
    in_place_samples,
)
from roverlab.navigation.controllers.dwa.kernels import (
    first_known_stretch,
    sample_grid,
    score_rollouts,
    target_distance_window,
)
from roverlab.navigation.controllers.dwa.params import DWAParams
from roverlab.navigation.costmap.costmap_2d import (
    Costmap2D,
)
from roverlab.navigation.errors import InvalidPathError, NoValidControlError

__all__ = ["DWAPlanner", "velocity_iterator"]


def velocity_iterator(lo: float, hi: float, num: int) -> list[float]:
    """base_local_planner's ``VelocityIterator``: ``num`` (>= 2) even samples from ``lo``
    to ``hi``, with 0 inserted where the samples change sign; ``[lo]`` when equal."""
    if lo == hi:
        return [lo]
    num = max(2, num)
    step = (hi - lo) / max(1, num - 1)
    out: list[float] = []
    nxt = lo
    for _ in range(num - 1):
        cur = nxt
        nxt += step
        out.append(cur)
        if cur < 0 < nxt:
            out.append(0.0)
    out.append(hi)
    return out


def _adjust_resolution(plan: NDArray[np.float64], resolution: float) -> NDArray[np.float64]:
    """MapGrid's ``adjustPlanResolution``: points inserted so that none are farther apart
    than ``resolution``."""
    xy = plan[:, :2]
    if len(plan) < 2:
        return xy
    a = xy[:-1]
    delta = xy[1:] - a
    d = np.hypot(delta[:, 0], delta[:, 1])
    steps = np.ones(len(d), dtype=np.int64)
    far = d > resolution
    steps[far] = np.ceil(d[far] / resolution).astype(np.int64)
    # each segment gives its start and steps - 1 points inside (a + j (b - a) / steps)
    seg = np.repeat(np.arange(len(d)), steps)
    j = np.arange(len(seg)) - np.repeat(np.cumsum(steps) - steps, steps)
    inner = a[seg] + j[:, None] * delta[seg] / steps[seg, None]
    return np.concatenate([inner, xy[-1:]])


def _forward_window(
    pose: SE2, cm: Costmap2D, reach: float, ahead: float, square: NDArray[np.int64]
) -> NDArray[np.int64]:
    """``square`` (cells) cut to the cells a forward rollout reads: with constant
    velocities (``use_dwa``), no lateral motion, ``vx >= 0`` and at most half a turn over
    ``sim_time``, every pose of a rollout lies ahead of the robot or beside it (a sum of
    ``v dt (cos j a, sin j a)``, ``j a < pi``, has a projection on the first heading
    ``>= 0``), and the goal-front point at most ``forward_point_distance`` behind: the
    robot-frame box ``[-ahead, reach] x [-reach, reach]`` (m), turned to the map, plus
    two cells. A read outside still falls back to the whole waves."""
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    back = max(ahead, 0.0)
    xs = [pose.x + u * c - v * s for u in (-back, reach) for v in (-reach, reach)]
    ys = [pose.y + u * s + v * c for u in (-back, reach) for v in (-reach, reach)]
    res = cm.resolution
    box = [
        math.floor((min(xs) - cm.origin_x) / res) - 2,
        math.floor((min(ys) - cm.origin_y) / res) - 2,
        math.floor((max(xs) - cm.origin_x) / res) + 2,
        math.floor((max(ys) - cm.origin_y) / res) + 2,
    ]
    return np.array(
        [max(box[0], square[0]), max(box[1], square[1]), min(box[2], square[2]),
         min(box[3], square[3])], dtype=np.int64,
    )  # fmt: skip


def _first_known_stretch(plan: NDArray[np.float64], cm: Costmap2D) -> NDArray[np.int64] | None:
    """The cells ``(ix, iy)`` of ``plan`` (at the costmap's resolution, see
    :func:`_adjust_resolution`) from its first point on a known cell of ``cm`` up to the
    point before the next one that is off the map or on unknown cost; None when no point
    is on a known cell."""
    cells = first_known_stretch(
        np.ascontiguousarray(plan[:, :2]), cm.costs, cm.resolution, cm.origin_x, cm.origin_y
    )  # compiled; the same cells as adjusting the plan and looking each point up
    return cells if len(cells) else None


class DWAPlanner(EscapeMixin):
    """DWAPlannerROS.

    Args:
        params: its parameters.
        footprint: the robot footprint ((N, 2) polygon, robot frame; fewer than 3 points:
            a circular robot checked at its centre), as the costmap gives it.

    Attributes:
        local_plan: the plan cut to the costmap, last cycle.
        trajectory: the chosen trajectory's poses, last cycle (empty when stopping or
            rotating at the goal).
        costs: every sample's cost, last cycle (negative: rejected).
        samples: the velocity samples, last cycle.
    """

    name = "dwa_local_planner/DWAPlannerROS"

    def __init__(
        self,
        params: DWAParams | None = None,
        *,
        footprint: ArrayLike = (),
        body_footprint: ArrayLike | None = None,
    ) -> None:
        self.params = params or DWAParams()
        fp = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        self.footprint = np.ascontiguousarray(fp)
        body = fp if body_footprint is None else np.asarray(body_footprint, dtype=np.float64)
        self.body_footprint = np.ascontiguousarray(body.reshape(-1, 2))
        self.escaping = False
        self._escape_from = SE2()
        self._orig_plan: NDArray[np.float64] | None = None
        self._plan: NDArray[np.float64] = np.zeros((0, 3))
        self.local_plan: NDArray[np.float64] = np.zeros((0, 3))
        self.trajectory: NDArray[np.float64] = np.zeros((0, 3))
        self.costs: NDArray[np.float64] = np.zeros(0)
        self.samples: NDArray[np.float64] = np.zeros((0, 3))
        self._last_pose: SE2 | None = None
        self._last_twist = Velocity2D()
        self._xy_latch = False
        self._rotating = False
        self._reset_oscillation()
        self._rotations = InPlaceRotations(
            self.params.heading_lookahead, self.params.oscillation_reset_dist
        )
        self._progress = ProgressCheck(
            self.params.required_movement_radius,
            self.params.movement_time_allowance,
            self.params.sim_period,
        )
        self._prev_stationary = SE2()
        self._grids: tuple[NDArray[np.float64], ...] = ()
        # the cells whose grid values are final (x0, y0, x1, y1) and the waves' seeds
        self._window = np.zeros(4, dtype=np.int64)
        self._seeds: tuple[NDArray[np.int64], ...] = ()
        self._scales = np.zeros(7)

    # ------------------------------------------------------------------ state
    def _reset_oscillation(self) -> None:
        # forward_pos_only, forward_neg_only, strafe_pos_only, strafe_neg_only,
        # rot_pos_only, rot_neg_only
        self._only = np.zeros(6, dtype=np.bool_)
        self._seen = {"fwd_pos": False, "fwd_neg": False, "str_pos": False}
        self._seen.update({"str_neg": False, "rot_pos": False, "rot_neg": False})

    def set_plan(self, plan: ArrayLike) -> None:
        """A new global plan: resets the goal latch and the oscillation flags."""
        p = as_plan(plan, "dwa_local_planner")
        self._orig_plan = p.copy()
        self._plan = p.copy()
        self._xy_latch = False
        self._rotating = False
        self._reset_oscillation()

    def _goal(self) -> NDArray[np.float64]:
        if len(self._plan) == 0:
            raise InvalidPathError("dwa_local_planner: no plan")
        return self._plan[-1]

    # ------------------------------------------------------------------ goal
    def _position_reached(self, pose: SE2) -> bool:
        g = self._goal()
        p = self.params
        if (p.latch_xy_goal_tolerance and self._xy_latch) or math.hypot(
            g[0] - pose.x, g[1] - pose.y
        ) <= p.xy_goal_tolerance:
            self._xy_latch = True
            return True
        return False

    def is_goal_reached(self, pose: SE2 | None = None, twist: Velocity2D | None = None) -> bool:
        """Within ``xy_goal_tolerance`` (or latched), within ``yaw_goal_tolerance`` and
        stopped (``trans_stopped_vel``, ``theta_stopped_vel``)."""
        pose = pose or self._last_pose
        twist = twist or self._last_twist
        if pose is None or len(self._plan) == 0:
            return False
        p = self.params
        g = self._plan[-1]
        if (p.latch_xy_goal_tolerance and self._xy_latch) or math.hypot(
            g[0] - pose.x, g[1] - pose.y
        ) <= p.xy_goal_tolerance:
            if p.latch_xy_goal_tolerance:
                self._xy_latch = True
            if abs(angle_diff(float(g[2]), pose.theta)) <= p.yaw_goal_tolerance:
                return stopped(twist, p.theta_stopped_vel, p.trans_stopped_vel)
        return False

    # ------------------------------------------------------------------ grids
    def _update_local_costs(self, pose: SE2, plan: NDArray[np.float64], cm: Costmap2D) -> None:
        p = self.params
        res = cm.resolution
        stretch = _first_known_stretch(plan, cm)
        if stretch is None:
            raise InvalidPathError(
                "dwa_local_planner: none of the points of the global plan are in the local "
                "costmap and free"
            )
        g = plan[-1]
        ang = math.atan2(g[1] - pose.y, g[0] - pose.x)
        front = plan.copy()
        front[-1, 0] += p.forward_point_distance * math.cos(ang)
        front[-1, 1] += p.forward_point_distance * math.sin(ang)
        front_stretch = _first_known_stretch(front, cm)
        # path grid, local goal grid (the last point of the plan's first stretch in the
        # map), goal-front grid; the front seed empty: none (every cell unreachable);
        # the same as the goal's (the plan leaves the map before its end): a copy
        seeds = [np.ascontiguousarray(stretch), np.ascontiguousarray(stretch[-1:])]
        if front_stretch is None:
            seeds.append(np.zeros((0, 2), dtype=np.int64))
        elif (front_stretch[-1] == stretch[-1]).all():
            seeds.append(seeds[1])
        else:
            seeds.append(np.ascontiguousarray(front_stretch[-1:]))
        self._seeds = tuple(seeds)
        self._waves(cm, self._reach_window(pose, cm))
        unit = res if p.meter_scoring else 1.0
        path_s = unit * p.path_distance_bias
        goal_s = unit * p.goal_distance_bias
        sq = (pose.x - g[0]) ** 2 + (pose.y - g[1]) ** 2
        align_s = path_s if sq > p.forward_point_distance**2 else 0.0
        self._scales = np.array(
            [
                p.occdist_scale,
                goal_s,
                align_s,
                path_s,
                goal_s,
                p.twirling_scale,
                p.forward_point_distance,
            ]
        )

    def _reach_window(self, pose: SE2, cm: Costmap2D) -> NDArray[np.int64]:
        """The cells the critics read this cycle, as far as the parameters bound them: the
        robot's cell +- the farthest a rollout gets in ``sim_time`` plus the look-ahead
        point (a read outside it is caught by the scoring, which then has the waves run
        to their end: the window affects the speed only, never a value read)."""
        p = self.params
        v = self._last_twist
        vx = max(abs(p.max_vel_x), abs(p.min_vel_x), abs(p.escape_vel), abs(v.vx))
        vy = max(abs(p.y_limits[0]), abs(p.y_limits[1]), abs(v.vy))
        reach = max(p.max_vel_trans, math.hypot(vx, vy)) * p.sim_time
        reach += max(p.forward_point_distance, p.heading_lookahead, 0.0)
        r = math.ceil(reach / cm.resolution) + 2
        cx = math.floor((pose.x - cm.origin_x) / cm.resolution)
        cy = math.floor((pose.y - cm.origin_y) / cm.resolution)
        window = np.array([cx - r, cy - r, cx + r, cy + r], dtype=np.int64)
        if (
            p.use_dwa and not self.escaping and p.min_vel_x >= 0.0 and v.vx >= 0.0
            and p.y_limits == (0.0, 0.0) and v.vy == 0.0
            and max(abs(p.max_vel_theta), abs(v.wz)) * p.sim_time <= math.pi
        ):  # fmt: skip
            window = _forward_window(pose, cm, reach, p.forward_point_distance, window)
        return window

    def _waves(self, cm: Costmap2D, window: NDArray[np.int64]) -> None:
        """The three map grids (``MapGrid::computeTargetDistance`` from ``self._seeds``),
        final within ``window`` (cells; the whole grid once every wave ran to its end)."""
        shape = (cm.size_y, cm.size_x)
        whole = np.array([0, 0, cm.size_x - 1, cm.size_y - 1], dtype=np.int64)
        if window[0] <= 0 and window[1] <= 0 and window[2] >= whole[2] and window[3] >= whole[3]:
            window = whole
        complete = True
        grids: list[NDArray[np.float64]] = []
        for i, seeds in enumerate(self._seeds):
            if i == 2 and seeds is self._seeds[1]:
                grids.append(grids[1])  # the same wave (the grids are only read)
            elif len(seeds) == 0:
                grids.append(np.full(shape, float(cm.size_x * cm.size_y + 1)))
            else:
                grid = np.empty(shape)
                complete &= target_distance_window(cm.costs, seeds, grid, window)
                grids.append(grid)
        self._grids = tuple(grids)
        self._window = whole if complete else window

    def _whole_grids(self, cm: Costmap2D) -> None:
        """The waves run to their end (a read fell outside the window)."""
        if not (self._window[0] <= 0 and self._window[1] <= 0 and self._window[2] >= cm.size_x - 1
                and self._window[3] >= cm.size_y - 1):  # fmt: skip
            self._waves(cm, np.array([0, 0, cm.size_x - 1, cm.size_y - 1], dtype=np.int64))

    # ------------------------------------------------------------------ scoring
    def _score(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64], cm: Costmap2D,
        flags: NDArray[np.bool_], prune: bool = True, footprint: NDArray[np.float64] | None = None,
    ) -> tuple[int, NDArray[np.float64]]:  # fmt: skip
        p = self.params
        out = np.empty(len(samples))
        gen = np.array(
            [p.sim_time, p.sim_granularity, p.angular_sim_granularity, p.min_vel_trans,
             p.max_vel_trans, p.min_vel_theta, p.stop_time_buffer]
        )  # fmt: skip
        scaling = np.array([p.scaling_speed, p.max_vel_trans, p.max_scaling_factor])
        while True:
            best = score_rollouts(
                np.ascontiguousarray(samples), pose.as_array(), vel.as_array(), gen,
                np.array([p.acc_lim_x, p.acc_lim_y, p.acc_lim_theta]), not p.use_dwa,
                cm.costs, cm.resolution, cm.origin_x, cm.origin_y, self._grids[0],
                self._grids[1], self._grids[2], self.footprint if footprint is None else footprint,
                self._scales, scaling, p.sum_scores, flags, prune, out, self._window,
            )  # fmt: skip
            if best != -2:
                return int(best), out
            self._whole_grids(cm)  # a rollout read past the window

    def _check(self, pose: SE2, vel: Velocity2D, cmd: NDArray[np.float64], cm: Costmap2D) -> bool:
        """DWAPlanner::checkTrajectory (the oscillation flags are reset, as ROS does)."""
        self._reset_oscillation()
        cost = self._score(pose, vel, cmd[None, :], cm, self._only)[1][0]
        return bool(cost >= 0 or cost == -100.0)

    def _sample_velocities(
        self, pose: SE2, vel: Velocity2D, rotations: bool = False
    ) -> NDArray[np.float64]:
        p = self.params
        g = self._goal()
        max_th = p.max_vel_theta
        min_x, max_x = p.min_vel_x, p.max_vel_x
        min_y, max_y = p.y_limits
        acc = (p.acc_lim_x, p.acc_lim_y, p.acc_lim_theta)
        if p.use_dwa:
            t = p.sim_period
        else:
            t = p.sim_time
            dist = math.hypot(g[0] - pose.x, g[1] - pose.y)
            max_x = max(min(max_x, dist / p.sim_time), min_x)
            max_y = max(min(max_y, dist / p.sim_time), min_y)
        v = vel.as_array()
        hi = [min(max_x, v[0] + acc[0] * t), min(max_y, v[1] + acc[1] * t)]
        hi.append(min(max_th, v[2] + acc[2] * t))
        lo = [max(min_x, v[0] - acc[0] * t), max(min_y, v[1] - acc[1] * t)]
        lo.append(max(-max_th, v[2] - acc[2] * t))
        nx, ny, nth = p.samples
        if min_y == max_y == 0.0:
            lo[1] = hi[1] = 0.0
        xs = velocity_iterator(lo[0], hi[0], nx)
        ys = velocity_iterator(lo[1], hi[1], ny)
        ths = velocity_iterator(lo[2], hi[2], nth)
        grid = sample_grid(np.array(xs), np.array(ys), np.array(ths))
        if rotations:  # TrajectoryPlanner's, whatever min_vel_x is
            grid = np.concatenate([grid, in_place_samples(lo[2], hi[2], nth, p.min_vel_theta)])
        return np.ascontiguousarray(grid, dtype=np.float64)

    def _update_oscillation(self, pose: SE2, cmd: NDArray[np.float64]) -> None:
        """OscillationCostFunction::updateOscillationFlags for the chosen command."""
        p = self.params
        s = self._seen
        only = self._only
        vx, vy, vth = (float(c) for c in cmd)
        flag = False
        if vx < 0.0:
            if s["fwd_pos"]:
                only[1] = flag = True
            s["fwd_pos"], s["fwd_neg"] = False, True
        if vx > 0.0:
            if s["fwd_neg"]:
                only[0] = flag = True
            s["fwd_neg"], s["fwd_pos"] = False, True
        if abs(vx) <= p.min_vel_trans:
            if vy < 0:
                if s["str_pos"]:
                    only[3] = flag = True
                s["str_pos"], s["str_neg"] = False, True
            if vy > 0:
                if s["str_neg"]:
                    only[2] = flag = True
                s["str_neg"], s["str_pos"] = False, True
            if vth < 0:
                if s["rot_pos"]:
                    only[5] = flag = True
                s["rot_pos"], s["rot_neg"] = False, True
            if vth > 0:
                if s["rot_neg"]:
                    only[4] = flag = True
                s["rot_neg"], s["rot_pos"] = False, True
        if flag:
            self._prev_stationary = pose
        if only.any():
            prev = self._prev_stationary
            d2 = (pose.x - prev.x) ** 2 + (pose.y - prev.y) ** 2
            if d2 > p.oscillation_reset_dist**2 or abs(pose.theta - prev.theta) > (
                p.oscillation_reset_angle
            ):
                self._reset_oscillation()

    # ------------------------------------------------------------------ control
    def compute_velocity(
        self, pose: SE2, twist: Velocity2D, plan: ArrayLike, costmap: Costmap2D
    ) -> Velocity2D:
        """The command for this cycle (see the module docstring).

        Raises:
            InvalidPathError: an empty plan, or none of it in the local costmap.
            NoValidControlError: every sample rejected, or the stop / rotate command
                would collide (the robot must stop).
        """
        p = self.params
        new = as_plan(plan, "dwa_local_planner")
        if self._orig_plan is None or not np.array_equal(new, self._orig_plan):
            self.set_plan(new)
        self._last_pose, self._last_twist = pose, twist
        if p.prune_plan and len(self._plan):
            # base_local_planner's prunePlan: with no point within 1 m the plan is used up
            # (until the next setPlan), as in ROS
            self._plan = prune_plan(pose, self._plan)
        local = local_plan_window(pose, self._plan, costmap)
        if len(local) == 0:
            raise InvalidPathError("dwa_local_planner: received an empty transformed plan")
        self.local_plan = local
        self._update_local_costs(pose, local, costmap)
        self.trajectory = np.zeros((0, 3))
        if self._position_reached(pose):
            return self._stop_rotate(pose, twist, costmap)
        self._update_escape(pose)
        rotations = p.in_place_samples or self._progress.stalled(pose)
        every = self._sample_velocities(pose, twist, rotations)
        # TrajectoryPlanner samples no forward motion while escaping
        samples = every[every[:, 0] <= 0.0] if self.escaping else every
        best, costs = self._best(pose, twist, samples, costmap)
        if best >= 0 and rotations:
            best = self._pick_in_place(pose, twist, samples, costs, costmap)
        if best < 0:
            back = self._back_up(pose, twist, costmap)
            if back is not None:
                return back
            if self.escaping:  # no room to back up any further: forward motion again
                self.escaping = False
                samples = every
                best, costs = self._best(pose, twist, samples, costmap)
        self.samples, self.costs = samples, costs
        if best < 0:
            raise NoValidControlError(
                "dwa_local_planner: the dwa local planner failed to find a valid plan, cost "
                "functions discarded all candidates. This can mean there is an obstacle too "
                "close to the robot."
            )
        cmd = samples[best]
        self._update_oscillation(pose, cmd)
        self.trajectory = self._roll(pose, twist, cmd).copy()
        return Velocity2D(float(cmd[0]), float(cmd[1]), float(cmd[2]))

    def _pick_in_place(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64],
        costs: NDArray[np.float64], cm: Costmap2D,
    ) -> int:  # fmt: skip
        """TrajectoryPlanner's choice between the best sample and its rotations in place
        (:class:`.in_place.InPlaceRotations`), from the rotations' end poses."""
        ends = np.zeros((len(samples), 3))
        for k in np.flatnonzero((samples[:, 0] == 0.0) & (costs >= 0)):
            traj = self._roll(pose, vel, samples[k])
            ends[k] = traj[-1] if len(traj) else pose.as_array()
        origin = (cm.resolution, cm.origin_x, cm.origin_y)
        self._whole_grids(cm)  # the look-ahead cells of the ends may be past the window
        return self._rotations.pick(pose, samples, costs, ends, self._grids[1], origin)

    def _best(
        self, pose: SE2, vel: Velocity2D, samples: NDArray[np.float64], cm: Costmap2D
    ) -> tuple[int, NDArray[np.float64]]:
        """The cheapest valid sample, else the ways out of a lethal cell under the outline
        and of an obstacle inside the padding; ``(-1, costs)`` when none."""
        best, costs = self._score(pose, vel, samples, cm, self._only)
        if best < 0:
            best, costs = self._escape(pose, vel, samples, cm, costs)
        if best < 0:
            best, costs = self._body_escape(pose, vel, samples, cm, costs)
        return best, costs

    def _stop_rotate(self, pose: SE2, twist: Velocity2D, cm: Costmap2D) -> Velocity2D:
        """LatchedStopRotateController::computeVelocityCommandsStopRotate."""
        p = self.params
        t = p.sim_period
        goal_th = float(self._goal()[2])
        if abs(angle_diff(goal_th, pose.theta)) <= p.yaw_goal_tolerance:
            self._rotating = False  # at the goal's heading: stop (move_base then sees
            return Velocity2D()  # the robot stopped and ends the goal SUCCEEDED)
        if not self._rotating and not stopped(twist, p.theta_stopped_vel, p.trans_stopped_vel):
            vx = math.copysign(max(0.0, abs(twist.vx) - p.acc_lim_x * t), twist.vx)
            vy = math.copysign(max(0.0, abs(twist.vy) - p.acc_lim_y * t), twist.vy)
            vth = math.copysign(max(0.0, abs(twist.wz) - p.acc_lim_theta * t), twist.wz)
            if self._check(pose, twist, np.array([vx, vy, vth]), cm):
                return Velocity2D(vx, vy, vth)
            raise NoValidControlError("dwa_local_planner: stopping cmd in collision")
        self._rotating = True
        ang = angle_diff(goal_th, pose.theta)
        v = min(p.max_vel_theta, max(p.min_vel_theta, abs(ang)))
        max_acc = abs(twist.wz) + p.acc_lim_theta * t
        min_acc = abs(twist.wz) - p.acc_lim_theta * t
        v = min(max(abs(v), min_acc), max_acc)
        v = min(math.sqrt(2 * p.acc_lim_theta * abs(ang)), abs(v))
        v = min(p.max_vel_theta, max(p.min_vel_theta, v))
        if ang < 0:
            v = -v
        if self._check(pose, twist, np.array([0.0, 0.0, v]), cm):
            return Velocity2D(0.0, 0.0, v)
        raise NoValidControlError("dwa_local_planner: rotation cmd in collision")
