"""Run a launch file: build its nodes in one context, assemble the simulation, spin."""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

from roverlab.core import Context, Node, QoSProfile
from roverlab.core.executor import ClockMode
from roverlab.core.log import log_to_file
from roverlab.core.logfiles import node_log_file
from roverlab.core.transport.zenoh import ZenohTransport
from roverlab.description.check import robot_notes, robot_warnings
from roverlab.launch.process import (
    ScriptLookupError,
    ScriptProcess,
    ScriptProcesses,
    child_network,
    find_script,
)
from roverlab.launch.registry import REGISTRY, LaunchState
from roverlab.launch.xml import LaunchError, LaunchSpec, NodeSpec, load_launch
from roverlab.msgs import classes as mc
from roverlab.sim.node import SimulatorNode, SpawnPose
from roverlab.sim.robot import sim_config_from_model
from roverlab.world import world_warnings

__all__ = ["Launch", "ScriptLookups", "build_launch", "find_launch_scripts"]

#: ``(pkg, type)`` -> the script that ``<node pkg type>`` runs, or why none runs
ScriptLookups = dict[tuple[str, str], Path | ScriptLookupError]


@contextlib.contextmanager
def _environment(env: Mapping[str, str]) -> Iterator[None]:
    """``env`` set in os.environ while a node is created (its ``<env>`` scope), then the
    process's own values back."""
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def find_launch_scripts(spec: LaunchSpec) -> ScriptLookups:
    """Each node type of ``spec`` that roverlab does not implement, looked up once as a
    script of its package (:func:`find_script`): ``roverlab launch`` decides from it
    whether the launch needs its script endpoint, and :func:`build_launch` starts the
    scripts (or warns) from it without walking the packages again."""
    found: ScriptLookups = {}
    for node_spec in spec.nodes:
        key = (node_spec.pkg, node_spec.type)
        if key not in REGISTRY and key not in found:
            found[key] = _lookup_script(*key)
    return found


def _lookup_script(pkg: str, type_: str) -> Path | ScriptLookupError:
    try:
        return find_script(pkg, type_)
    except ScriptLookupError as err:
        return err


