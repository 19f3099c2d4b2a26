"""teb_local_planner's parameters (``TebLocalPlannerReconfigure.cfg`` / ``teb_config``
names and defaults) and its ``footprint_model``.

Names of teb_local_planner features roverlab does not implement (homotopy class
planning, costmap_converter plugins, dynamic obstacles, the shrink-horizon backup mode,
visualisation) are accepted with a warning naming them, and so is an unknown name (ROS
ignores it). Homotopy class planning is on by default in teb: unless
``enable_homotopy_class_planning`` is false, a warning says it is not implemented.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.params import build_params, check, flatten_ros, unknown_warning

__all__ = ["FOOTPRINT_MODELS", "FootprintModel", "TebParams"]

FOOTPRINT_MODELS = ("point", "circular", "two_circles", "line", "polygon")

_NOT_IMPLEMENTED = (
    "enable_multithreading",
    "simple_exploration",
    "max_number_classes",
    "max_number_plans_in_current_class",
    "selection_cost_hysteresis",
    "selection_prefer_initial_plan",
    "selection_obst_cost_scale",
    "selection_viapoint_cost_scale",
    "selection_alternative_time_cost",
    "selection_dropping_probability",
    "switching_blocking_period",
    "roadmap_graph_no_samples",
    "roadmap_graph_area_width",
    "roadmap_graph_area_length_scale",
    "h_signature_prescaler",
    "h_signature_threshold",
    "obstacle_keypoint_offset",
    "obstacle_heading_threshold",
    "viapoints_all_candidates",
    "visualize_hc_graph",
    "visualize_with_time_as_z_axis_scale",
    "delete_detours_backwards",
    "detours_orientation_tolerance",
    "length_start_orientation_vector",
    "max_ratio_detours_duration_best_duration",
    "include_dynamic_obstacles",
    "dynamic_obstacle_inflation_dist",
    "weight_dynamic_obstacle",
    "weight_dynamic_obstacle_inflation",
    "weight_velocity_obstacle_ratio",
    "obstacle_proximity_ratio_max_vel",
    "obstacle_proximity_lower_bound",
    "obstacle_proximity_upper_bound",
    "costmap_converter_plugin",
    "costmap_converter_spin_thread",
    "costmap_converter_rate",
    "shrink_horizon_backup",
    "shrink_horizon_min_duration",
    "divergence_detection_enable",
    "divergence_detection_max_chi_squared",
    "publish_feedback",
    "optimization_verbose",
    "map_frame",
    "legacy_obstacle_association",
    "obstacle_poses_affected",
    "wheelbase",
    "cmd_angle_instead_rotvel",
    "is_footprint_dynamic",
)


_FOOTPRINT_KEYS = frozenset(
    {
        "type",
        "radius",
        "front_offset",
        "front_radius",
        "rear_offset",
        "rear_radius",
        "line_start",
        "line_end",
        "vertices",
    }
)


@dataclass(frozen=True, slots=True)
class FootprintModel:
    """TEB's robot model for the obstacle distances (``footprint_model/*``).

    Attributes:
        type: ``point``, ``circular`` (``radius``), ``two_circles`` (``front_offset``,
            ``front_radius``, ``rear_offset``, ``rear_radius``), ``line`` (``line_start``,
            ``line_end``) or ``polygon`` (``vertices``).
        values: the model's numbers in that order (line: start x, y, end x, y; polygon:
            the vertices flattened).
    """

    type: str = "point"
    values: tuple[float, ...] = ()

    @property
    def code(self) -> int:
        return FOOTPRINT_MODELS.index(self.type)

    def as_array(self) -> NDArray[np.float64]:
        return np.asarray(self.values, dtype=np.float64)

    @staticmethod
    def from_ros(values: Mapping[str, Any]) -> FootprintModel:
        """From ``footprint_model/...`` names (``type``, ``radius``, ``vertices``, ...).

        Raises:
            NavigationParamsError: an unknown type, a missing or bad value.
        """
        w = "teb_local_planner: footprint_model"
        t = values.get("type", "point")
        if t not in FOOTPRINT_MODELS:
            raise NavigationParamsError(
                f"{w}/type must be one of {', '.join(FOOTPRINT_MODELS)}, got {t!r}"
            )
        need = {
            "point": (),
            "circular": ("radius",),
            "two_circles": ("front_offset", "front_radius", "rear_offset", "rear_radius"),
            "line": ("line_start", "line_end"),
            "polygon": ("vertices",),
        }[t]
        unknown = sorted(set(values) - _FOOTPRINT_KEYS)
        if unknown:  # TebParams.from_ros warns about these and drops them first
            raise NavigationParamsError(f"{w}: unknown parameter {unknown[0]!r}")
        nums: list[float] = []
        for key in need:
            if key not in values:
                raise NavigationParamsError(f"{w}/{key} is required for type {t}")
            v = values[key]
            try:
                arr = np.asarray(v, dtype=np.float64).ravel()
            except (TypeError, ValueError) as err:
                raise NavigationParamsError(f"{w}/{key}: not numbers: {v!r}") from err
            shape_ok = {
                "line_start": arr.size == 2,
                "line_end": arr.size == 2,
                "vertices": arr.size >= 2 and arr.size % 2 == 0,
            }.get(key, arr.size == 1)
            if not shape_ok or not np.isfinite(arr).all():
                raise NavigationParamsError(f"{w}/{key}: bad value {v!r}")
            nums.extend(float(a) for a in arr)
        if t in ("circular",) and nums[0] < 0:
            raise NavigationParamsError(f"{w}/radius must be >= 0")
        return FootprintModel(t, tuple(nums))


@dataclass(frozen=True, slots=True, kw_only=True)
class TebParams:
    """TebLocalPlannerROS's parameters (m, rad, s). ``max_vel_trans`` 0: ``max_vel_x``."""

    teb_autosize: bool = True
    dt_ref: float = 0.3
    dt_hysteresis: float = 0.1
    min_samples: int = 3
    max_samples: int = 500
    global_plan_overwrite_orientation: bool = True
    allow_init_with_backwards_motion: bool = False
    #: roverlab's addition (0: off, as TEB): once every band has been "not feasible" for
    #: this many seconds in a row, the band is initialised backwards (as with
    #: ``allow_init_with_backwards_motion``) when the local goal lies behind the robot, so
    #: a robot standing in a pocket it cannot turn in backs out along its plan instead of
    #: waiting out move_base's ``controller_patience``
    backwards_init_when_stuck: float = 0.0
    global_plan_viapoint_sep: float = -0.1
    via_points_ordered: bool = False
    max_global_plan_lookahead_dist: float = 3.0
    global_plan_prune_distance: float = 1.0
    exact_arc_length: bool = False
    force_reinit_new_goal_dist: float = 1.0
    force_reinit_new_goal_angular: float = 0.5 * math.pi
    feasibility_check_no_poses: int = 5
    #: the check ends at the last pose within this distance of the first, whatever
    #: ``feasibility_check_no_poses`` says (<= 0: not used, TEB's default)
    feasibility_check_lookahead_distance: float = -1.0
    control_look_ahead_poses: int = 1
    min_resolution_collision_check_angular: float = math.pi
    max_vel_x: float = 0.4
    max_vel_x_backwards: float = 0.2
    max_vel_y: float = 0.0
    max_vel_trans: float = 0.0
    max_vel_theta: float = 0.3
    acc_lim_x: float = 0.5
    acc_lim_y: float = 0.5
    acc_lim_theta: float = 0.5
    min_turning_radius: float = 0.0
    use_proportional_saturation: bool = False
    footprint_model: FootprintModel = field(default_factory=FootprintModel)
    xy_goal_tolerance: float = 0.2
    yaw_goal_tolerance: float = 0.1
    free_goal_vel: bool = False
    complete_global_plan: bool = True
    trans_stopped_vel: float = 0.1
    theta_stopped_vel: float = 0.1
    min_obstacle_dist: float = 0.5
    inflation_dist: float = 0.6
    include_costmap_obstacles: bool = True
    costmap_obstacles_behind_robot_dist: float = 1.5
    obstacle_association_force_inclusion_factor: float = 1.5
    obstacle_association_cutoff_factor: float = 5.0
    no_inner_iterations: int = 5
    no_outer_iterations: int = 4
    optimization_activate: bool = True
    penalty_epsilon: float = 0.1
    obstacle_cost_exponent: float = 1.0
    weight_max_vel_x: float = 2.0
    weight_max_vel_y: float = 2.0
    weight_max_vel_theta: float = 1.0
    weight_acc_lim_x: float = 1.0
    weight_acc_lim_y: float = 1.0
    weight_acc_lim_theta: float = 1.0
    weight_kinematics_nh: float = 1000.0
    weight_kinematics_forward_drive: float = 1.0
    weight_kinematics_turning_radius: float = 1.0
    weight_optimaltime: float = 1.0
    weight_shortest_path: float = 0.0
    weight_obstacle: float = 50.0
    weight_inflation: float = 0.1
    weight_viapoint: float = 1.0
    weight_adapt_factor: float = 2.0
    weight_prefer_rotdir: float = 50.0
    #: TEB's oscillation recovery: when the last ``oscillation_filter_duration`` s of
    #: commands oscillate (see :mod:`.recovery`), prefer the current turning direction
    #: for ``oscillation_recovery_min_duration`` s (``weight_prefer_rotdir`` on the band's
    #: first three turns)
    oscillation_recovery: bool = True
    oscillation_v_eps: float = 0.1
    oscillation_omega_eps: float = 0.1
    oscillation_recovery_min_duration: float = 10.0
    oscillation_filter_duration: float = 10.0
    #: move_base's (TEB reads it from there, 5 Hz without it): sizes the oscillation
    #: filter and turns control cycles into seconds
    controller_frequency: float = 5.0

    def __post_init__(self) -> None:
        w = "teb_local_planner"
        check(self.dt_ref > 0, f"{w}: dt_ref must be > 0, got {self.dt_ref}")
        check(0 <= self.dt_hysteresis < self.dt_ref, f"{w}: dt_hysteresis must be in [0, dt_ref)")
        check(self.min_samples >= 3, f"{w}: min_samples must be >= 3")
        check(self.max_samples >= self.min_samples, f"{w}: max_samples must be >= min_samples")
        check(self.max_vel_x > 0, f"{w}: max_vel_x must be > 0")
        check(self.max_vel_x_backwards >= 0, f"{w}: max_vel_x_backwards must be >= 0")
        check(self.backwards_init_when_stuck >= 0, f"{w}: backwards_init_when_stuck must be >= 0")
        check(self.max_vel_theta > 0, f"{w}: max_vel_theta must be > 0")
        for name in ("acc_lim_x", "acc_lim_theta"):
            check(getattr(self, name) > 0, f"{w}: {name} must be > 0")
        check(self.min_turning_radius >= 0, f"{w}: min_turning_radius must be >= 0")
        check(self.xy_goal_tolerance >= 0, f"{w}: xy_goal_tolerance must be >= 0")
        check(self.yaw_goal_tolerance >= 0, f"{w}: yaw_goal_tolerance must be >= 0")
        check(self.min_obstacle_dist >= 0, f"{w}: min_obstacle_dist must be >= 0")
        check(self.inflation_dist >= 0, f"{w}: inflation_dist must be >= 0")
        check(1 <= self.no_inner_iterations <= 100, f"{w}: no_inner_iterations must be 1..100")
        check(1 <= self.no_outer_iterations <= 100, f"{w}: no_outer_iterations must be 1..100")
        check(self.penalty_epsilon >= 0, f"{w}: penalty_epsilon must be >= 0")
        check(self.feasibility_check_no_poses >= 0, f"{w}: feasibility_check_no_poses >= 0")
        check(self.control_look_ahead_poses >= 1, f"{w}: control_look_ahead_poses must be >= 1")
        check(
            self.min_resolution_collision_check_angular > 0,
            f"{w}: min_resolution_collision_check_angular must be > 0",
        )
        for name in TebParams.__dataclass_fields__:
            if name.startswith("weight_"):
                check(getattr(self, name) >= 0, f"{w}: {name} must be >= 0")
        check(self.weight_adapt_factor >= 1, f"{w}: weight_adapt_factor must be >= 1")
        check(self.controller_frequency > 0, f"{w}: controller_frequency must be > 0")
        check(self.oscillation_filter_duration >= 0, f"{w}: oscillation_filter_duration >= 0")

    @property
    def trans_limit(self) -> float:
        """``max_vel_trans``, or ``max_vel_x`` when it is 0."""
        return self.max_vel_trans if self.max_vel_trans > 0 else self.max_vel_x

    @classmethod
    def from_ros(cls, values: Mapping[str, Any]) -> tuple[TebParams, tuple[str, ...]]:
        """From ``TebLocalPlannerROS/...`` parameters (``footprint_model/type`` etc. flat or
        nested).

        Raises:
            NavigationParamsError: an unknown name or a bad value.
        """
        w = "teb_local_planner"
        flat = flatten_ros(values)
        fp = {k.split("/", 1)[1]: v for k, v in flat.items() if k.startswith("footprint_model/")}
        rest = {
            k: v
            for k, v in flat.items()
            if not k.startswith(("footprint_model/", "costmap_converter/")) and k != "odom_topic"
        }
        warnings: list[str] = []
        converter = sorted(k for k in flat if k.startswith("costmap_converter/"))
        if converter:
            warnings.append(
                f"{w}: costmap_converter plugins are not implemented by roverlab (each "
                f"occupied costmap cell is a point obstacle): {', '.join(converter)} ignored"
            )
        homotopy = rest.pop("enable_homotopy_class_planning", True)
        if homotopy is not False:
            warnings.append(
                f"{w}: enable_homotopy_class_planning is true (teb's default), but homotopy "
                "class planning is not implemented by roverlab: one trajectory, started from "
                "the global plan, is optimised (set it false to silence this warning)"
            )
        vy = rest.get("max_vel_y", 0.0)
        if vy != 0:
            warnings.append(
                f"{w}: max_vel_y {vy} ignored: roverlab's TEB plans for differential-drive "
                "and car-like robots only (holonomic motion is not implemented); max_vel_y 0"
            )
            rest["max_vel_y"] = 0.0
        for key in sorted(set(fp) - _FOOTPRINT_KEYS):
            warnings.append(unknown_warning(f"{w}: footprint_model", key, _FOOTPRINT_KEYS))
            fp.pop(key)
        extra = {"footprint_model": FootprintModel.from_ros(fp)} if fp else None
        p, res = build_params(cls, rest, where=w, ignored=_NOT_IMPLEMENTED, extra=extra)
        warnings.extend(res.warnings)
        if p.max_vel_x_backwards <= 0:
            warnings.append(
                "teb_local_planner: do not choose max_vel_x_backwards to be <= 0; disable "
                "backwards driving by increasing weight_kinematics_forward_drive"
            )
        return p, tuple(warnings)
