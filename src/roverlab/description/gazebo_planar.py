"""``libgazebo_ros_planar_move.so``: the holonomic base plugin of omni-wheel and mecanum
robots (ROS 1 noetic's ``GazeboRosPlanarMove``), read into a :class:`PlanarMoveSpec`.

The plugin reads ``robotNamespace`` (``""``), ``commandTopic`` (``cmd_vel``),
``odometryTopic`` (``odom``), ``odometryFrame`` (``odom``), ``robotBaseFrame``
(``base_footprint``), ``odometryRate`` (20 Hz) and ``cmdTimeout`` (-1 s: off). It has no
switch for its ``odom -> robotBaseFrame`` transform; roverlab reads
``publishOdometryTf`` (default true) to turn it off.
"""

from __future__ import annotations

from roverlab.description.gazebo_specs import PlanarMoveSpec, resolve_frame, resolve_topic
from roverlab.description.gazebo_values import ElementValues

__all__ = ["parse_planar_move"]


def parse_planar_move(v: ElementValues) -> PlanarMoveSpec:
    """The plugin's parameters with its defaults for those left out.

    Topics resolve in ``robotNamespace``; frames get no namespace prefix (the plugin
    prefixes them with the ``tf_prefix`` parameter only, which roverlab does not model).

    Raises:
        URDFError: a value that is not a number or a boolean, or a negative
            ``odometryRate``.
    """
    ns = v.text("robotNamespace", "")
    return PlanarMoveSpec(
        command_topic=resolve_topic(ns, v.text("commandTopic", "cmd_vel")),
        odometry_topic=resolve_topic(ns, v.text("odometryTopic", "odom")),
        odometry_frame=resolve_frame("", v.text("odometryFrame", "odom")),
        robot_base_frame=resolve_frame("", v.text("robotBaseFrame", "base_footprint")),
        odometry_rate_hz=v.non_negative("odometryRate", 20.0),
        cmd_timeout_s=v.number("cmdTimeout", -1.0),
        publish_odometry_tf=v.flag("publishOdometryTf", True),
        robot_namespace=ns,
    )
