"""move_base's own parameters (ROS 1 names and defaults) and its recovery behaviour list."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.params import unknown_warning

__all__ = [
    "GLOBAL_PLANNERS",
    "LOCAL_PLANNERS",
    "RECOVERY_TYPES",
    "MoveBaseParams",
    "RecoverySpec",
    "default_recoveries",
]

#: ``base_global_planner`` values roverlab implements (ROS plugin names).
GLOBAL_PLANNERS = ("navfn/NavfnROS", "global_planner/GlobalPlanner")
#: ``base_local_planner`` values roverlab implements.
LOCAL_PLANNERS = (
    "dwa_local_planner/DWAPlannerROS",
    "teb_local_planner/TebLocalPlannerROS",
    "base_local_planner/TrajectoryPlannerROS",
)
#: ``recovery_behaviors`` types roverlab implements.
RECOVERY_TYPES = (
    "clear_costmap_recovery/ClearCostmapRecovery",
    "rotate_recovery/RotateRecovery",
    "move_slow_and_clear/MoveSlowAndClear",
    "nav2_behaviors/BackUp",
    "nav2_behaviors/Spin",
    "nav2_behaviors/Wait",
)

# dynamic_reconfigure's reset switch: nothing to reset in a parameter set read once
IGNORED = frozenset({"restore_defaults"})


@dataclass(frozen=True)
class RecoverySpec:
    """One entry of ``recovery_behaviors``: its name (its parameters live under it) and
    its plugin type."""

    name: str
    type: str


def default_recoveries(clearing_rotation_allowed: bool) -> tuple[RecoverySpec, ...]:
    """move_base's list when none is given: conservative reset, rotate, aggressive reset,
    rotate (the rotations only with ``clearing_rotation_allowed``)."""
    clear = "clear_costmap_recovery/ClearCostmapRecovery"
    rotate = "rotate_recovery/RotateRecovery"
    out = [RecoverySpec("conservative_reset", clear)]
    if clearing_rotation_allowed:
        out.append(RecoverySpec("rotate_recovery", rotate))
    out.append(RecoverySpec("aggressive_reset", clear))
    if clearing_rotation_allowed:
        out.append(RecoverySpec("rotate_recovery", rotate))
    return tuple(out)


@dataclass(frozen=True)
class MoveBaseParams:
    """move_base's parameters, ROS 1 names and defaults (move_base wiki, MoveBase.cfg).

    Attributes:
        base_global_planner: the global planner plugin (``navfn/NavfnROS``).
        base_local_planner: the local planner plugin
            (``base_local_planner/TrajectoryPlannerROS``, move_base's default).
        recovery_behaviors: the recovery list (default: :func:`default_recoveries`).
        controller_frequency: control cycles per second (Hz).
        planner_patience: seconds to find a valid plan before recovery.
        controller_patience: seconds without a valid control before recovery.
        conservative_reset_dist: the conservative reset keeps obstacles within this
            distance (m) of the robot.
        recovery_behavior_enabled: run recoveries at all.
        clearing_rotation_allowed: the default list rotates in place.
        shutdown_costmaps: stop the costmaps while no goal is active.
        oscillation_timeout: seconds without moving ``oscillation_distance`` before
            recovery (0: never).
        oscillation_distance: metres that count as moving.
        planner_frequency: replans per second while controlling (0: plan only when a new
            goal comes or the local planner fails).
        max_planning_retries: planning failures before recovery (-1: until
            ``planner_patience``).
        make_plan_clear_costmap: ``~make_plan`` first clears the obstacle layers in a
            ``2 * clearing_radius`` square around the robot.
        make_plan_add_unreachable_goal: a ``~make_plan`` answer that stops short of the
            goal (within the request's tolerance) ends with the goal itself.
        clearing_radius: that square's half side (m; None: the footprint's circumscribed
            radius, as move_base).
        plan_footprint_check: roverlab's addition (not in ROS): re-plan around places
            where the footprint, heading along the plan, would touch a lethal cell
            (:mod:`roverlab.navigation.planners.footprint_check`); false plans as ROS does.
    """

    base_global_planner: str = "navfn/NavfnROS"
    base_local_planner: str = "base_local_planner/TrajectoryPlannerROS"
    recovery_behaviors: tuple[RecoverySpec, ...] = field(default=())
    controller_frequency: float = 20.0
    planner_patience: float = 5.0
    controller_patience: float = 15.0
    conservative_reset_dist: float = 3.0
    recovery_behavior_enabled: bool = True
    clearing_rotation_allowed: bool = True
    shutdown_costmaps: bool = False
    oscillation_timeout: float = 0.0
    oscillation_distance: float = 0.5
    planner_frequency: float = 0.0
    max_planning_retries: int = -1
    make_plan_clear_costmap: bool = True
    make_plan_add_unreachable_goal: bool = True
    clearing_radius: float | None = None
    plan_footprint_check: bool = True

    def __post_init__(self) -> None:
        w = "move_base"
        if self.base_global_planner not in GLOBAL_PLANNERS:
            raise NavigationParamsError(
                f"{w}: base_global_planner {self.base_global_planner!r} is not available "
                f"(roverlab has {', '.join(GLOBAL_PLANNERS)})"
            )
        if self.base_local_planner not in LOCAL_PLANNERS:
            raise NavigationParamsError(
                f"{w}: base_local_planner {self.base_local_planner!r} is not available "
                f"(roverlab has {', '.join(LOCAL_PLANNERS)})"
            )
        positive = ("controller_frequency",)
        for name in positive:
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise NavigationParamsError(f"{w}: {name} must be > 0, got {v}")
        for name in (
            "planner_patience",
            "controller_patience",
            "conservative_reset_dist",
            "oscillation_timeout",
            "oscillation_distance",
            "planner_frequency",
            "clearing_radius",
        ):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v >= 0):
                raise NavigationParamsError(f"{w}: {name} must be >= 0, got {v}")
        for r in self.recovery_behaviors:
            if r.type not in RECOVERY_TYPES:
                raise NavigationParamsError(
                    f"{w}: recovery behavior {r.name!r} has type {r.type!r}, which is not "
                    f"available (roverlab has {', '.join(RECOVERY_TYPES)})"
                )

    @property
    def recoveries(self) -> tuple[RecoverySpec, ...]:
        """The recovery list in effect (the given one, or move_base's default)."""
        return self.recovery_behaviors or default_recoveries(self.clearing_rotation_allowed)

    @classmethod
    def from_ros(cls, values: Mapping[str, Any]) -> tuple[MoveBaseParams, tuple[str, ...]]:
        """From move_base's private parameters; plugin parameters (``NAME/...``, the
        costmaps', planners' and recoveries') are left to their plugins.

        Returns:
            The parameters and warnings (an unknown name: ROS ignores it, we name it).

        Raises:
            NavigationParamsError: a bad value, named.
        """
        names = {f.name: f for f in fields(cls)}
        kwargs: dict[str, Any] = {}
        warnings: list[str] = []
        recoveries = _recoveries(values.get("recovery_behaviors"))
        for key, value in values.items():
            if key == "recovery_behaviors" or key in IGNORED or "/" in key or "." in key:
                continue
            if key not in names:
                warnings.append(unknown_warning("move_base", key, names))
                continue
            kwargs[key] = _convert(key, value, names[key].default)
        return cls(recovery_behaviors=recoveries, **kwargs), tuple(warnings)


def _convert(key: str, value: Any, default: Any) -> Any:
    where = f"move_base: parameter {key!r}"
    if isinstance(default, bool):
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        raise NavigationParamsError(f"{where} must be true or false, got {value!r}")
    if isinstance(default, int):
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        if isinstance(value, float) and value.is_integer():
            return int(value)
        raise NavigationParamsError(f"{where} must be an integer, got {value!r}")
    if isinstance(default, float) or (default is None and key == "clearing_radius"):
        if isinstance(value, int | float) and not isinstance(value, bool):
            return float(value)
        try:
            return float(value)
        except (TypeError, ValueError):
            raise NavigationParamsError(f"{where} must be a number, got {value!r}") from None
    if not isinstance(value, str):
        raise NavigationParamsError(f"{where} must be a string, got {value!r}")
    return value


def _recoveries(value: Any) -> tuple[RecoverySpec, ...]:
    if value is None:
        return ()
    if not isinstance(value, list | tuple) or not value:
        raise NavigationParamsError(
            "move_base: recovery_behaviors must be a non-empty list of {name: ..., type: ...}"
        )
    out = []
    seen: set[str] = set()
    for item in value:
        if not isinstance(item, Mapping) or "name" not in item or "type" not in item:
            raise NavigationParamsError(
                f"move_base: recovery_behaviors entry {item!r} needs a name and a type"
            )
        name, typ = str(item["name"]), str(item["type"])
        if name in seen:
            raise NavigationParamsError(
                f"move_base: recovery_behaviors has the name {name!r} twice"
            )
        seen.add(name)
        out.append(RecoverySpec(name, typ))
    return tuple(out)
