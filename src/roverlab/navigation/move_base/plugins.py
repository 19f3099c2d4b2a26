"""move_base's plugins by their ROS names: global planners, local planners, recoveries.

Pure factories: each takes the plugin's ROS parameters (what the node finds under
``~NAME/``) and returns the algorithm object, or raises NavigationParamsError naming the
plugin and the parameter.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from roverlab.navigation.controllers import (
    ControllerProtocol,
    DWAParams,
    DWAPlanner,
    TebParams,
    TebPlanner,
)
from roverlab.navigation.costmap.footprint import footprint_radii
from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.move_base.behaviors import (
    BackUp,
    BehaviorParams,
    MoveSlowAndClear,
    Spin,
    Wait,
)
from roverlab.navigation.move_base.recovery import (
    ClearCostmapRecovery,
    RotateRecovery,
    RotateRecoveryParams,
)
from roverlab.navigation.params import unknown_warning
from roverlab.navigation.planners import (
    GlobalPlanner,
    GlobalPlannerParams,
    NavfnParams,
    NavfnPlanner,
    PlannerProtocol,
)

__all__ = [
    "LocalPlannerLimits",
    "make_global_planner",
    "make_local_planner",
    "make_recovery",
    "plugin_short_name",
    "rotate_fallback",
]


def plugin_short_name(plugin: str) -> str:
    """``NavfnROS`` of ``navfn/NavfnROS``: the namespace its parameters live in."""
    return plugin.rsplit("/", 1)[-1]


def make_global_planner(
    plugin: str, values: Mapping[str, Any]
) -> tuple[PlannerProtocol, tuple[str, ...]]:
    """The global planner ``plugin`` with its parameters; also the warnings to log."""
    if plugin == "navfn/NavfnROS":
        p, warnings = NavfnParams.from_ros(values)
        return NavfnPlanner(p), warnings
    if plugin == "global_planner/GlobalPlanner":
        gp, warnings = GlobalPlannerParams.from_ros(values)
        return GlobalPlanner(gp), warnings
    raise NavigationParamsError(f"move_base: unknown base_global_planner {plugin!r}")


@dataclass(frozen=True)
class LocalPlannerLimits:
    """What rotate_recovery borrows from the local planner when its own are not set."""

    acc_lim_th: float
    max_rotational_vel: float
    min_in_place_rotational_vel: float
    yaw_goal_tolerance: float


def make_local_planner(
    plugin: str,
    values: Mapping[str, Any],
    *,
    footprint: ArrayLike,
    controller_frequency: float,
    body_footprint: ArrayLike | None = None,
) -> tuple[ControllerProtocol, LocalPlannerLimits, tuple[str, ...]]:
    """The local planner ``plugin`` with its parameters (``controller_frequency`` is
    move_base's, as ROS's local planners search it up), its rotation limits, warnings.
    ``footprint`` is the costmap's (padded) one, ``body_footprint`` the robot's own (the
    escape checks it; None: ``footprint``)."""
    if plugin in ("dwa_local_planner/DWAPlannerROS", "base_local_planner/TrajectoryPlannerROS"):
        merged = {"controller_frequency": controller_frequency, **values}
        if plugin == "dwa_local_planner/DWAPlannerROS":
            dp, warnings = DWAParams.from_ros(merged)
        else:
            dp, warnings = DWAParams.from_trajectory_planner_ros(merged)
        limits = LocalPlannerLimits(
            acc_lim_th=dp.acc_lim_theta,
            max_rotational_vel=dp.max_vel_theta,
            min_in_place_rotational_vel=dp.min_vel_theta,
            yaw_goal_tolerance=dp.yaw_goal_tolerance,
        )
        return DWAPlanner(dp, footprint=footprint, body_footprint=body_footprint), limits, warnings
    if plugin == "teb_local_planner/TebLocalPlannerROS":
        tp, warnings = TebParams.from_ros({"controller_frequency": controller_frequency, **values})
        limits = LocalPlannerLimits(
            acc_lim_th=tp.acc_lim_theta,
            max_rotational_vel=tp.max_vel_theta,
            min_in_place_rotational_vel=min(0.4, tp.max_vel_theta),
            yaw_goal_tolerance=tp.yaw_goal_tolerance,
        )
        return TebPlanner(tp, footprint=footprint), limits, warnings
    raise NavigationParamsError(f"move_base: unknown base_local_planner {plugin!r}")


Recovery = ClearCostmapRecovery | RotateRecovery | MoveSlowAndClear | BackUp | Spin | Wait
_BEHAVIORS: dict[str, type[BackUp | Spin | Wait]] = {
    "nav2_behaviors/BackUp": BackUp,
    "nav2_behaviors/Spin": Spin,
    "nav2_behaviors/Wait": Wait,
}


def rotate_fallback(limits: LocalPlannerLimits, footprint: ArrayLike, body: ArrayLike) -> BackUp:
    """What a rotate_recovery that cannot turn hands over to: backing up at 0.1 m/s far
    enough for the padded footprint to clear what the body clears (its circumscribed
    radius less the body's inscribed radius, at least 0.1 m), the body checked."""
    _, circumscribed = footprint_radii(np.asarray(footprint, dtype=np.float64).reshape(-1, 2))
    inscribed, _ = footprint_radii(np.asarray(body, dtype=np.float64).reshape(-1, 2))
    params = BehaviorParams(backup_dist=max(0.1, circumscribed - inscribed), backup_speed=0.1,
                            max_rotational_vel=limits.max_rotational_vel)  # fmt: skip
    return BackUp("rotate_recovery/back_up", params, footprint=body)


def make_recovery(
    name: str,
    plugin: str,
    values: Mapping[str, Any],
    *,
    default_reset_distance: float,
    limits: LocalPlannerLimits,
    trajectory_planner: Mapping[str, Any],
    footprint: ArrayLike,
    body_footprint: ArrayLike | None = None,
) -> tuple[Recovery, tuple[str, ...]]:
    """One recovery behaviour, and warnings (unknown names: ROS ignores them).

    ``clear_costmap_recovery/ClearCostmapRecovery``: ``reset_distance`` defaults to
    ``default_reset_distance`` (move_base: ``conservative_reset_dist``, or four times the
    circumscribed radius for its ``aggressive_reset``).
    ``rotate_recovery/RotateRecovery``: its own ``sim_granularity`` and ``frequency``; the
    rotation limits from ``~TrajectoryPlannerROS/`` as ROS 1 reads them, else from the
    local planner in use (ROS falls back to fixed defaults there).
    """
    warnings: list[str] = []
    body = footprint if body_footprint is None else body_footprint
    behavior = _BEHAVIORS.get(plugin)
    if behavior is not None:
        bp, bw = BehaviorParams.from_ros(name, values)
        return behavior(name, bp, footprint=body), bw
    if plugin == "move_slow_and_clear/MoveSlowAndClear":
        return MoveSlowAndClear.from_ros(name, values)
    if plugin == "clear_costmap_recovery/ClearCostmapRecovery":
        rec = ClearCostmapRecovery.from_ros(
            name, values, default_reset_distance=default_reset_distance, warnings=warnings
        )
        return rec, tuple(warnings)
    if plugin == "rotate_recovery/RotateRecovery":
        known = ("sim_granularity", "frequency")
        warnings += [unknown_warning(name, k, known) for k in sorted(set(values) - set(known))]
        tp = trajectory_planner
        get: Callable[[str, float], float] = lambda key, fallback: float(  # noqa: E731
            tp.get(key, fallback)
        )
        try:
            params = RotateRecoveryParams(
                sim_granularity=float(values.get("sim_granularity", 0.017)),
                frequency=float(values.get("frequency", 20.0)),
                acc_lim_th=get("acc_lim_th", limits.acc_lim_th),
                max_rotational_vel=get("max_rotational_vel", limits.max_rotational_vel),
                min_in_place_rotational_vel=get(
                    "min_in_place_rotational_vel", limits.min_in_place_rotational_vel
                ),
                tolerance=get("yaw_goal_tolerance", limits.yaw_goal_tolerance),
            )
        except (TypeError, ValueError) as err:
            raise NavigationParamsError(f"{name}: {err}") from None
        return RotateRecovery(name, params, footprint=footprint), tuple(warnings)
    raise NavigationParamsError(f"move_base: unknown recovery behavior type {plugin!r}")
