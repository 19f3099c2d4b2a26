"""roslaunch for roverlab: ``.launch`` XML files run with roverlab's nodes.

:func:`load_launch` reads a file into a :class:`LaunchSpec`; :func:`build_launch` creates
the nodes through :data:`REGISTRY` (ROS ``(pkg, type)`` -> roverlab node).
"""

from roverlab.launch.registry import REGISTRY, LaunchState, register
from roverlab.launch.runner import Launch, build_launch, find_launch_scripts
from roverlab.launch.xml import LaunchError, LaunchSpec, NodeSpec, load_launch

__all__ = [
    "REGISTRY",
    "Launch",
    "LaunchError",
    "LaunchSpec",
    "LaunchState",
    "NodeSpec",
    "build_launch",
    "find_launch_scripts",
    "load_launch",
    "register",
]
