"""ROS ``(pkg, type)`` -> roverlab node factories: what a ``<node>`` line starts.

Plugins from other packages register through the ``roverlab.nodes`` entry-point group
(``"pkg/type" = "module:factory"``); a duplicate registration is an error.
"""

from __future__ import annotations

import dataclasses
import math
import shlex
from collections.abc import Callable
from functools import partial
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any

from roverlab.core import Context, Node, QoSProfile
from roverlab.description import load_robot
from roverlab.description.node import JointStatePublisher, RobotStatePublisher
from roverlab.geometry import quat_from_rpy
from roverlab.launch.devices import DEVICE_NODES
from roverlab.launch.state import (
    LaunchState,
    NodeFactory,
    build_node,
    node_factory,
    node_kwargs,
)
from roverlab.launch.xml import LaunchError, NodeSpec
from roverlab.maps.node import MapSaver, MapServer
from roverlab.msgs import classes as mc
from roverlab.perception.image_transport.node import Republish
from roverlab.viz.errors import DashboardError
from roverlab.viz.joints import SLIDER_TOPIC
from roverlab.viz.launcher import start_image_view, start_rviz
from roverlab.world import BUNDLED_WORLDS, load_world

__all__ = ["REGISTRY", "ROS_NODE_NAMES", "LaunchState", "NodeFactory", "register", "rosrun_name"]


REGISTRY: dict[tuple[str, str], NodeFactory] = {}

#: The name a ROS 1 node gives itself (``ros::init`` / ``rospy.init_node`` in its source)
#: where it is not its executable's: ``rosrun PKG TYPE`` without ``__name:=`` runs it under
#: that name (``rosrun usb_cam usb_cam_node`` is ``/usb_cam``, its topics
#: ``/usb_cam/image_raw``). A launch file's ``<node name=...>`` always wins.
ROS_NODE_NAMES: dict[tuple[str, str], str] = {
    ("usb_cam", "usb_cam_node"): "usb_cam",
    ("rplidar_ros", "rplidarNode"): "rplidar_node",
    ("arbotix_python", "arbotix_driver"): "arbotix",
    ("ros_arduino_python", "arduino_node.py"): "arduino",
    ("hector_mapping", "hector_mapping"): "hector_slam",
    ("move_base", "move_base"): "move_base_node",
    ("costmap_2d", "costmap_2d_node"): "costmap_node",
    ("robot_state_publisher", "state_publisher"): "robot_state_publisher",
    ("gazebo_ros", "gzserver"): "gazebo",
}


def rosrun_name(pkg: str, type_: str) -> str:
    """The node name ``rosrun PKG TYPE`` gives (see :data:`ROS_NODE_NAMES`)."""
    return ROS_NODE_NAMES.get((pkg, type_), Path(type_).stem)


def register(pkg: str, type_: str) -> Callable[[NodeFactory], NodeFactory]:
    def deco(fn: NodeFactory) -> NodeFactory:
        key = (pkg, type_)
        if key in REGISTRY:
            raise LaunchError(f"node {pkg}/{type_} is registered twice")
        REGISTRY[key] = fn
        return fn

    return deco


def load_plugins() -> None:
    """Register the nodes other packages declare in the ``roverlab.nodes`` entry points."""
    for ep in entry_points(group="roverlab.nodes"):
        pkg, _, type_ = ep.name.partition("/")
        register(pkg, type_)(ep.load())


def _description(state: LaunchState, spec: NodeSpec) -> str | None:
    if "robot_description" in spec.params:
        return str(spec.params.pop("robot_description"))
    glob = spec.namespace.rstrip("/") + "/robot_description"
    return str(state.params[glob]) if glob in state.params else None


class DescriptionWaiter(Node):
    """Starts a node once ``/robot_description`` arrives, for launch files that rely on a
    parameter set by another launch (ROS 1's global parameter server): in roverlab the
    description travels on the latched ``/robot_description`` topic, as in ROS 2.

    It waits under the node's own name (``node list`` shows ``/robot_state_publisher``, as
    ROS does while that node waits for its parameter) and hands the name over to the node
    it starts."""

    def __init__(self, state: LaunchState, spec: NodeSpec, make: Callable[[str], Node]) -> None:
        super().__init__(spec.name, context=state.context, namespace=spec.namespace)
        self.started: Node | None = None
        self._handing_over = False
        self._make = make
        self.get_logger().info(f"{spec.name}: waiting for /robot_description")
        self.create_subscription(
            mc.String,
            "/robot_description",
            self._on_description,
            QoSProfile(depth=1, durability="transient_local"),
        )

    def _on_description(self, msg: Any) -> None:
        if self.started is None and not self._handing_over:
            self._handing_over = True
            text = str(msg.data)
            self.context.executor.call_soon(lambda: self._hand_over(text))

    def _hand_over(self, text: str) -> None:
        self.destroy_node()  # frees the name for the node it stands for
        self.started = self._make(text)