@dataclass
class Launch:
    """The nodes a launch file started, and what it could not start."""

    context: Context
    spec: LaunchSpec
    nodes: list[Node] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    simulator: SimulatorNode | None = None
    state: LaunchState | None = None
    # what roslaunch does for a process: which node runs each <node>, and how it ended
    running: dict[str, tuple[NodeSpec, Node]] = field(default_factory=dict)
    deaths: list[str] = field(default_factory=list)
    # notes, not warnings: where roverlab does what roslaunch won't, and what the world and
    # the spawned robot say that the simulator does not act on (non-static models, contacts)
    notes: list[str] = field(default_factory=list)
    # the user's own scripts, each in a process of its own (roverlab run), by node name
    processes: dict[str, tuple[NodeSpec, ScriptProcess]] = field(default_factory=dict)
    # the scripts of the node types roverlab lacks, each looked up once (a respawn too)
    scripts: ScriptLookups = field(default_factory=dict)
    _group: ScriptProcesses | None = None
    _watch: threading.Thread | None = None

    def start_node(self, node_spec: NodeSpec) -> Node | None:
        """Create one ``<node>``; a node that fails to start has died (roslaunch's
        "process has died"): respawned after ``respawn_delay``, the launch shut down when
        it is ``required``, otherwise reported while the others go on."""
        assert self.state is not None
        factory = REGISTRY.get((node_spec.pkg, node_spec.type))
        if factory is None:
            self.start_script(node_spec)
            return None
        if node_spec.cwd is not None:
            self.state.warnings.append(
                f"{node_spec.source}: cwd={node_spec.cwd!r} not applied: roverlab's "
                f"{node_spec.pkg}/{node_spec.type} runs in the launch's process, so relative "
                f"paths resolve against its working directory ({os.getcwd()})"
            )
        if node_spec.launch_prefix:
            self.state.warnings.append(
                f"{node_spec.source}: launch-prefix={node_spec.launch_prefix!r} not applied: "
                f"roverlab's {node_spec.pkg}/{node_spec.type} runs in the launch's process"
            )
        before = set(self.context.nodes)
        try:
            with _environment(node_spec.env):
                node = factory(self.state, node_spec)
        except LaunchError:
            raise
        except Exception as err:  # the node's failure, in one line
            for name in set(self.context.nodes) - before:  # what it left half made
                self.context.nodes[name].destroy_node()
            self.died(node_spec, f"{type(err).__name__}: {err}".splitlines()[0])
            return None
        if node is None:
            return None
        unused = node.unused_parameter_overrides()
        if unused:
            self.state.warnings.append(
                f"{node_spec.source}: parameters not used by roverlab's "
                f"{node_spec.pkg}/{node_spec.type}: {', '.join(sorted(unused))}"
            )
            node.discard_parameter_overrides(unused)
        if node_spec.output == "log":
            name = node.get_fully_qualified_name()
            log_to_file(name, node_log_file(name))
        self.nodes.append(node)
        self.running[node_spec.fq_name] = (node_spec, node)
        return node

    def stop_processes(self) -> None:
        """Stop the script processes now (before the context's network closes, so their
        shutdown hooks' messages still travel); the context's shutdown would otherwise."""
        if self._group is not None:
            self._group.close()

    def start_script(self, node_spec: NodeSpec) -> None:
        """A ``<node>`` roverlab does not implement: the package's Python script in a
        process of its own (as ``roverlab run``), else skipped with a warning."""
        assert self.state is not None
        what = f"{node_spec.source}: node {node_spec.pkg}/{node_spec.type}"
        key = (node_spec.pkg, node_spec.type)
        if key not in self.scripts:
            self.scripts[key] = _lookup_script(*key)
        script = self.scripts[key]
        if isinstance(script, ScriptLookupError):
            joint = " is not part of roverlab, and" if script.missing else ":"
            self.state.warnings.append(f"{what}{joint} {script}; skipped")
            return
        if not os.access(script, os.X_OK):  # roslaunch: "found but it is not executable"
            self.notes.append(
                f"{what}: {script} is not executable (roslaunch refuses it; chmod +x "
                "it for ROS): run anyway"
            )
        zenoh = [t for t in self.context.transports if isinstance(t, ZenohTransport)]
        if not zenoh:
            raise LaunchError(
                f"{what}: the script runs in a process of its own, which needs the launch's "
                "topics exposed (--expose)"
            )
        if self._group is None:
            self._group = ScriptProcesses()
            self.context.add_transport(self._group)  # stopped when the context shuts down
        clock = "wall" if self.context.clock_mode is ClockMode.WALL else "external"
        proc = ScriptProcess(
            node_spec,
            script,
            clock=clock,
            params=self.spec.params,
            network=child_network(zenoh[0].options),
        )
        self._group.processes.append(proc)
        self.processes[node_spec.fq_name] = (node_spec, proc)

    def died(self, node_spec: NodeSpec, reason: str) -> None:
        """roslaunch's handling of a process that ended: respawn, shut down, or report."""
        name = node_spec.fq_name
        self.running.pop(name, None)
        self.processes.pop(name, None)
        if node_spec.required:
            self.deaths.append(f"REQUIRED process [{name}] has died: {reason}; shutting down")
            print(f"[ERROR] {self.deaths[-1]}", file=sys.stderr, flush=True)
            self.context.shutdown()
            return
        if node_spec.respawn:
            self.deaths.append(
                f"process [{name}] has died: {reason}; respawning in {node_spec.respawn_delay:g} s"
            )
            print(f"[WARN] {self.deaths[-1]}", file=sys.stderr, flush=True)
            timer = threading.Timer(
                node_spec.respawn_delay,
                self.context.executor.call_soon_threadsafe,
                (partial(self._respawn, node_spec),),
            )
            timer.daemon = True
            timer.start()
            return
        self.deaths.append(f"process [{name}] has died: {reason}")
        print(f"[ERROR] {self.deaths[-1]}", file=sys.stderr, flush=True)

    def _respawn(self, node_spec: NodeSpec) -> None:
        if not self.context.is_shutdown():
            self.start_node(node_spec)

    def supervise(self, period_s: float = 0.5) -> None:
        """Watch the nodes (wall clock) for ones that end themselves (``destroy_node``:
        a script that returned, ``rospy.signal_shutdown``) and treat them as dead."""

        def watch() -> None:
            stop = threading.Event()
            while not self.context.is_shutdown() and not stop.wait(period_s):
                for spec_node in list(self.running.values()):
                    node_spec, node = spec_node
                    if node.is_destroyed() and node_spec.fq_name in self.running:
                        self.context.executor.call_soon_threadsafe(partial(self._ended, node_spec))
                for node_spec, proc in list(self.processes.values()):
                    code = proc.poll()
                    if code is not None:
                        self.context.executor.call_soon_threadsafe(
                            partial(self._exited, node_spec, proc, code)
                        )

        self._watch = threading.Thread(target=watch, name="roslaunch-watch", daemon=True)
        self._watch.start()

    def _ended(self, node_spec: NodeSpec) -> None:
        name = node_spec.fq_name
        if name not in self.running or self.context.is_shutdown():
            return
        node = self.running[name][1]
        if node.exit_code == 0 and not (node_spec.required or node_spec.respawn):
            # its job done (map_saver wrote the map): roslaunch's clean exit
            self.running.pop(name)
            print(f"[INFO] process [{name}] has finished cleanly", file=sys.stderr, flush=True)
            return
        reason = "it ended" if node.exit_code is None else f"exit code {node.exit_code}"
        self.died(node_spec, reason)

    def _exited(self, node_spec: NodeSpec, proc: ScriptProcess, code: int) -> None:
        name = node_spec.fq_name
        if self.processes.get(name, (None, None))[1] is not proc or self.context.is_shutdown():
            return
        proc.stop()  # its files
        if code == 0 and not (node_spec.required or node_spec.respawn):
            self.processes.pop(name)
            print(f"[INFO] process [{name}] has finished cleanly", file=sys.stderr, flush=True)
            return
        self.died(node_spec, f"pid {proc.pid}, exit code {code}")

    world_warnings: list[str] = field(default_factory=list)
    """The Gazebo world's warnings, grouped (models and meshes not found, ...)."""
    robot_warnings: list[str] = field(default_factory=list)
    """The spawned robot's warnings (urdfdom's, unsupported plugins and sensors)."""


