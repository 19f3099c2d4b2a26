"""move_base's recovery behaviours: clear_costmap_recovery and rotate_recovery.

Pure: they act on layered costmaps and poses; move_base's node runs them. A recovery
that moves the robot (rotate) is a stepper: :meth:`RotateRecovery.step` gives the next
velocity each control cycle until the rotation is done or blocked, so nothing blocks the
executor (ROS 1 runs it in a loop on move_base's thread).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from roverlab.geometry import SE2, wrap_angle
from roverlab.navigation.costmap.costmap_2d import Costmap2D
from roverlab.navigation.costmap.footprint_kernels import footprint_cost
from roverlab.navigation.costmap.layered import CostmapLayer, LayeredCostmap
from roverlab.navigation.costmap.obstacle_layer import ObstacleLayer
from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.params import unknown_warning

__all__ = ["ClearCostmapRecovery", "RotateRecovery", "RotateRecoveryParams"]

_AFFECTED = ("global", "local", "both")


class ClearCostmapRecovery:
    """clear_costmap_recovery: forget obstacles farther than ``reset_distance / 2`` from
    the robot (a square window), in the global and/or local costmap.

    Args:
        name: the recovery's name (``conservative_reset``).
        reset_distance: side of the kept window (m).
        layer_names: the layers to clear, by name (the part after the last ``/``). None
            (not set) clears every obstacle layer: ROS 1 defaults to ``["obstacles"]``,
            which clears nothing in the many setups whose layer is ``obstacle_layer``.
        affected_maps: ``global``, ``local`` or ``both``.
        invert_area_to_clear: clear inside the window instead.
        force_updating: the node updates the cleared costmaps at once.
    """

    type = "clear_costmap_recovery/ClearCostmapRecovery"

    def __init__(
        self,
        name: str,
        *,
        reset_distance: float = 3.0,
        layer_names: tuple[str, ...] | None = None,
        affected_maps: str = "both",
        invert_area_to_clear: bool = False,
        force_updating: bool = False,
    ) -> None:
        if not (math.isfinite(reset_distance) and reset_distance >= 0):
            raise NavigationParamsError(
                f"{name}: reset_distance must be >= 0, got {reset_distance}"
            )
        if affected_maps not in _AFFECTED:
            raise NavigationParamsError(
                f"{name}: affected_maps must be global, local or both, got {affected_maps!r}"
            )
        self.name = name
        self.reset_distance = float(reset_distance)
        self.layer_names = layer_names
        self.affected_maps = affected_maps
        self.invert_area_to_clear = invert_area_to_clear
        self.force_updating = force_updating

    @classmethod
    def from_ros(
        cls,
        name: str,
        values: Mapping[str, Any],
        *,
        default_reset_distance: float,
        warnings: list[str] | None = None,
    ) -> ClearCostmapRecovery:
        """From the recovery's ROS parameters (``~NAME/reset_distance``, ...); an unknown
        name is appended to ``warnings`` (ROS ignores it).

        Raises:
            NavigationParamsError: a bad parameter, named.
        """
        known = {
            "reset_distance",
            "layer_names",
            "affected_maps",
            "invert_area_to_clear",
            "force_updating",
        }
        for key in sorted(set(values) - known):
            if warnings is not None:
                warnings.append(unknown_warning(name, key, known))
        layers = values.get("layer_names")
        if layers is not None and (
            not isinstance(layers, list | tuple) or not all(isinstance(x, str) for x in layers)
        ):
            raise NavigationParamsError(f"{name}: layer_names must be a list of layer names")
        try:
            distance = float(values.get("reset_distance", default_reset_distance))
        except (TypeError, ValueError):
            raise NavigationParamsError(f"{name}: reset_distance must be a number") from None
        return cls(
            name,
            reset_distance=distance,
            layer_names=None if layers is None else tuple(layers),
            affected_maps=str(values.get("affected_maps", "both")),
            invert_area_to_clear=bool(values.get("invert_area_to_clear", False)),
            force_updating=bool(values.get("force_updating", False)),
        )

    def _layers(self, costmap: LayeredCostmap) -> list[CostmapLayer]:
        out: list[CostmapLayer] = []
        for layer in costmap.plugins:
            if not isinstance(layer, CostmapLayer):
                continue
            short = layer.name.rsplit("/", 1)[-1]
            if self.layer_names is None:
                if isinstance(layer, ObstacleLayer):
                    out.append(layer)
            elif short in self.layer_names:
                out.append(layer)
        return out

    def clear(self, costmap: LayeredCostmap, pose: SE2) -> list[str]:
        """Clear ``costmap``'s chosen layers around ``pose`` (its frame); the names cleared."""
        grid = costmap.costmap
        half = self.reset_distance / 2.0
        x0, y0 = grid.world_to_map_no_bounds(pose.x - half, pose.y - half)
        xn, yn = grid.world_to_map_no_bounds(pose.x + half, pose.y + half)
        cleared = []
        for layer in self._layers(costmap):
            layer.clear_area(x0, y0, xn, yn, self.invert_area_to_clear)
            cleared.append(layer.name)
        return cleared

    def run(
        self,
        *,
        global_costmap: LayeredCostmap | None,
        global_pose: SE2 | None,
        local_costmap: LayeredCostmap | None,
        local_pose: SE2 | None,
    ) -> list[str]:
        """Clear the affected costmaps; ``global:NAME`` / ``local:NAME`` of every cleared
        layer."""
        out: list[str] = []
        if self.affected_maps in ("global", "both") and global_costmap and global_pose:
            out += [f"global:{n}" for n in self.clear(global_costmap, global_pose)]
        if self.affected_maps in ("local", "both") and local_costmap and local_pose:
            out += [f"local:{n}" for n in self.clear(local_costmap, local_pose)]
        return out


