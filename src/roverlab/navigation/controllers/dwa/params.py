"""dwa_local_planner's parameters (``DWAPlanner.cfg`` names and defaults), and the
``base_local_planner/TrajectoryPlannerROS`` names mapped onto them.

Renamed names are accepted with a warning when the new one is not set, as DWAPlannerROS's
``warnRenamedParameter``: ``max_trans_vel``, ``min_trans_vel``, ``max_rot_vel``,
``min_rot_vel``, ``acc_limit_trans``, ``rot_stopped_vel``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.params import build_params, check, unknown_warning

__all__ = ["NODE_KEYS", "DWAParams"]

_RENAMED = {
    "max_trans_vel": "max_vel_trans",
    "min_trans_vel": "min_vel_trans",
    "max_rot_vel": "max_vel_theta",
    "min_rot_vel": "min_vel_theta",
    "acc_limit_trans": "acc_lim_trans",
    "rot_stopped_vel": "theta_stopped_vel",
}
# visualisation only (point clouds roverlab does not publish), or dynamic_reconfigure's
# reset switch; DWAPlanner's cheat_factor scales only the cost-grid cloud
_IGNORED = (
    "publish_traj_pc",
    "publish_cost_grid_pc",
    "global_frame_id",
    "cheat_factor",
)
#: names the node reads, not the planner (``odom_topic``: move_base's odometry subscription)
NODE_KEYS = frozenset({"odom_topic", "restore_defaults"})

# TrajectoryPlannerROS (base_local_planner) defaults, for the names that map
_TP_DEFAULTS: dict[str, Any] = {
    "acc_lim_x": 2.5,
    "acc_lim_y": 2.5,
    "acc_lim_theta": 3.2,
    "max_vel_x": 0.5,
    "min_vel_x": 0.1,
    "max_vel_theta": 1.0,
    "min_in_place_vel_theta": 0.4,
    "holonomic_robot": True,
    "y_vels": [-0.3, -0.1, 0.1, 0.3],
    "yaw_goal_tolerance": 0.05,
    "xy_goal_tolerance": 0.1,
    "latch_xy_goal_tolerance": False,
    "sim_time": 1.0,
    "sim_granularity": 0.025,
    "vx_samples": 3,
    "vtheta_samples": 20,
    "controller_frequency": 20.0,
    "meter_scoring": False,
    "pdist_scale": 0.6,
    "gdist_scale": 0.8,
    "occdist_scale": 0.01,
    "oscillation_reset_dist": 0.05,
    "prune_plan": True,
    "dwa": True,
    "escape_vel": -0.1,
    "escape_reset_dist": 0.10,
    "escape_reset_theta": math.pi / 4,
    "heading_scoring": False,
    "heading_lookahead": 0.325,
    "in_place_rotations": False,  # roverlab's: True samples TrajectoryPlanner's rotations
    # roverlab's (Nav2's SimpleProgressChecker names): the rotations once stalled
    "required_movement_radius": 0.5,
    "movement_time_allowance": 20.0,
    "simple_attractor": False,
    "world_model": "costmap",
}
# read by TrajectoryPlanner only with heading_scoring (warned when true), or never used
# (stop_time_buffer: its check is commented out), or visualisation;
# min_vel_theta is not one of TrajectoryPlannerROS's parameters (min_in_place_vel_theta is)
_TP_IGNORED = (
    "stop_time_buffer",
    "heading_scoring_timestep",
    "publish_cost_grid_pc",
    "global_frame_id",
    "min_vel_theta",
)
# TrajectoryPlannerROS's deprecated names (it warns and reads them)
_TP_RENAMED = {
    "backup_vel": "escape_vel",
    "min_in_place_rotational_vel": "min_in_place_vel_theta",
    "max_rotational_vel": "max_vel_theta",
}
# other spellings read as these (rotate_recovery's acc_lim_th; DWA's bias names)
_TP_ALIAS = {
    "acc_lim_th": "acc_lim_theta",
    "path_distance_bias": "pdist_scale",
    "goal_distance_bias": "gdist_scale",
}


@dataclass(frozen=True, slots=True, kw_only=True)
class DWAParams:
    """DWAPlannerROS's parameters (m, rad, s).

    roverlab additions: ``controller_frequency`` (ROS searches it up the namespace, from
    move_base; ``sim_period = 1 / controller_frequency``), ``holonomic_robot`` (False forces
    ``vy = 0``; None: the ``min/max_vel_y`` decide, as DWA) and ``meter_scoring`` (False:
    the biases weigh cells, not metres: TrajectoryPlannerROS's default).

    base_local_planner's escape (TrajectoryPlannerROS's names and defaults, used by
    DWAPlannerROS too, where ROS has none): when every sampled trajectory is rejected the
    robot backs up at ``escape_vel`` (m/s, < 0; 0 turns escaping off) while its real
    footprint stays clear, and forward motion is not sampled until it has moved
    ``escape_reset_dist`` (m) or turned ``escape_reset_theta`` (rad) from where it began.

    ``in_place_samples`` (TrajectoryPlannerROS's roverlab parameter ``in_place_rotations``,
    default false): base_local_planner's TrajectoryPlanner also samples rotations in place
    every cycle (``vx = 0``, the theta window's ``vth_samples`` speeds, at least
    ``min_vel_theta`` = its ``min_in_place_vel_theta``), whatever ``min_vel_x`` is, and
    picks among them by ``heading_lookahead`` (m) with its stuck flags (:mod:`.in_place`).
    True is ROS's exact sampling; false (the default) samples only the dynamic window,
    which measured better on BARN (docs/benchmarks.md), until the robot stalls:
    ``movement_time_allowance`` (s; TrajectoryPlannerROS default 20, DWAPlannerROS 0 =
    never) without moving ``required_movement_radius`` (m, 0.5), Nav2's progress
    checker names, turns the rotations on until it has moved that far.
    """

    max_vel_trans: float = 0.55
    min_vel_trans: float = 0.1
    max_vel_x: float = 0.55
    min_vel_x: float = 0.0
    max_vel_y: float = 0.1
    min_vel_y: float = -0.1
    max_vel_theta: float = 1.0
    min_vel_theta: float = 0.4
    acc_lim_x: float = 2.5
    acc_lim_y: float = 2.5
    acc_lim_theta: float = 3.2
    acc_lim_trans: float = 0.1
    prune_plan: bool = True
    xy_goal_tolerance: float = 0.1
    yaw_goal_tolerance: float = 0.1
    trans_stopped_vel: float = 0.1
    theta_stopped_vel: float = 0.1
    latch_xy_goal_tolerance: bool = False
    sim_time: float = 1.7
    sim_granularity: float = 0.025
    angular_sim_granularity: float = 0.1
    path_distance_bias: float = 32.0
    goal_distance_bias: float = 24.0
    occdist_scale: float = 0.01
    twirling_scale: float = 0.0
    stop_time_buffer: float = 0.2
    oscillation_reset_dist: float = 0.05
    oscillation_reset_angle: float = 0.2
    forward_point_distance: float = 0.325
    scaling_speed: float = 0.25
    max_scaling_factor: float = 0.2
    vx_samples: int = 3
    vy_samples: int = 10
    vth_samples: int = 20
    use_dwa: bool = True
    sum_scores: bool = False
    controller_frequency: float = 20.0
    holonomic_robot: bool | None = None
    meter_scoring: bool = True
    escape_vel: float = -0.1
    escape_reset_dist: float = 0.10
    escape_reset_theta: float = math.pi / 4
    in_place_samples: bool = False
    heading_lookahead: float = 0.325
    required_movement_radius: float = 0.5
    movement_time_allowance: float = 0.0

    def __post_init__(self) -> None:
        w = "dwa_local_planner"
        check(
            self.escape_vel <= 0, f"{w}: escape_vel must be <= 0 (backwards), got {self.escape_vel}"
        )
        check(self.escape_reset_dist >= 0, f"{w}: escape_reset_dist must be >= 0")
        check(self.escape_reset_theta >= 0, f"{w}: escape_reset_theta must be >= 0")
        for name in (
            "max_vel_trans",
            "max_vel_theta",
            "acc_lim_x",
            "acc_lim_y",
            "acc_lim_theta",
            "xy_goal_tolerance",
            "yaw_goal_tolerance",
            "trans_stopped_vel",
            "theta_stopped_vel",
            "stop_time_buffer",
            "oscillation_reset_dist",
            "oscillation_reset_angle",
            "forward_point_distance",
            "scaling_speed",
            "max_scaling_factor",
            "path_distance_bias",
            "goal_distance_bias",
            "occdist_scale",
            "twirling_scale",
            "heading_lookahead",
            "required_movement_radius",
            "movement_time_allowance",
        ):
            check(getattr(self, name) >= 0, f"{w}: {name} must be >= 0, got {getattr(self, name)}")
        check(self.min_vel_x <= self.max_vel_x, f"{w}: min_vel_x must be <= max_vel_x")
        check(self.min_vel_y <= self.max_vel_y, f"{w}: min_vel_y must be <= max_vel_y")
        check(self.sim_time > 0, f"{w}: sim_time must be > 0, got {self.sim_time}")
        check(self.sim_granularity > 0, f"{w}: sim_granularity must be > 0")
        check(self.angular_sim_granularity > 0, f"{w}: angular_sim_granularity must be > 0")
        check(self.controller_frequency > 0, f"{w}: controller_frequency must be > 0")
        for name in ("vx_samples", "vy_samples", "vth_samples"):
            check(getattr(self, name) <= 1000, f"{w}: {name} must be <= 1000")

    @property
    def sim_period(self) -> float:
        """``1 / controller_frequency``: the dynamic window's time step (s)."""
        return 1.0 / self.controller_frequency

    @property
    def samples(self) -> tuple[int, int, int]:
        """``vx_samples, vy_samples, vth_samples``, at least 1 each (DWAPlanner raises a
        zero to one with a warning)."""
        return max(1, self.vx_samples), max(1, self.vy_samples), max(1, self.vth_samples)

    @property
    def y_limits(self) -> tuple[float, float]:
        """``(min_vel_y, max_vel_y)``, ``(0, 0)`` when ``holonomic_robot`` is False."""
        if self.holonomic_robot is False:
            return 0.0, 0.0
        return self.min_vel_y, self.max_vel_y

    @classmethod
    def from_ros(cls, values: Mapping[str, Any]) -> tuple[DWAParams, tuple[str, ...]]:
        """From ``DWAPlannerROS/...`` parameters (ROS names; old names renamed).

        Raises:
            NavigationParamsError: a bad value (an unknown name is a warning).
        """
        values = {k: v for k, v in values.items() if k not in NODE_KEYS}
        p, res = build_params(
            cls, values, where="dwa_local_planner", renamed=_RENAMED, ignored=_IGNORED
        )
        warnings = list(res.warnings)
        if "acc_lim_trans" in values or "acc_limit_trans" in values:
            warnings.append(
                "dwa_local_planner: parameter acc_lim_trans has no effect: the trajectory "
                "generator limits acc_lim_x and acc_lim_y, as ROS's does"
            )
        for name in ("vx_samples", "vy_samples", "vth_samples"):
            if getattr(p, name) <= 0:
                warnings.append(
                    f"dwa_local_planner: {name} <= 0: at least one sample is taken in that "
                    "dimension"
                )
        return p, tuple(warnings)

    @classmethod
    def from_trajectory_planner_ros(
        cls, values: Mapping[str, Any]
    ) -> tuple[DWAParams, tuple[str, ...]]:
        """From ``TrajectoryPlannerROS/...`` parameters (base_local_planner), on its
        defaults: the velocity limits, acceleration limits, sampling, goal tolerances and
        the three biases (``pdist_scale``, ``gdist_scale``, ``occdist_scale`` and their
        newer names). TrajectoryPlanner has no alignment or nose-goal cost: the forward
        point distance is 0 and the path and goal biases are halved, since with a zero
        shift those two critics repeat the path and goal ones.

        Raises:
            NavigationParamsError: a bad value (an unknown name is a warning).
        """
        v = dict(_TP_DEFAULTS)
        w = "base_local_planner"
        warnings: list[str] = []
        for key, value in values.items():
            if key in NODE_KEYS:
                continue
            if key in _TP_IGNORED:
                warnings.append(f"{w}: parameter {key} has no effect in roverlab (ignored)")
                continue
            new = _TP_RENAMED.get(key)
            if new is not None:
                if new in values:
                    warnings.append(f"{w}: parameter {key} is deprecated and {new} is set")
                    continue
                warnings.append(f"{w}: parameter {key} has been renamed to {new}")
                key = new
            key = _TP_ALIAS.get(key, key)
            if key not in _TP_DEFAULTS and key != "angular_sim_granularity":
                known = [*_TP_DEFAULTS, *_TP_RENAMED, *_TP_ALIAS]
                warnings.append(unknown_warning(w, key, known))
                continue
            v[key] = value
        for key, why in (
            ("heading_scoring", "the path distance is scored, not the heading to the path"),
            ("simple_attractor", "the path and goal distances are scored"),
        ):
            if v[key] is True:
                warnings.append(f"{w}: {key} true is not implemented by roverlab ({why})")
        if v["world_model"] != "costmap":
            warnings.append(
                f"{w}: world_model {v['world_model']!r} is not implemented: the costmap's "
                "cells are checked (world_model costmap)"
            )
        y_vels = v["y_vels"]
        if not isinstance(y_vels, list | tuple) or not y_vels:
            raise NavigationParamsError("base_local_planner: y_vels must be a list of speeds")
        holonomic = v["holonomic_robot"]
        vy_lo, vy_hi = (min(y_vels), max(y_vels)) if holonomic is True else (0.0, 0.0)
        vmax = float(v["max_vel_x"])
        max_trans = float((vmax**2 + max(abs(vy_lo), abs(vy_hi)) ** 2) ** 0.5)
        mapped = {
            "acc_lim_x": v["acc_lim_x"],
            "acc_lim_y": v["acc_lim_y"],
            "acc_lim_theta": v["acc_lim_theta"],
            "max_vel_x": v["max_vel_x"],
            "min_vel_x": v["min_vel_x"],
            "max_vel_y": vy_hi,
            "min_vel_y": vy_lo,
            "max_vel_trans": max_trans,
            "min_vel_trans": max(float(v["min_vel_x"]), 0.0),
            "max_vel_theta": v["max_vel_theta"],
            "min_vel_theta": v["min_in_place_vel_theta"],
            "holonomic_robot": holonomic,
            "yaw_goal_tolerance": v["yaw_goal_tolerance"],
            "xy_goal_tolerance": v["xy_goal_tolerance"],
            "latch_xy_goal_tolerance": v["latch_xy_goal_tolerance"],
            "sim_time": v["sim_time"],
            "sim_granularity": v["sim_granularity"],
            "angular_sim_granularity": v.get("angular_sim_granularity", v["sim_granularity"]),
            "vx_samples": v["vx_samples"],
            "vy_samples": len(y_vels) if holonomic is True else 1,
            "vth_samples": v["vtheta_samples"],
            "controller_frequency": v["controller_frequency"],
            "meter_scoring": v["meter_scoring"],
            "oscillation_reset_dist": v["oscillation_reset_dist"],
            "prune_plan": v["prune_plan"],
            "use_dwa": v["dwa"],
            "occdist_scale": v["occdist_scale"],
            "forward_point_distance": 0.0,
            "scaling_speed": 0.0,
            "max_scaling_factor": 0.0,
            "escape_vel": v["escape_vel"],
            "escape_reset_dist": v["escape_reset_dist"],
            "escape_reset_theta": v["escape_reset_theta"],
            "in_place_samples": v["in_place_rotations"],
            "heading_lookahead": v["heading_lookahead"],
            "required_movement_radius": v["required_movement_radius"],
            "movement_time_allowance": v["movement_time_allowance"],
            # TrajectoryPlannerROS reads stop_time_buffer, but the check that used it is
            # commented out in TrajectoryPlanner::generateTrajectory: a trajectory is
            # checked up to sim_time and no further
            "stop_time_buffer": 0.0,
        }
        for name, key in (
            ("path_distance_bias", "pdist_scale"),
            ("goal_distance_bias", "gdist_scale"),
        ):
            val = v[key]
            if isinstance(val, bool) or not isinstance(val, int | float):
                raise NavigationParamsError(f"base_local_planner: {key} must be a number")
            mapped[name] = float(val) / 2.0
        p, res = build_params(cls, mapped, where="base_local_planner")
        return p, tuple(warnings) + res.warnings