def _spawned_controllers(state: LaunchState) -> dict[str, Any]:
    """The parameter tree of every controller the spawner started, nested by namespace
    (``{"jackal_velocity_controller": {"type": ..., "linear": {"x": {...}}}}``)."""
    tree: dict[str, Any] = {}
    for ns, name in state.controllers:
        prefix = f"{ns.rstrip('/')}/{name}/"
        if not prefix.startswith("/"):
            prefix = "/" + prefix
        for key, value in state.params.items():
            if key.startswith(prefix):
                node = tree
                parts = [p for p in prefix.split("/") if p] + key[len(prefix) :].split("/")
                for part in parts[:-1]:
                    node = node.setdefault(part, {})
                node[parts[-1]] = value
    return tree


def build_launch(
    path: str | Path | LaunchSpec,
    args: Mapping[str, str] | None = None,
    *,
    context: Context,
    seed: int = 0,
    scripts: ScriptLookups | None = None,
) -> Launch:
    """Read ``path`` (or take an already read :class:`LaunchSpec`, ``args`` unused) and
    create its nodes in ``context``. ``scripts``: :func:`find_launch_scripts` of the spec,
    when the caller has it already (else each script is looked up as its node starts).

    Nodes roverlab has no implementation of are skipped with a warning (ROS would fail to
    start them; skipping lets the rest of a launch file run). Parameters a node does not
    implement are reported the same way.

    Raises:
        LaunchError: a malformed file, a missing file or package, a bad node argument.
    """
    spec = path if isinstance(path, LaunchSpec) else load_launch(path, args)
    state = LaunchState(
        context=context,
        params=spec.params,
        param_sources=spec.param_sources,
        warnings=list(spec.warnings),
    )
    launch = Launch(context=context, spec=spec, state=state, scripts=dict(scripts or {}))
    for node_spec in spec.nodes:
        launch.start_node(node_spec)
        if context.is_shutdown():  # a required node failed to start
            raise LaunchError(launch.deaths[-1])
    if state.spawns:
        if state.world is None:
            raise LaunchError(f"{state.spawns[0][2]}: spawn_model without a Gazebo world")
        if len(state.spawns) > 1:
            raise LaunchError(f"{state.spawns[1][2]}: one robot per simulation is supported")
        robot, (x, y, yaw), _ = state.spawns[0]
        launch.robot_warnings = robot_warnings(robot)
        launch.notes += robot_notes(robot)
        launch.simulator = SimulatorNode(
            context=context,
            scene=state.world.to_scene(),
            robot=sim_config_from_model(
                robot,
                controllers=_spawned_controllers(state),
                controllers_source=next(iter(state.param_sources.values()), "<parameters>"),
            ),
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
        launch.notes[:0] = state.world.notes
    launch.warnings = state.warnings
    return launch