@dataclass(frozen=True)
class RotateRecoveryParams:
    """rotate_recovery's parameters (ROS names and defaults): its own ``sim_granularity``
    and ``frequency``, and the local planner's ``acc_lim_th``, ``max_rotational_vel``,
    ``min_in_place_rotational_vel`` and ``yaw_goal_tolerance`` (as ROS 1 reads them from
    ``~TrajectoryPlannerROS``)."""

    sim_granularity: float = 0.017
    frequency: float = 20.0
    acc_lim_th: float = 3.2
    max_rotational_vel: float = 1.0
    min_in_place_rotational_vel: float = 0.4
    tolerance: float = 0.10

    def __post_init__(self) -> None:
        for name in ("sim_granularity", "frequency", "acc_lim_th", "max_rotational_vel"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise NavigationParamsError(f"rotate_recovery: {name} must be > 0, got {v}")
        if not (0 <= self.min_in_place_rotational_vel <= self.max_rotational_vel):
            raise NavigationParamsError(
                "rotate_recovery: min_in_place_rotational_vel must be within "
                "[0, max_rotational_vel]"
            )
        if not (0 < self.tolerance < math.pi):
            raise NavigationParamsError("rotate_recovery: tolerance must be in (0, pi)")


class RotateRecovery:
    """rotate_recovery: turn once in place, if the footprint stays clear of obstacles.

    Call :meth:`start` with the robot's pose, then :meth:`step` each control cycle with the
    pose and the local costmap; it returns the angular speed to command, or None when the
    rotation is over (``finished``) or cannot be done (``blocked`` holds why).
    """

    type = "rotate_recovery/RotateRecovery"

    def __init__(self, name: str, params: RotateRecoveryParams | None = None, *,
                 footprint: ArrayLike = ()) -> None:  # fmt: skip
        self.name = name
        self.params = params or RotateRecoveryParams()
        self.footprint = np.ascontiguousarray(
            np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
        )
        self._start = 0.0
        self._got_180 = False
        self.finished = False
        self.blocked: str | None = None
        self._buf = np.empty((4096, 2), dtype=np.int64)

    def start(self, pose: SE2) -> None:
        self._start = pose.theta
        self._got_180 = False
        self.finished = False
        self.blocked = None

    def _left(self, yaw: float) -> float:
        tol = self.params.tolerance
        if not self._got_180:
            to_180 = abs(float(wrap_angle(self._start + math.pi - yaw)))
            if to_180 < tol:
                self._got_180 = True
            else:
                return math.pi + to_180
        return abs(float(wrap_angle(self._start - yaw)))

    def step(self, pose: SE2, costmap: Costmap2D) -> float | None:
        """The angular velocity for this cycle (rad/s, counter-clockwise), or None."""
        p = self.params
        left = self._left(pose.theta)
        if self._got_180 and left <= p.tolerance:
            self.finished = True
            return None
        sim = 0.0
        while sim < left:
            cost = footprint_cost(
                costmap.costs,
                costmap.resolution,
                costmap.origin_x,
                costmap.origin_y,
                pose.x,
                pose.y,
                pose.theta + sim,
                self.footprint,
                1.0,
                self._buf,
            )
            if cost < 0:
                self.blocked = (
                    "Rotate recovery can't rotate in place because there is a potential "
                    f"collision. Cost: {cost:.2f}"
                )
                return None
            sim += p.sim_granularity
        vel = math.sqrt(2.0 * p.acc_lim_th * left)
        return min(max(vel, p.min_in_place_rotational_vel), p.max_rotational_vel)
