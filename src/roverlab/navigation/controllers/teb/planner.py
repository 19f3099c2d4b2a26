"""teb_local_planner (``teb_local_planner/TebLocalPlannerROS``) as a pure local planner.

Per control cycle, as TebLocalPlannerROS::computeVelocityCommands:

* the global plan loses the part more than ``global_plan_prune_distance`` behind the
  robot; the local plan is its stretch from the point nearest the robot, within 85 % of
  half the local costmap and ``max_global_plan_lookahead_dist`` of path length; its last
  point is the local goal, its yaw estimated from the following plan points
  (``global_plan_overwrite_orientation``); via-points every ``global_plan_viapoint_sep``;
* the goal is reached within ``xy_goal_tolerance`` and ``yaw_goal_tolerance`` of the global
  goal, once stopped (or at once with ``free_goal_vel``): the command is then zero;
* TEB's oscillation recovery (:mod:`.recovery`) may prefer a turning direction;
* every lethal cell of the local costmap is a point obstacle
  (``include_costmap_obstacles``), except those behind the robot farther than
  ``costmap_obstacles_behind_robot_dist`` (unless the local plan runs behind the robot
  near them: roverlab's addition, so a band turning back sees the posts it passes);
* the band is initialised from the local plan (or warm-started: passed poses pruned, start
  and goal updated; re-initialised when the goal moved more than
  ``force_reinit_new_goal_dist`` / ``_angular``), then ``no_outer_iterations`` times:
  resized (``teb_autosize``, ``dt_ref``, ``dt_hysteresis``), obstacles associated to poses,
  and optimised as a sparse nonlinear least-squares problem by g2o's Levenberg-Marquardt
  for ``no_inner_iterations`` iterations (:mod:`.solver`: the normal equations of the
  chain are banded, factorised in time linear in the band's length); the obstacle weight
  grows by ``weight_adapt_factor`` each time;
* the first ``feasibility_check_no_poses`` poses (or, when
  ``feasibility_check_lookahead_distance`` is set, those up to the first pose beyond it)
  are checked against the costmap with the costmap's footprint; the command is the
  velocity between the first pose and the next (``control_look_ahead_poses``), saturated
  to the limits.

Failures raise :class:`NoValidControlError` and reset the band, as TEB clears its planner.
roverlab's ``backwards_init_when_stuck`` (off by default): after that many seconds of
infeasible bands, with the local goal behind the robot, a band initialised backwards is
tried in the same cycle (a robot in a pocket it cannot turn in reverses out).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from roverlab.geometry import SE2, wrap_angle
from roverlab.navigation.controllers.base import Velocity2D, angle_diff, as_plan, stopped
from roverlab.navigation.controllers.teb.band import TimedElasticBand, goal_behind
from roverlab.navigation.controllers.teb.feasibility import FootprintCheck
from roverlab.navigation.controllers.teb.kernels import (
    associate_obstacles,
    build_structure,
    evaluate,
)
from roverlab.navigation.controllers.teb.obstacles import association_reach, costmap_obstacles
from roverlab.navigation.controllers.teb.params import TebParams
from roverlab.navigation.controllers.teb.recovery import OscillationRecovery
from roverlab.navigation.controllers.teb.solver import band_order, levenberg_marquardt
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.errors import InvalidPathError, NoValidControlError

__all__ = ["TebPlanner"]

_DT_MIN = 1e-3  # floor of every time difference after a solve


#: force-included obstacles kept per pose (the closest): bounds the edges a pose gets
#: when the obstacles are costmap cells, a dozen of them per post or wall stretch
_MAX_FORCED_PER_POSE = 8


def _prune(pose: SE2, plan: NDArray[np.float64], dist_behind: float) -> NDArray[np.float64]:
    d2 = (plan[:, 0] - pose.x) ** 2 + (plan[:, 1] - pose.y) ** 2
    near = np.nonzero(d2 < dist_behind * dist_behind)[0]
    return plan[near[0] :] if len(near) else plan


def _transform(
    pose: SE2, plan: NDArray[np.float64], cm: Costmap2D, max_len: float
) -> tuple[NDArray[np.float64], int]:
    """TEB's ``transformGlobalPlan``: the local plan and the index of its last point."""
    limit = 0.85 * max(cm.size_x * cm.resolution, cm.size_y * cm.resolution) / 2.0
    lim2 = limit * limit
    d2 = (plan[:, 0] - pose.x) ** 2 + (plan[:, 1] - pose.y) ** 2
    i = 0
    best = 1e10
    reached = False
    for j in range(len(plan)):
        if d2[j] > lim2:
            break
        if reached and d2[j] > best:
            break
        if d2[j] < best:
            best, i = float(d2[j]), j
            if best < 0.05:
                reached = True
    out = []
    length = 0.0
    sq = best
    while i < len(plan) and sq <= lim2 and (max_len <= 0 or length <= max_len):
        out.append(plan[i])
        sq = float(d2[i])
        if i > 0 and max_len > 0:
            length += math.hypot(*(plan[i, :2] - plan[i - 1, :2]))
        i += 1
    if not out:
        return plan[-1:].copy(), len(plan) - 1
    return np.array(out), i - 1


