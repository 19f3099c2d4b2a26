"""A robot that maps a world on its own: simulator + SLAM + move_base + explore_lite.

:func:`start_explore_stack` runs robot_navigation's ``explore.launch`` (the SLAM node of
``slam``, move_base with the NanoRobot parameters, explore) next to a :class:`Simulation`
in one context. The launch file's parameters are mybot's; for another robot the costmaps'
footprint is the outline of the robot's collision shapes (from its URDF, as the simulator
sees it) and the inflation radius grows to cover it, so the same launch file drives mbot.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.core import Context, Node
from roverlab.description import find_package
from roverlab.errors import RoverlabError
from roverlab.launch import Launch, build_launch
from roverlab.launch.xml import LaunchSpec, load_launch
from roverlab.navigation.costmap.footprint import footprint_radii, pad_footprint
from roverlab.navigation.costmap.inflation_layer import compute_cost
from roverlab.navigation.explore.node import Explore
from roverlab.navigation.move_base.node import MoveBase
from roverlab.sim.app import Simulation
from roverlab.sim.node import SpawnPose
from roverlab.world import World

__all__ = [
    "SLAM_METHODS",
    "SLAM_NODES",
    "AutonomyError",
    "ExploreStack",
    "footprint_params",
    "set_node_params",
    "start_explore_stack",
]

#: ``--slam`` choices -> the SLAM node's name in explore.launch
SLAM_NODES: dict[str, str] = {
    "gmapping": "slam_gmapping",
    "hector": "hector_mapping",
    "graph": "slam_toolbox",
}
SLAM_METHODS = tuple(SLAM_NODES)

# robot_navigation's NanoRobot parameters were written for mybot
_PARAMS_ROBOT = "mybot"
_INFLATION_M = 0.45  # NanoRobot's inflation_radius
_FOOTPRINT_PADDING_M = 0.01
_COST_SCALING = 6.0  # NanoRobot's cost_scaling_factor


class AutonomyError(RoverlabError):
    """A run that cannot be set up: an unknown SLAM method, a robot without a drive."""


@dataclass
class ExploreStack:
    """The nodes of one exploring robot."""

    simulation: Simulation
    launch: Launch
    slam: Node
    move_base: MoveBase
    explore: Explore
    nodes: list[Node] = field(default_factory=list)

    def destroy_navigation(self) -> None:
        """Stop explore, move_base and the SLAM node (the simulator keeps running)."""
        for node in (self.explore, self.move_base, self.slam):
            node.destroy_node()


def footprint_params(footprint: np.ndarray, inflation_m: float = _INFLATION_M) -> dict[str, Any]:
    """Both costmaps' ``footprint`` (the outline, padded in the costmap), an inflation
    radius that covers the robot's circumscribed radius plus a margin, and the global
    planner's ``lethal_cost`` at that circumscribed radius (as explore_planner_params.yaml
    for mybot: plans only where the robot can turn in place)."""
    outline = [[round(float(x), 3), round(float(y), 3)] for x, y in footprint]
    padded = pad_footprint(np.asarray(outline), _FOOTPRINT_PADDING_M)
    inscribed, circumscribed = footprint_radii(padded)
    inflation = max(inflation_m, circumscribed + 0.2)
    at_circumscribed = compute_cost(circumscribed, 1.0, inscribed, _COST_SCALING)
    out: dict[str, Any] = {"GlobalPlanner/lethal_cost": min(253, at_circumscribed + 2)}
    for costmap in ("global_costmap", "local_costmap"):
        out[f"{costmap}/footprint"] = outline
        out[f"{costmap}/inflation_layer/inflation_radius"] = inflation
    return out


def set_node_params(spec: LaunchSpec, node: str, params: dict[str, Any]) -> None:
    """Set private parameters of the launch file's node ``node`` (its ``<param>`` and
    ``<rosparam>`` lines; they win over global ones, so overrides go here).

    Raises:
        AutonomyError: the launch file has no such node.
    """
    found = [n for n in spec.nodes if n.name == node]
    if not found:
        raise AutonomyError(f"the launch file starts no node named {node!r}")
    for n in found:
        n.params.update(params)


def start_explore_stack(
    context: Context,
    *,
    world: str | Path | World = "maze",
    robot: str | Path = "mybot",
    slam: str = "gmapping",
    seed: int = 0,
    spawn: SpawnPose | None = None,
    planner: str = "dwa",
    cameras: bool = False,
    explore_params: dict[str, Any] | None = None,
) -> ExploreStack:
    """Start the simulator and robot_navigation's explore.launch in ``context``.

    Args:
        world, robot, seed, spawn, cameras: as :class:`~roverlab.sim.app.Simulation`.
        slam: ``gmapping``, ``hector`` or ``graph`` (slam_toolbox).
        planner: move_base's local planner (``dwa`` or ``teb``).
        explore_params: explore's parameters over the launch file's (``progress_timeout``...).

    Raises:
        AutonomyError: an unknown SLAM method or a robot that cannot drive.
        LaunchError, SimulationError: bad files.
    """
    if slam not in SLAM_NODES:
        raise AutonomyError(f"unknown SLAM method {slam!r} (one of {', '.join(SLAM_METHODS)})")
    simulation = Simulation(
        context=context, world=world, robot=robot, spawn=spawn or SpawnPose(), seed=seed,
        cameras=cameras,
    )  # fmt: skip
    if simulation.config.drive is None:
        raise AutonomyError(
            f"robot {robot}: no drive plugin (diff drive, skid steer or planar move), "
            "move_base cannot drive it"
        )
    spec = load_launch(
        find_package("robot_navigation") / "launch" / "explore.launch",
        {"simulation": "true", "slam": slam, "planner": planner, "base_type": "NanoRobot"},
    )
    if str(robot) != _PARAMS_ROBOT:
        set_node_params(spec, "move_base", footprint_params(simulation.config.footprint))
    set_node_params(spec, "explore", dict(explore_params or {}))
    launch = build_launch(spec, context=context, seed=seed)
    by_name = {n.get_name(): n for n in launch.nodes}
    (explore,) = [n for n in launch.nodes if isinstance(n, Explore)]
    (move_base,) = [n for n in launch.nodes if isinstance(n, MoveBase)]
    return ExploreStack(
        simulation=simulation,
        launch=launch,
        slam=by_name[SLAM_NODES[slam]],
        move_base=move_base,
        explore=explore,
        nodes=list(launch.nodes),
    )
