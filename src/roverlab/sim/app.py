"""A whole simulation in one context: world, robot, simulator, robot_state_publisher.

What ``roslaunch gazebo_ros empty_world.launch world_name:=...`` plus ``spawn_model -urdf
-param robot_description -x -y -Y`` plus ``robot_state_publisher`` set up in ROS.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import yaml

from roverlab.core import Context
from roverlab.description import RobotModel, find_package, load_robot
from roverlab.description.node import JointStatePublisher, RobotStatePublisher
from roverlab.errors import RoverlabError, yaml_reason
from roverlab.sim.config import DiffDriveConfig
from roverlab.sim.node import SimulatorNode, SpawnPose
from roverlab.sim.robot import sim_config_from_model
from roverlab.world import World, load_world

__all__ = ["BUNDLED_ROBOTS", "Simulation", "SimulationError", "resolve_robot"]

# name -> (package, file inside the package): the robots of the seeds
BUNDLED_ROBOTS: dict[str, tuple[str, str]] = {
    "mbot": ("mbot_description", "urdf/mbot_with_laser_gazebo.xacro"),
    "mybot": ("bingda_tutorials", "urdf/mybot.xacro"),
    "mycar": ("mycar", "urdf/xacro/car.urdf.xacro"),
    "jackal": ("jackal_description", "urdf/jackal.urdf.xacro"),
}
# name -> (package, file): the ros_control controllers' YAML a bundled robot loads (what
# its control.launch puts on the parameter server)
BUNDLED_CONTROLLERS: dict[str, tuple[str, str]] = {
    "jackal": ("jackal_control", "config/control.yaml"),
}


class SimulationError(RoverlabError):
    """A simulation could not be set up (bad robot, world or option)."""


def resolve_robot(name_or_path: str) -> Path:
    """A bundled robot name (mbot, mybot, mycar) or a URDF/xacro file path."""
    if name_or_path in BUNDLED_ROBOTS:
        pkg, rel = BUNDLED_ROBOTS[name_or_path]
        return find_package(pkg) / rel
    path = Path(name_or_path)
    if not path.is_file():
        raise SimulationError(
            f"unknown robot {name_or_path!r}: not a file, and bundled robots are "
            f"{', '.join(sorted(BUNDLED_ROBOTS))}"
        )
    return path


def _controllers_yaml(path: Path) -> Any:
    try:
        return yaml.safe_load(path.read_text())
    except OSError as err:
        raise SimulationError(f"{path}: cannot read: {err.strerror}") from err
    except yaml.YAMLError as err:
        raise SimulationError(f"{path}: {yaml_reason(err)}") from err


@dataclass
class Simulation:
    """The nodes of one simulated robot in one world, in ``context``.

    Args:
        context: where the nodes run (its clock mode decides the pacing).
        world: a bundled world name, a world file or a loaded :class:`World`.
        robot: a bundled robot name, a URDF/xacro file or a loaded :class:`RobotModel`.
        spawn: the robot's start pose in the world.
        seed: seed of every random draw.
        robot_args: xacro arguments (``name:=value`` on the command line).
        cameras: simulate the robot's cameras and depth cameras (rendering is by far
            the most expensive sensor; switch it off for fast batch runs).
        parameters: parameters of the ``gazebo`` node (``physics_rate``, ``wheel_slip``,
            ``ground_truth_rate``, ...), as ``<param>`` lines in a launch file.
        controllers: a ros_control controllers' YAML file for a robot with
            ``libgazebo_ros_control.so`` (default: the bundled robot's own, e.g.
            jackal_control's ``control.yaml``).
    """

    context: Context
    world: str | Path | World = "maze"
    robot: str | Path | RobotModel = "mybot"
    spawn: SpawnPose = field(default_factory=SpawnPose)
    seed: int = 0
    robot_args: dict[str, str] = field(default_factory=dict)
    cameras: bool = True
    parameters: dict[str, Any] = field(default_factory=dict)
    controllers: Path | None = None

    def __post_init__(self) -> None:
        for v in (self.spawn.x, self.spawn.y, self.spawn.yaw):
            if not math.isfinite(v):
                raise SimulationError(f"spawn pose must be finite, got {self.spawn}")
        self.world_model = self.world if isinstance(self.world, World) else load_world(self.world)
        if isinstance(self.robot, RobotModel):
            self.robot_model = self.robot
        else:
            path = resolve_robot(str(self.robot))
            self.robot_model = load_robot(path, args=self.robot_args)
        control = self.controllers
        if control is None and str(self.robot) in BUNDLED_CONTROLLERS:
            pkg, rel = BUNDLED_CONTROLLERS[str(self.robot)]
            control = find_package(pkg) / rel
        tree = _controllers_yaml(Path(control)) if control is not None else None
        self.config = sim_config_from_model(
            self.robot_model, controllers=tree, controllers_source=str(control)
        )
        if not self.cameras:
            self.config = replace(self.config, cameras=(), depth_cameras=())
        self.scene = self.world_model.to_scene()
        self.simulator = SimulatorNode(
            context=self.context,
            scene=self.scene,
            robot=self.config,
            spawn=self.spawn,
            seed=self.seed,
            parameter_overrides=self.parameters,
        )
        self.state_publisher = RobotStatePublisher(
            context=self.context, robot_description=self.robot_model
        )
        drive = self.config.drive
        wheel_states = isinstance(drive, DiffDriveConfig) and drive.publish_wheel_joint_state
        self.joint_state_publisher = (
            None
            if wheel_states or not self.robot_model.movable_joints
            else JointStatePublisher(context=self.context, robot_description=self.robot_model)
        )