def _goal_orientation(
    plan: NDArray[np.float64], local_goal: NDArray[np.float64], idx: int
) -> float:
    """TEB's ``estimateLocalGoalOrientation`` (moving average over 3 plan segments)."""
    n = len(plan)
    avg = 3
    if idx > n - avg - 2:
        return float(local_goal[2]) if idx >= n - 1 else float(plan[-1, 2])
    avg = min(avg, n - idx - 1)
    k = local_goal[:2]
    sins, coss = 0.0, 0.0
    for i in range(idx, idx + avg):
        kp1 = plan[i + 1, :2]
        a = math.atan2(kp1[1] - k[1], kp1[0] - k[0])
        sins += math.sin(a)
        coss += math.cos(a)
        k = kp1
    return math.atan2(sins, coss)


class TebPlanner:
    """TebLocalPlannerROS.

    Args:
        params: its parameters.
        footprint: the costmap's footprint ((N, 2) polygon, robot frame), for the
            feasibility check (TEB's own ``footprint_model`` is for the optimisation).

    Attributes:
        band: the timed elastic band (last optimised).
        obstacles: the point obstacles of the last cycle, ``(K, 2)``.
        via_points: the via-points of the last cycle.
        local_plan: the local plan of the last cycle.
        goal_reached: set by :meth:`compute_velocity`, as TEB's ``isGoalReached``.
    """

    name = "teb_local_planner/TebLocalPlannerROS"

    def __init__(self, params: TebParams | None = None, *, footprint: ArrayLike = ()) -> None:
        self.params = params or TebParams()
        self._check = FootprintCheck(footprint)
        self.band = TimedElasticBand()
        self.obstacles: NDArray[np.float64] = np.zeros((0, 2))
        self._obstacle_tree: cKDTree | None = None
        self.via_points: NDArray[np.float64] = np.zeros((0, 2))
        self.local_plan: NDArray[np.float64] = np.zeros((0, 3))
        self.goal_reached = False
        self._orig_plan: NDArray[np.float64] | None = None
        self._plan: NDArray[np.float64] = np.zeros((0, 3))
        self._last_pose: SE2 | None = None
        self._last_twist = Velocity2D()
        self._recovery = OscillationRecovery(self.params)
        self._cycles = 0  # control cycles: the oscillation recovery's clock
        self._preferred_rotdir = 0  # TEB's RotType: +1 left, -1 right, 0 none
        self._last_cmd = Velocity2D()
        self._infeasible_cycles = 0  # control cycles in a row without a valid command

    @property
    def footprint(self) -> NDArray[np.float64]:
        """The costmap's footprint the feasibility check tests, ``(N, 2)``."""
        return self._check.footprint

    @property
    def trajectory(self) -> NDArray[np.float64]:
        """The optimised band's poses ``(N, 3)`` (what TebLocalPlannerROS publishes as
        ``local_plan``); empty after a failed cycle."""
        return self.band.poses

    # ------------------------------------------------------------------ plan / goal
    def set_plan(self, plan: ArrayLike) -> None:
        """A new global plan (the goal flag is reset; the band is kept for a warm start)."""
        p = as_plan(plan, "teb_local_planner")
        self._orig_plan = p.copy()
        self._plan = p.copy()
        self.goal_reached = False

    def is_goal_reached(self, pose: SE2 | None = None, twist: Velocity2D | None = None) -> bool:
        """TEB's goal test (position, yaw, stopped or ``free_goal_vel``) at ``pose`` and
        ``twist`` when given, else what the last :meth:`compute_velocity` found."""
        if pose is None:
            return self.goal_reached
        return self._goal_test(pose, twist or Velocity2D())

    def _goal_test(self, pose: SE2, twist: Velocity2D) -> bool:
        p = self.params
        if len(self._plan) == 0:
            return False
        g = self._plan[-1]
        return (
            math.hypot(g[0] - pose.x, g[1] - pose.y) < p.xy_goal_tolerance
            and abs(angle_diff(float(g[2]), pose.theta)) < p.yaw_goal_tolerance
            and (not p.complete_global_plan or len(self.via_points) == 0)
            and (stopped(twist, p.theta_stopped_vel, p.trans_stopped_vel) or p.free_goal_vel)
        )

    # ------------------------------------------------------------------ obstacles
    def _near_obstacles(self, poses: NDArray[np.float64]) -> NDArray[np.float64]:
        """The obstacles within the association cutoff of some inner pose of the band (the
        only ones :func:`associate_obstacles` can pick), found in the cycle's k-d tree:
        the association's work grows with the band, not with the costmap's cells."""
        tree = self._obstacle_tree
        if tree is None or len(poses) < 3:
            return np.zeros((0, 2))
        hits = tree.query_ball_point(
            poses[1:-1, :2], association_reach(self.params), return_sorted=False
        )
        idx = np.unique(np.concatenate([np.asarray(h, dtype=np.int64) for h in hits]))
        return np.ascontiguousarray(self.obstacles[idx])

    def _via_points(self, plan: NDArray[np.float64]) -> NDArray[np.float64]:
        sep = self.params.global_plan_viapoint_sep
        if sep <= 0:
            return np.zeros((0, 2))
        out = []
        prev = 0
        for i in range(1, len(plan)):
            if math.hypot(*(plan[i, :2] - plan[prev, :2])) < sep:
                continue
            out.append(plan[i, :2])
            prev = i
        return np.array(out).reshape(-1, 2)

    # ------------------------------------------------------------------ graph
    def _graph(
        self, weight_multiplier: float, start_vel: Velocity2D, free_goal: bool
    ) -> tuple[
        NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.float64],
        NDArray[np.float64],
    ]:  # fmt: skip
        """The edges of the current band: types, pose and dt indices, aux values, and the
        square root of each residual's weight."""
        p = self.params
        poses = self.band.poses
        n = len(poses)
        types: list[NDArray[np.int64]] = []
        pid: list[NDArray[np.int64]] = []
        did: list[NDArray[np.int64]] = []
        aux: list[NDArray[np.float64]] = []
        wts: list[NDArray[np.float64]] = []

        def add(
            et: int,
            pi: NDArray[np.int64],
            di: NDArray[np.int64],
            ax: NDArray[np.float64],
            w: tuple[float, ...],
        ) -> None:
            m = len(pi)
            if m == 0:
                return
            types.append(np.full(m, et, dtype=np.int64))
            pid.append(pi)
            did.append(di)
            aux.append(ax)
            wts.append(np.tile(np.sqrt(np.asarray(w, dtype=np.float64)), m))

        i = np.arange(n - 1)
        j = np.arange(n - 2)
        no = np.full(n - 1, -1)
        pair = np.column_stack([i, i + 1, no])
        z2 = np.zeros((n - 1, 2))
        dt_i = np.column_stack([i, no])
        dt_none = np.column_stack([no, no])
        add(0, pair, dt_i, z2, (p.weight_max_vel_x, p.weight_max_vel_theta))
        if p.weight_acc_lim_x != 0 or p.weight_acc_lim_theta != 0:
            wa = (p.weight_acc_lim_x, p.weight_acc_lim_theta)
            start_v = np.array([[start_vel.vx, start_vel.wz]])
            add(2, np.array([[0, 1, -1]]), np.array([[0, -1]]), start_v, wa)
            triple = np.column_stack([j, j + 1, j + 2])
            add(1, triple, np.column_stack([j, j + 1]), np.zeros((n - 2, 2)), wa)
            if not free_goal:
                goal_pair = np.array([[n - 2, n - 1, -1]])
                add(3, goal_pair, np.array([[n - 2, -1]]), np.zeros((1, 2)), wa)
        add(4, np.column_stack([no, no, no]), dt_i, z2, (p.weight_optimaltime,))
        if p.weight_shortest_path > 0:
            add(5, pair, dt_none, z2, (p.weight_shortest_path,))
        if p.min_turning_radius == 0 or p.weight_kinematics_turning_radius == 0:
            add(6, pair, dt_none, z2, (p.weight_kinematics_nh, p.weight_kinematics_forward_drive))
        else:
            add(7, pair, dt_none, z2, (p.weight_kinematics_nh, p.weight_kinematics_turning_radius))
        near = self._near_obstacles(poses)
        if p.weight_obstacle > 0 and len(near) and n > 2:
            cap = (n - 2) * (min(len(near), _MAX_FORCED_PER_POSE) + 2)
            op = np.empty(cap, dtype=np.int64)
            oo = np.empty(cap, dtype=np.int64)
            fm = p.footprint_model
            cnt = associate_obstacles(
                poses,
                near,
                fm.code,
                fm.as_array(),
                p.min_obstacle_dist * p.obstacle_association_force_inclusion_factor,
                p.min_obstacle_dist * p.obstacle_association_cutoff_factor,
                op,
                oo,
                _MAX_FORCED_PER_POSE,
            )
            m = np.full(cnt, -1)
            w_obs = p.weight_obstacle * weight_multiplier
            one = np.column_stack([op[:cnt], m, m])
            if p.inflation_dist > p.min_obstacle_dist:
                add(
                    9,
                    one,
                    np.column_stack([m, m]),
                    near[oo[:cnt]],
                    (w_obs, p.weight_inflation),
                )
            else:
                add(8, one, np.column_stack([m, m]), near[oo[:cnt]], (w_obs,))
        if self._preferred_rotdir and p.weight_prefer_rotdir > 0:
            k = min(n - 1, 3)  # TEB: the first three turns
            m = np.full((k, 2), float(self._preferred_rotdir))
            add(11, pair[:k], dt_none[:k], m, (p.weight_prefer_rotdir,))
        if p.weight_viapoint > 0 and len(self.via_points) and n >= 3:
            rows = []
            start_idx = 0
            for vp in self.via_points:
                d = np.hypot(poses[start_idx:, 0] - vp[0], poses[start_idx:, 1] - vp[1])
                idx = start_idx + int(np.argmin(d)) if len(d) else n - 1
                if p.via_points_ordered:
                    start_idx = min(idx + 2, n - 1)
                idx = min(idx, n - 2)
                if idx < 1:
                    if not p.via_points_ordered:
                        continue
                    idx = 1
                rows.append((idx, vp[0], vp[1]))
            if rows:
                r = np.array(rows)
                m = np.full(len(r), -1)
                vp_pose = np.column_stack([r[:, 0].astype(np.int64), m, m])
                add(10, vp_pose, np.column_stack([m, m]), r[:, 1:], (p.weight_viapoint,))
        return (
            np.ascontiguousarray(np.concatenate(types)),
            np.ascontiguousarray(np.concatenate(pid)),
            np.ascontiguousarray(np.concatenate(did)),
            np.ascontiguousarray(np.concatenate(aux)),
            np.ascontiguousarray(np.concatenate(wts)),
        )

    def _optimize(self, start_vel: Velocity2D, free_goal: bool) -> None:
        """TEB's ``optimizeTEB``: outer iterations of resize, association, inner solve."""
        p = self.params
        cfg = np.array(
            [p.max_vel_x, p.max_vel_x_backwards, p.max_vel_theta, p.acc_lim_x, p.acc_lim_theta,
             p.penalty_epsilon, p.min_turning_radius, p.min_obstacle_dist, p.inflation_dist,
             p.obstacle_cost_exponent, 1.0 if p.exact_arc_length else 0.0]
        )  # fmt: skip
        fm = p.footprint_model
        model, mp = fm.code, fm.as_array()
        mult = 1.0
        for _ in range(p.no_outer_iterations):
            if p.teb_autosize:
                self.band.auto_resize(p.dt_ref, p.dt_hysteresis, p.min_samples, p.max_samples)
            poses, dts = self.band.poses, self.band.dts
            n = len(poses)
            et, pi, di, ax, sw = self._graph(mult, start_vel, free_goal)
            indptr, indices, _row0 = build_structure(et, pi, di, n)
            nres = int(indptr.shape[0] - 1)
            x0 = np.concatenate([poses[1:-1].ravel(), dts])
            r = np.empty(nres)
            jdata = np.empty(indices.shape[0])

            def fun(
                x: NDArray[np.float64], want_jac: bool
            ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
                evaluate(x, poses, dts, et, pi, di, ax, sw, cfg, model, mp, want_jac, r, jdata)  # noqa: B023
                return r, jdata  # noqa: B023

            x = levenberg_marquardt(x0, fun, indices, indptr, band_order(n), p.no_inner_iterations)
            self.band.poses[1:-1] = x[: 3 * (n - 2)].reshape(-1, 3)
            self.band.poses[1:-1, 2] = wrap_angle(self.band.poses[1:-1, 2])
            # g2o bounds no variable either; a time difference must stay positive
            self.band.dts = np.maximum(x[3 * (n - 2) :], _DT_MIN)
            mult *= p.weight_adapt_factor

    # ------------------------------------------------------------------ feasibility
    def _feasible(self, cm: Costmap2D) -> bool:
        """TEB's ``isTrajectoryFeasible`` on the band (:mod:`.feasibility`)."""
        return self._check.feasible(cm, self.band.poses, self.params)

    # ------------------------------------------------------------------ command
    def _backwards_when_stuck(
        self, local: NDArray[np.float64], twist: Velocity2D, costmap: Costmap2D
    ) -> bool:
        """``backwards_init_when_stuck``: after that long without a feasible band, and with
        the local goal behind the robot, a band initialised backwards, optimised and
        checked like the first; True when it is feasible (it then stays the band)."""
        p = self.params
        if (
            p.backwards_init_when_stuck <= 0
            or p.allow_init_with_backwards_motion  # the first band was already one
            or self._infeasible_cycles < p.backwards_init_when_stuck * p.controller_frequency
            or not goal_behind(local[0], local[-1])  # ahead: the same band as the first
        ):
            return False
        self._init_band(local, backwards=True)
        try:
            self._solve(twist)
        except NoValidControlError:
            return False
        return self._feasible(costmap)

    def _velocity_command(self) -> Velocity2D:
        p = self.params
        poses, dts = self.band.poses, self.band.dts
        look = max(1, min(p.control_look_ahead_poses, len(poses) - 1))
        dt = 0.0
        for c in range(look):
            dt += dts[c]
            if dt >= p.dt_ref * look:
                look = c + 1
                break
        if dt <= 0:
            raise NoValidControlError("teb_local_planner: timediff <= 0 is invalid")
        a, b = poses[0], poses[look]
        d = b[:2] - a[:2]
        direction = float(d @ [math.cos(a[2]), math.sin(a[2])])
        vx = math.copysign(1.0, direction) * math.hypot(*d) / dt if direction != 0 else 0.0
        om = wrap_angle(float(b[2] - a[2])) / dt
        return self._saturate(vx, om)

    def _saturate(self, vx: float, om: float) -> Velocity2D:
        """TebLocalPlannerROS::saturateVelocity."""
        p = self.params
        rx, ro = 1.0, 1.0
        if vx > p.max_vel_x:
            rx = p.max_vel_x / vx
        if abs(om) > p.max_vel_theta:
            ro = abs(p.max_vel_theta / om)
        if p.max_vel_x_backwards > 0 and vx < -p.max_vel_x_backwards:
            rx = -p.max_vel_x_backwards / vx
        if p.use_proportional_saturation:
            rx = ro = min(rx, ro)
        vx *= rx
        om *= ro
        if abs(vx) > p.trans_limit:
            vx *= p.trans_limit / abs(vx)
        return Velocity2D(vx, 0.0, om)

    def compute_velocity(
        self, pose: SE2, twist: Velocity2D, plan: ArrayLike, costmap: Costmap2D
    ) -> Velocity2D:
        """The command for this cycle (see the module docstring).

        Raises:
            InvalidPathError: an empty plan.
            NoValidControlError: optimisation off, an infeasible or invalid trajectory.
        """
        p = self.params
        new = as_plan(plan, "teb_local_planner")
        if self._orig_plan is None or not np.array_equal(new, self._orig_plan):
            self.set_plan(new)
        self._last_pose, self._last_twist = pose, twist
        self.goal_reached = False
        self._plan = _prune(pose, self._plan, p.global_plan_prune_distance)
        local, goal_idx = _transform(pose, self._plan, costmap, p.max_global_plan_lookahead_dist)
        self.via_points = self._via_points(local)
        self._cycles += 1
        if self._goal_test(pose, twist):
            self.goal_reached = True
            return Velocity2D()
        if p.oscillation_recovery:  # TEB's configureBackupModes (its oscillation part)
            now = self._cycles / p.controller_frequency
            self._preferred_rotdir = self._recovery.update(now, self._last_cmd, twist)
        try:
            cmd = self._cycle(pose, twist, costmap, local, goal_idx)
        except NoValidControlError:
            self._last_cmd = Velocity2D()  # TEB's last_cmd_ is the zero it commands then
            self._infeasible_cycles += 1
            raise
        self._last_cmd = cmd
        self._infeasible_cycles = 0
        return cmd

    def _init_band(self, local: NDArray[np.float64], *, backwards: bool) -> None:
        """A new band from the local plan (TEB's ``initTrajectoryToGoal``), ``backwards``
        guessed from where the local goal lies when set, at the spacing ``autoResize``
        keeps."""
        p = self.params
        spacing = max((p.dt_ref - p.dt_hysteresis) * p.max_vel_x if p.teb_autosize else 0.0, 0.0)
        self.band.clear()
        self.band.init_from_plan(
            local, p.max_vel_x, p.max_vel_theta, p.global_plan_overwrite_orientation,
            p.min_samples, backwards, spacing,
        )  # fmt: skip

    def _solve(self, twist: Velocity2D) -> None:
        """Optimise the band.

        Raises:
            NoValidControlError: the solver failed or the band diverged (it is cleared).
        """
        band = self.band
        try:
            self._optimize(twist, self.params.free_goal_vel)
        except (ValueError, TypeError, np.linalg.LinAlgError) as err:
            band.clear()
            raise NoValidControlError(
                f"teb_local_planner was not able to obtain a local plan ({err})"
            ) from err
        if not np.isfinite(band.poses).all() or not np.isfinite(band.dts).all():
            band.clear()
            raise NoValidControlError("teb_local_planner: the trajectory has diverged")

    def _cycle(
        self, pose: SE2, twist: Velocity2D, costmap: Costmap2D, local: NDArray[np.float64],
        goal_idx: int,
    ) -> Velocity2D:  # fmt: skip
        """The cycle after the goal test: local goal, obstacles, band, check, command."""
        p = self.params
        if len(local) == 0:
            raise InvalidPathError("teb_local_planner: transformed plan is empty")
        local = local.copy()
        if p.global_plan_overwrite_orientation:
            local[-1, 2] = _goal_orientation(self._plan, local[-1], goal_idx)
        if len(local) == 1:
            local = np.vstack([local[:1], local])
        local[0] = pose.as_array()
        self.local_plan = local
        self.obstacles = costmap_obstacles(p, pose, costmap, local)
        self._obstacle_tree = cKDTree(self.obstacles) if len(self.obstacles) else None
        if not p.optimization_activate:
            raise NoValidControlError("teb_local_planner: optimization_activate is false")
        start, goal = local[0], local[-1]
        band = self.band
        if band.is_init and (
            math.hypot(*(goal[:2] - band.poses[-1, :2])) < p.force_reinit_new_goal_dist
            and abs(wrap_angle(float(goal[2] - band.poses[-1, 2])))
            < p.force_reinit_new_goal_angular
        ):
            band.update_and_prune(start, goal, p.min_samples)
        else:
            self._init_band(local, backwards=p.allow_init_with_backwards_motion)
        self._solve(twist)
        if not self._feasible(costmap) and not self._backwards_when_stuck(local, twist, costmap):
            band.clear()
            raise NoValidControlError("teb_local_planner: trajectory is not feasible")
        try:
            return self._velocity_command()
        except NoValidControlError:
            band.clear()
            raise