def _with_description(make: Callable[[LaunchState, NodeSpec, str], Node]) -> NodeFactory:
    def factory(state: LaunchState, spec: NodeSpec) -> Node:
        urdf = _description(state, spec)
        if urdf is None:
            return DescriptionWaiter(state, spec, lambda text: make(state, spec, text))
        return make(state, spec, urdf)

    return factory


def _make_rsp(state: LaunchState, spec: NodeSpec, urdf: str) -> Node:
    return RobotStatePublisher(
        state.context, robot_description=urdf, node_name=spec.name, **node_kwargs(spec)
    )


def _make_jsp(state: LaunchState, spec: NodeSpec, urdf: str) -> Node:
    return JointStatePublisher(
        state.context, robot_description=urdf, node_name=spec.name, **node_kwargs(spec)
    )


for _key in (
    ("robot_state_publisher", "robot_state_publisher"),
    ("robot_state_publisher", "state_publisher"),
):
    REGISTRY[_key] = _with_description(_make_rsp)


def _make_jsp_gui(state: LaunchState, spec: NodeSpec, urdf: str) -> Node:
    """joint_state_publisher_gui: joint_state_publisher that also follows the dashboard's
    Joints sliders (their topic is added to its ``source_list``)."""
    sources = list(spec.params.get("source_list") or [])
    if SLIDER_TOPIC not in sources:
        sources.append(SLIDER_TOPIC)
    kwargs = {**node_kwargs(spec), "parameter_overrides": {**spec.params, "source_list": sources}}
    return JointStatePublisher(state.context, robot_description=urdf, node_name=spec.name, **kwargs)


REGISTRY[("joint_state_publisher", "joint_state_publisher")] = _with_description(_make_jsp)
REGISTRY[("joint_state_publisher_gui", "joint_state_publisher_gui")] = _with_description(
    _make_jsp_gui
)


class StaticTransformPublisher(Node):
    """tf2_ros static_transform_publisher: ``x y z yaw pitch roll frame child`` or
    ``x y z qx qy qz qw frame child`` (ROS 1 order), latched on ``/tf_static``."""

    def __init__(
        self, context: Context, *, args: str, source: str, pkg: str = "tf2_ros", **kwargs: Any
    ) -> None:
        super().__init__(
            kwargs.pop("node_name", "static_transform_publisher"), context=context, **kwargs
        )
        parts = shlex.split(args)
        if pkg == "tf":  # ROS 1 tf: a trailing period in ms (republished; latched here)
            if len(parts) not in (9, 10):
                raise LaunchError(
                    f"{source}: tf/static_transform_publisher needs 'x y z yaw pitch roll "
                    f"frame child period_in_ms' or 'x y z qx qy qz qw frame child "
                    f"period_in_ms', got {args!r}"
                )
            try:
                period = float(parts[-1])
            except ValueError:
                period = float("nan")
            if not period > 0:
                raise LaunchError(
                    f"{source}: tf/static_transform_publisher: period_in_ms {parts[-1]!r} "
                    "must be a positive number"
                )
            parts = parts[:-1]
        if len(parts) not in (8, 9):
            raise LaunchError(
                f"{source}: static_transform_publisher needs 'x y z yaw pitch roll frame child' "
                f"or 'x y z qx qy qz qw frame child', got {args!r}"
            )
        try:
            nums = [float(v) for v in parts[:-2]]
        except ValueError as err:
            raise LaunchError(f"{source}: static_transform_publisher: {err}") from err
        if not all(math.isfinite(v) for v in nums):
            raise LaunchError(f"{source}: static_transform_publisher: values must be finite")
        parent, child = parts[-2].lstrip("/"), parts[-1].lstrip("/")
        x, y, z = nums[:3]
        if len(nums) == 6:
            yaw, pitch, roll = nums[3:]
            q = [float(v) for v in quat_from_rpy(roll, pitch, yaw)]
        else:
            q = nums[3:]
        pub = self.create_publisher(
            mc.TFMessage, "/tf_static", QoSProfile(depth=1, durability="transient_local")
        )
        stamp = self.get_clock().now().to_msg()
        pub.publish(
            mc.TFMessage(
                [
                    mc.TransformStamped(
                        mc.Header(stamp, parent),
                        child,
                        mc.Transform(
                            mc.Vector3(x, y, z),
                            mc.Quaternion(float(q[0]), float(q[1]), float(q[2]), float(q[3])),
                        ),
                    )
                ]
            )
        )


