"""Run a launch file: build its nodes in one context, assemble the simulation, spin."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from roverlab.core import Context, Node, QoSProfile
from roverlab.description.check import robot_warnings
from roverlab.launch.registry import REGISTRY, LaunchState
from roverlab.launch.xml import LaunchError, LaunchSpec, load_launch
from roverlab.msgs import classes as mc
from roverlab.sim.node import SimulatorNode, SpawnPose
from roverlab.sim.robot import sim_config_from_model
from roverlab.world import world_warnings

__all__ = ["Launch", "build_launch"]


@dataclass
class Launch:
    """The nodes a launch file started, and what it could not start."""

    context: Context
    spec: LaunchSpec
    nodes: list[Node] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    simulator: SimulatorNode | None = None
    world_warnings: list[str] = field(default_factory=list)
    """The Gazebo world's warnings, grouped (models and meshes not found, ...)."""
    robot_warnings: list[str] = field(default_factory=list)
    """The spawned robot's warnings (urdfdom's, unsupported plugins and sensors)."""


def build_launch(
    path: str | Path | LaunchSpec,
    args: Mapping[str, str] | None = None,
    *,
    context: Context,
    seed: int = 0,
) -> Launch:
    """Read ``path`` (or take an already read :class:`LaunchSpec`, ``args`` unused) and
    create its nodes in ``context``.

    Nodes roverlab has no implementation of are skipped with a warning (ROS would fail to
    start them; skipping lets the rest of a launch file run). Parameters a node does not
    implement are reported the same way.

    Raises:
        LaunchError: a malformed file, a missing file or package, a bad node argument.
    """
    spec = path if isinstance(path, LaunchSpec) else load_launch(path, args)
    state = LaunchState(context=context, params=spec.params)
    launch = Launch(context=context, spec=spec)
    for node_spec in spec.nodes:
        factory = REGISTRY.get((node_spec.pkg, node_spec.type))
        if factory is None:
            state.warnings.append(
                f"{node_spec.source}: node {node_spec.pkg}/{node_spec.type} is not part of "
                "roverlab; skipped"
            )
            continue
        node = factory(state, node_spec)
        if node is not None:
            unused = node.unused_parameter_overrides()
            if unused:
                state.warnings.append(
                    f"{node_spec.source}: parameters not used by roverlab's "
                    f"{node_spec.pkg}/{node_spec.type}: {', '.join(sorted(unused))}"
                )
                node.discard_parameter_overrides(unused)
            launch.nodes.append(node)
    if state.spawns:
        if state.world is None:
            raise LaunchError(f"{state.spawns[0][2]}: spawn_model without a Gazebo world")
        if len(state.spawns) > 1:
            raise LaunchError(f"{state.spawns[1][2]}: one robot per simulation is supported")
        robot, (x, y, yaw), _ = state.spawns[0]
        launch.robot_warnings = robot_warnings(robot)
        launch.simulator = SimulatorNode(
            context=context,
            scene=state.world.to_scene(),
            robot=sim_config_from_model(robot),
            spawn=SpawnPose(x, y, yaw),
            seed=seed,
        )
        launch.nodes.append(launch.simulator)
        topic = context.graph.topics.get("/robot_description")
        if topic is None or not topic.publishers:
            # like Gazebo holding the spawned model: others (another launch's
            # robot_state_publisher) get the description from the latched topic
            holder = context.create_node("robot_description_publisher")
            holder.create_publisher(
                mc.String, "/robot_description", QoSProfile(depth=1, durability="transient_local")
            ).publish(mc.String(state.spawn_urdf))
            launch.nodes.append(holder)
    elif state.world is not None:
        state.warnings.append(f"{state.world_source}: a world without a spawned robot")
    if state.world is not None:
        launch.world_warnings = world_warnings(state.world)
    launch.warnings = state.warnings
    return launch
