"""Robot descriptions: ROS package lookup, xacro, URDF + ``<gazebo>`` -> a typed model.

The pieces, bottom up:

* :mod:`.packages`: ``$(find pkg)`` / ``package://`` through ``ROVERLAB_PACKAGE_PATH``,
  ``ROS_PACKAGE_PATH`` and the robots bundled in :mod:`roverlab.packages`;
* :mod:`.xacro_hook`: the ``xacro`` package with ``$(find)`` hooked to that path;
* :mod:`.model` and :mod:`.gazebo`: frozen dataclasses for links, joints, sensors and
  plugins, and the tree math (root, chains, link poses for joint positions);
* :mod:`.urdf`: :func:`load_robot` / :func:`robot_description`, with check_urdf's checks;
* :mod:`.check`: check_urdf's report (:func:`format_check`), :mod:`.cli`: ``roverlab urdf``;
* :mod:`.node`: ``robot_state_publisher`` and ``joint_state_publisher`` (import it from
  there: it is the only module of this package that uses the node runtime).

Example::

    from roverlab.description import load_robot, format_check

    robot = load_robot("mybot.xacro", args={"laser_visual": "true"})
    print(format_check(robot))
    robot.gazebo.diff_drive.wheel_separation_m        # 0.18
    robot.link_transform("base_laser_link").translation

Every error is a :class:`DescriptionError` with a one-line message naming the file and the
element or macro at fault.
"""

from __future__ import annotations

from roverlab.description.check import format_check, format_tree
from roverlab.description.errors import (
    DescriptionError,
    PackageNotFoundError,
    URDFError,
    XacroError,
)
from roverlab.description.gazebo import PLUGIN_SPECS
from roverlab.description.gazebo_specs import (
    GAZEBO_MATERIALS,
    SENSOR_TYPES,
    CameraPluginSpec,
    CameraSpec,
    DiffDriveSpec,
    GazeboExtensions,
    GazeboPlugin,
    GazeboReference,
    GazeboSensor,
    ImuPluginSpec,
    ImuSpec,
    KinectPluginSpec,
    LaserPluginSpec,
    NoiseSpec,
    PlanarMoveSpec,
    PluginSpec,
    RaySpec,
    RosControlSpec,
    ScanAxis,
    gazebo_material_rgba,
    resolve_frame,
    resolve_topic,
)
from roverlab.description.model import (
    MOVABLE_JOINT_TYPES,
    Box,
    Collision,
    Cylinder,
    Geometry,
    Inertial,
    Joint,
    JointDynamics,
    JointLimit,
    JointMimic,
    JointSafety,
    JointType,
    Link,
    Material,
    Mesh,
    RobotModel,
    Sphere,
    Visual,
)
from roverlab.description.packages import (
    PackagePath,
    find_package,
    package_search_path,
    resolve_uri,
)
from roverlab.description.urdf import load_robot, parse_urdf, robot_description
from roverlab.description.xacro_hook import (
    XACRO_HOOK,
    XACRO_PINNED_VERSION,
    check_xacro_hook,
    xacro_file,
    xacro_string,
)

__all__ = [
    "GAZEBO_MATERIALS",
    "MOVABLE_JOINT_TYPES",
    "PLUGIN_SPECS",
    "SENSOR_TYPES",
    "XACRO_HOOK",
    "XACRO_PINNED_VERSION",
    "Box",
    "CameraPluginSpec",
    "CameraSpec",
    "Collision",
    "Cylinder",
    "DescriptionError",
    "DiffDriveSpec",
    "GazeboExtensions",
    "GazeboPlugin",
    "GazeboReference",
    "GazeboSensor",
    "Geometry",
    "ImuPluginSpec",
    "ImuSpec",
    "Inertial",
    "Joint",
    "JointDynamics",
    "JointLimit",
    "JointMimic",
    "JointSafety",
    "JointType",
    "KinectPluginSpec",
    "LaserPluginSpec",
    "Link",
    "Material",
    "Mesh",
    "NoiseSpec",
    "PackageNotFoundError",
    "PackagePath",
    "PlanarMoveSpec",
    "PluginSpec",
    "RaySpec",
    "RobotModel",
    "RosControlSpec",
    "ScanAxis",
    "Sphere",
    "URDFError",
    "Visual",
    "XacroError",
    "check_xacro_hook",
    "find_package",
    "format_check",
    "format_tree",
    "gazebo_material_rgba",
    "load_robot",
    "package_search_path",
    "parse_urdf",
    "resolve_frame",
    "resolve_topic",
    "resolve_uri",
    "robot_description",
    "xacro_file",
    "xacro_string",
]