def _static_tf(state: LaunchState, spec: NodeSpec) -> Node:
    return StaticTransformPublisher(
        state.context,
        args=spec.args,
        source=spec.source,
        pkg=spec.pkg,
        node_name=spec.name,
        **node_kwargs(spec),
    )


REGISTRY[("tf2_ros", "static_transform_publisher")] = _static_tf
REGISTRY[("tf", "static_transform_publisher")] = _static_tf


@register("gazebo_ros", "gzserver")
def _gzserver(state: LaunchState, spec: NodeSpec) -> None:
    world = shlex.split(spec.args)[-1] if spec.args.strip() else "empty"
    # Gazebo's own worlds ("worlds/empty.world") resolve to roverlab's bundled ones
    if not Path(world).is_file() and Path(world).stem in BUNDLED_WORLDS:
        world = Path(world).stem
    state.world = load_world(world)
    state.world_source = spec.source
    return None


@register("gazebo_ros", "spawn_model")
def _spawn(state: LaunchState, spec: NodeSpec) -> None:
    argv = shlex.split(spec.args)
    opts: dict[str, str] = {}
    flags: set[str] = set()
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-urdf", "-sdf", "-gazebo", "-unpause", "-wait"):
            flags.add(a)
            i += 1
        elif a.startswith("-") and i + 1 < len(argv):
            opts[a] = argv[i + 1]
            i += 2
        else:
            raise LaunchError(f"{spec.source}: spawn_model: unexpected argument {a!r}")
    if "-sdf" in flags:
        raise LaunchError(f"{spec.source}: spawn_model -sdf is not supported; use -urdf")
    if "-param" in opts:
        key = opts["-param"]
        full = key if key.startswith("/") else spec.namespace.rstrip("/") + "/" + key
        if full not in state.params:
            raise LaunchError(f"{spec.source}: spawn_model: parameter {full} is not set")
        state.spawn_urdf = str(state.params[full])
        # its messages name the file the parameter was read from, not <string>
        where = state.param_sources.get(full, f"{spec.source}: parameter {full}")
        robot = load_robot(state.spawn_urdf, source=where)
    elif "-file" in opts:
        robot = load_robot(Path(opts["-file"]))
        state.spawn_urdf = robot.urdf
    else:
        raise LaunchError(f"{spec.source}: spawn_model needs -param NAME or -file PATH")
    try:
        pose = (float(opts.get("-x", 0)), float(opts.get("-y", 0)), float(opts.get("-Y", 0)))
    except ValueError as err:
        raise LaunchError(f"{spec.source}: spawn_model: {err}") from err
    state.spawns.append((robot, pose, spec.source))
    return None


@register("controller_manager", "spawner")
def _spawner(state: LaunchState, spec: NodeSpec) -> None:
    """controller_manager's spawner: the controllers it names run in the simulator (a
    diff_drive_controller of a robot with libgazebo_ros_control.so drives it); options
    (``--shutdown-timeout 3``, ``--namespace=ns``...) are accepted."""
    argv = shlex.split(spec.args)
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("--shutdown-timeout", "--timeout", "--namespace", "--controller-manager"):
            i += 2
            continue
        if not a.startswith("-"):
            state.controllers.append((spec.namespace, a))
        i += 1
    return None


@register("map_server", "map_server")
def _map_server(state: LaunchState, spec: NodeSpec) -> Node:
    argv = shlex.split(spec.args)
    if len(argv) != 1:
        raise LaunchError(f"{spec.source}: map_server takes one argument, the map's YAML file")
    return MapServer(state.context, yaml_path=argv[0], node_name=spec.name, **node_kwargs(spec))


@register("map_server", "map_saver")
def _map_saver(state: LaunchState, spec: NodeSpec) -> Node:
    argv = shlex.split(spec.args)
    prefix = "map"
    if "-f" in argv:
        i = argv.index("-f")
        if i + 1 >= len(argv):
            raise LaunchError(f"{spec.source}: map_saver -f needs a file name")
        prefix = argv[i + 1]
    return MapSaver(state.context, path_prefix=prefix, node_name=spec.name, **node_kwargs(spec))


