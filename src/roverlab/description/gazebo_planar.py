"""``libgazebo_ros_planar_move.so``: the holonomic base plugin of omni-wheel and mecanum
robots (ROS 1 noetic's ``GazeboRosPlanarMove``), read into a :class:`PlanarMoveSpec`; and
``libgazebo_ros_control.so`` (ros_control in Gazebo), read into a :class:`RosControlSpec`.

The plugin reads ``robotNamespace`` (``""``), ``commandTopic`` (``cmd_vel``),
``odometryTopic`` (``odom``), ``odometryFrame`` (``odom``), ``robotBaseFrame``
(``base_footprint``), ``odometryRate`` (20 Hz) and ``cmdTimeout`` (-1 s: off). It has no
switch for its ``odom -> robotBaseFrame`` transform; roverlab reads
``publishOdometryTf`` (default true) to turn it off.
"""

from __future__ import annotations

from roverlab.description.gazebo_specs import (
    PlanarMoveSpec,
    RosControlSpec,
    resolve_frame,
    resolve_topic,
)
from roverlab.description.gazebo_values import ElementValues

__all__ = ["parse_planar_move", "parse_ros_control"]


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


def parse_ros_control(v: ElementValues) -> RosControlSpec:
    """``libgazebo_ros_control.so``'s ``robotNamespace`` (default: the model's name, as
    the plugin), ``controlPeriod`` (s; default every physics step) and ``robotSimType``.

    Raises:
        URDFError: a negative or non-numeric ``controlPeriod``.
    """
    ns = v.text("robotNamespace", v.model_name) or "/"
    return RosControlSpec(
        robot_namespace=ns if ns.startswith("/") else "/" + ns,
        control_period_s=v.non_negative("controlPeriod", 0.0),
        robot_sim_type=v.text("robotSimType", "gazebo_ros_control/DefaultRobotHWSim"),
    )