# The algorithm nodes, imported when a launch first starts one.
_NODES = {
    ("gmapping", "slam_gmapping"): "roverlab.slam.gmapping.node:SlamGMapping",
    ("hector_mapping", "hector_mapping"): "roverlab.slam.hector.node:HectorMapping",
    ("slam_toolbox", "async_slam_toolbox_node"): "roverlab.slam.graph.node:SlamToolbox",
    ("slam_toolbox", "sync_slam_toolbox_node"): "roverlab.slam.graph.node:SyncSlamToolbox",
    ("slam_karto", "slam_karto"): "roverlab.slam.graph.node:SlamKarto",
    ("costmap_2d", "costmap_2d_node"): "roverlab.navigation.costmap.node:Costmap2DNode",
    ("amcl", "amcl"): "roverlab.localization.amcl.node:AmclNode",
    ("fake_localization", "fake_localization"): (
        "roverlab.localization.fake_localization:FakeLocalization"
    ),
    ("move_base", "move_base"): "roverlab.navigation.move_base.node:MoveBase",
    ("explore_lite", "explore"): "roverlab.navigation.explore.node:Explore",
}
for _key, _path in _NODES.items():
    REGISTRY[_key] = node_factory(_path)


@register("image_transport", "republish")
def _republish(state: LaunchState, spec: NodeSpec) -> Node:
    """``republish IN_TRANSPORT [in:=IN] [OUT_TRANSPORT] [out:=OUT]`` (``in``/``out`` also
    as ``<remap>``)."""
    argv = shlex.split(spec.args)
    transports = [a for a in argv if ":=" not in a]
    if not 1 <= len(transports) <= 2:
        raise LaunchError(f"{spec.source}: republish takes IN_TRANSPORT [OUT_TRANSPORT]")
    remaps = dict(a.split(":=", 1) for a in argv if ":=" in a)
    spec = dataclasses.replace(spec, remaps={**spec.remaps, **remaps})
    out = transports[1] if len(transports) > 1 else None
    make = partial(Republish, in_transport=transports[0], out_transport=out)
    return build_node(state, spec, make)


def _unavailable(reason: str) -> NodeFactory:
    def factory(state: LaunchState, spec: NodeSpec) -> None:
        state.warnings.append(f"{spec.source}: {spec.pkg}/{spec.type} not started: {reason}")
        return None

    return factory


@register("rviz", "rviz")
def _rviz(state: LaunchState, spec: NodeSpec) -> Node | None:
    """The web dashboard on the launch's context (``-d FILE.rviz``, ``-f FRAME``)."""
    try:
        return start_rviz(
            state.context,
            spec.args,
            node_name=spec.name,
            source=spec.source,
            warn=state.warnings.append,
        )
    except DashboardError as err:
        raise LaunchError(f"{spec.source}: rviz: {err}") from err


_NO_JOYSTICK = (
    "no joystick here: roverlab reads no /dev/input devices; drive with `roverlab teleop` "
    "(the keyboard, as teleop_twist_keyboard) or publish /cmd_vel"
)
for _key in (
    ("joy", "joy_node"),
    ("joy", "joy"),
    ("teleop_twist_joy", "teleop_node"),
    ("teleop_twist_joy", "teleop_twist_joy"),
    ("turtlebot_teleop", "turtlebot_teleop_joy"),
):
    REGISTRY[_key] = _unavailable(_NO_JOYSTICK)


@register("rqt_image_view", "rqt_image_view")
def _rqt_image_view(state: LaunchState, spec: NodeSpec) -> Node | None:
    """The dashboard's image panel (``args`` or ``<remap from="image">`` names the topic)."""
    try:
        return start_image_view(
            state.context,
            spec.args,
            remaps=spec.remaps,
            node_name=spec.name,
            source=spec.source,
            warn=state.warnings.append,
        )
    except DashboardError as err:
        raise LaunchError(f"{spec.source}: rqt_image_view: {err}") from err


for _t in ("teleop_twist_keyboard.py", "teleop_twist_keyboard"):
    REGISTRY[("teleop_twist_keyboard", _t)] = _unavailable(
        "it needs a terminal: run `roverlab teleop` in one"
    )

for _key, _factory in DEVICE_NODES.items():
    if _key in REGISTRY:
        raise LaunchError(f"node {_key[0]}/{_key[1]} is registered twice")
    REGISTRY[_key] = _factory
