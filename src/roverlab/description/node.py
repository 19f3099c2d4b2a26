"""``robot_state_publisher`` and ``joint_state_publisher`` nodes.

Both take the robot from the ``robot_description`` keyword (URDF/xacro XML, a file path or
a :class:`RobotModel`) or, as ROS 2's nodes do, from their ``robot_description`` parameter
(e.g. set by a launch file from ``xacro``). The tree math is :class:`RobotModel`'s; these
classes only turn messages into joint positions and transforms into messages.

RobotStatePublisher (ROS names and semantics)
    * publishes the fixed (and planar) joints once on ``/tf_static`` (latched);
    * on every ``/joint_states`` message, publishes the movable joints it names (and the
      joints mimicking them) on ``/tf``, stamped with the message's stamp, at most
      ``publish_frequency`` times per second per joint (as ROS 1's JointStateListener);
      ``ignore_timestamp`` publishes every message, stamped now (as does a zero stamp);
    * prefixes frames with ``frame_prefix`` (ROS 2);
    * latches the URDF on ``/robot_description`` (std_msgs/String), as ROS 2 does.

JointStatePublisher
    publishes ``/joint_states`` for every movable joint at ``rate`` Hz: 0 (or the middle of
    the limits when they exclude 0), overridden by the latest values from the
    ``source_list`` topics; mimic joints follow their joint.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from roverlab.core import Context, Duration, Node, ParameterError, QoSProfile, Time
from roverlab.description.errors import DescriptionError
from roverlab.description.model import Joint, JointType, RobotModel
from roverlab.description.urdf import load_robot
from roverlab.geometry import Transform3
from roverlab.msgs import JointState, String
from roverlab.msgs import builders as build
from roverlab.msgs import classes as mc
from roverlab.tf import StaticTransformBroadcaster, TransformBroadcaster, transform_to_msg

__all__ = ["JointStatePublisher", "RobotStatePublisher"]

_LATCHED = QoSProfile(depth=1, durability="transient_local")

# parent frame, child frame, translation, origin rotation (x, y, z, w), axis
_Revolute = tuple[
    str,
    str,
    tuple[float, float, float],
    tuple[float, float, float, float],
    tuple[float, float, float],
]


def _robot(node: Node, robot_description: str | RobotModel | None) -> RobotModel:
    """The robot from the keyword, else from the ``robot_description`` parameter."""
    initial = robot_description.urdf if isinstance(robot_description, RobotModel) else ""
    param = node.declare_parameter("robot_description", initial)
    if isinstance(robot_description, RobotModel):
        return robot_description
    source = robot_description if robot_description is not None else str(param.value)
    if not source.strip():
        raise DescriptionError(
            f"{node.get_name()}: no robot description (pass robot_description= or set "
            f"the robot_description parameter)"
        )
    model = load_robot(source)
    param.value = model.urdf  # the expanded URDF, as a launch file's xacro command sets it
    return model


class RobotStatePublisher(Node):
    """Publishes the robot's link frames on ``/tf`` and ``/tf_static``.

    Args:
        context: the context the node joins.
        robot_description: URDF/xacro XML, a file path or a loaded :class:`RobotModel`;
            None reads the ``robot_description`` parameter.
        node_name: defaults to ``robot_state_publisher``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings`` of
            :class:`~roverlab.core.Node`.

    Parameters:
        publish_frequency (double, 20.0): most publications per second of a joint (Hz).
        ignore_timestamp (bool, False): publish every joint state, stamped now.
        frame_prefix (string, ""): prepended to every frame id.
        tf_prefix (string, ""): ROS 1's name: ``PREFIX/`` before every frame id (when
            ``frame_prefix`` is empty).

    Raises:
        DescriptionError: no description, or an invalid one.
        ParameterError: a negative ``publish_frequency``.
    """

    def __init__(
        self,
        context: Context,
        *,
        robot_description: str | RobotModel | None = None,
        node_name: str = "robot_state_publisher",
        **node_kwargs: Any,
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        self.model = _robot(self, robot_description)
        frequency = float(self.declare_parameter("publish_frequency", 20.0).value)
        if frequency < 0.0:
            raise ParameterError(f"{node_name}: publish_frequency must be >= 0, got {frequency}")
        self.publish_interval = (
            Duration.from_seconds(1.0 / frequency) if frequency > 0 else Duration(0)
        )
        self.ignore_timestamp = bool(self.declare_parameter("ignore_timestamp", False).value)
        self.frame_prefix = str(self.declare_parameter("frame_prefix", "").value)
        # ROS 1's tf_prefix (turtlebot3_remote.launch sets it, empty unless multi-robot):
        # tf::resolve puts "PREFIX/" before every frame
        tf_prefix = str(self.declare_parameter("tf_prefix", "").value).strip("/")
        if tf_prefix and not self.frame_prefix:
            self.frame_prefix = tf_prefix + "/"

        self._description_pub = self.create_publisher(String, "robot_description", _LATCHED)
        self._description_pub.publish(String(data=self.model.urdf))
        self._tf = TransformBroadcaster(self)
        self._tf_static = StaticTransformBroadcaster(self)
        self._movable = {j.name: j for j in self.model.movable_joints}
        self._mimics: dict[str, list[Joint]] = {}
        for j in self.model.movable_joints:
            if j.mimic is not None:
                self._mimics.setdefault(j.mimic.joint, []).append(j)
        self._positions: dict[str, float] = {}
        # revolute and continuous joints: frames, the translation and rotation of
        # ``origin * motion(q)`` that do not depend on q, and the axis
        self._revolute: dict[str, _Revolute] = {}
        for j in self.model.movable_joints:
            if j.type in (JointType.REVOLUTE, JointType.CONTINUOUS):
                t = j.origin * Transform3((0.0, 0.0, 0.0), j.origin.rotation)
                tx, ty, tz = (float(v) for v in t.translation)
                ax, ay, az, aw = (float(v) for v in j.origin.rotation)
                ux, uy, uz = (float(v) for v in j.axis)
                self._revolute[j.name] = (
                    self._frame(j.parent),
                    self._frame(j.child),
                    (tx, ty, tz),
                    (ax, ay, az, aw),
                    (ux, uy, uz),
                )
        self._last_published: dict[str, int] = {}
        self._plans: dict[tuple[str, ...], list[tuple[int, str, Joint, list[Joint]]]] = {}
        self._executor = context.executor
        self.publish_fixed_transforms()
        self.create_subscription(JointState, "joint_states", self._on_joint_states, 10)

    def _frame(self, link: str) -> str:
        return self.frame_prefix + link

    def _msg(self, joint: Joint, stamp: Time, position: float = 0.0) -> Any:
        return transform_to_msg(
            self._frame(joint.parent), self._frame(joint.child), stamp, joint.transform(position)
        )

    def _revolute_msg(self, spec: _Revolute, sec: int, nanosec: int, position: float) -> Any:
        """:meth:`_msg` of a revolute or continuous joint, the same numbers computed
        without the intermediate transforms (this runs for every joint state)."""
        parent, child, (tx, ty, tz), (ax, ay, az, aw), (ux, uy, uz) = spec
        half = position / 2.0
        s = math.sin(half)
        bx, by, bz, bw = ux * s, uy * s, uz * s, math.cos(half)
        return build.transform_stamped(
            sec,
            nanosec,
            parent,
            child,
            tx,
            ty,
            tz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        )

    def publish_fixed_transforms(self) -> None:
        """(Re)publish every fixed joint on ``/tf_static``, stamped now."""
        now = self.get_clock().now()
        msgs = [self._msg(j, now) for j in self.model.fixed_joints]
        if msgs:
            self._tf_static.send_transform(msgs)

    def _plan(self, names: tuple[str, ...]) -> list[tuple[int, str, Joint, list[Joint]]]:
        """For each name of a movable joint that mimics none: its index, the joint and
        its mimics."""
        plan = []
        for i, name in enumerate(names):
            joint = self._movable.get(name)
            if joint is not None and joint.mimic is None:
                plan.append((i, name, joint, self._mimics.get(name, [])))
        if len(self._plans) < 64:
            self._plans[names] = plan
        return plan

    def _on_joint_states(self, msg: mc.JointState) -> None:
        names = msg.name
        positions = msg.position
        if len(names) != len(positions):
            self.get_logger().warning(
                f"joint_states message has {len(names)} names but {len(positions)} positions; "
                "ignored"
            )
            return
        stamp = msg.header.stamp
        stamp_ns = stamp.sec * 1_000_000_000 + stamp.nanosec
        now_ns = self._executor.now_ns
        ignore = self.ignore_timestamp
        if ignore or stamp_ns == 0:
            stamp_ns = now_ns
        last_published = self._last_published
        if not ignore:
            # ROS 1 throttling: publish when the oldest of these joints was last published
            # at least one publish interval ago
            last_ns = now_ns
            for name in names:
                t = last_published.get(name, 0)
                if t < last_ns:
                    last_ns = t
            if stamp_ns < last_ns + self.publish_interval.nanoseconds:
                return
        if type(positions) is np.ndarray and positions.dtype.char == "d":
            values = positions.tolist()  # the usual case: float64 already
        else:
            values = np.asarray(positions, dtype=float).tolist()
        # the movable joints these names set, worked out once per list of names
        key = tuple(names)
        plan = self._plans.get(key)
        if plan is None:
            plan = self._plan(key)
        known = self._positions
        updated: dict[str, Joint] = {}
        for i, name, joint, mimics in plan:
            known[name] = values[i]
            updated[name] = joint
            for mimic in mimics:
                updated[mimic.name] = mimic
        for name in names:
            last_published[name] = stamp_ns
        # transforms are built only when someone reads /tf (here or in another process)
        if updated and self._tf.publisher.has_listeners:
            sec, nanosec = divmod(stamp_ns, 1_000_000_000)
            revolute = self._revolute
            position_of = self.model.joint_position
            msgs = []
            for j in updated.values():
                spec = revolute.get(j.name)
                q = position_of(j, known)
                msgs.append(
                    self._msg(j, Time(stamp_ns), q)
                    if spec is None
                    else self._revolute_msg(spec, sec, nanosec, q)
                )
            self._tf.publisher.publish(build.tf_message(msgs))


class JointStatePublisher(Node):
    """Publishes ``/joint_states`` for the robot's movable joints.

    Args:
        context: the context the node joins.
        robot_description: URDF/xacro XML, a file path or a loaded :class:`RobotModel`;
            None reads the ``robot_description`` parameter.
        node_name: defaults to ``joint_state_publisher``.
        **node_kwargs: ``namespace``, ``parameter_overrides``, ``remappings``.

    Parameters:
        rate (double, 10.0): publications per second.
        source_list (string array, []): JointState topics whose values override the
            defaults (e.g. a simulator's wheel joint states).
    """

    def __init__(
        self,
        context: Context,
        *,
        robot_description: str | RobotModel | None = None,
        node_name: str = "joint_state_publisher",
        **node_kwargs: Any,
    ) -> None:
        super().__init__(node_name, context=context, **node_kwargs)
        self.model = _robot(self, robot_description)
        rate = float(self.declare_parameter("rate", 10.0).value)
        if not rate > 0.0:
            raise ParameterError(f"{node_name}: rate must be > 0, got {rate}")
        sources = self.declare_parameter("source_list", None).value or []
        if not isinstance(sources, list | tuple) or not all(isinstance(s, str) for s in sources):
            raise ParameterError(f"{node_name}: source_list must be a list of topic names")
        self.joints: tuple[Joint, ...] = self.model.movable_joints
        self.source_positions: dict[str, float] = {}
        self._velocities: dict[str, float] = {}
        self._efforts: dict[str, float] = {}
        self._pub = self.create_publisher(JointState, "joint_states", 10)
        for topic in sources:
            self.create_subscription(JointState, topic, self._on_source, 10)
        self.create_timer(1.0 / rate, self.publish)

    @staticmethod
    def default_position(joint: Joint) -> float:
        """0, or the middle of the limits when they exclude 0 (as joint_state_publisher)."""
        limit = joint.limit
        if (
            joint.type in (JointType.REVOLUTE, JointType.PRISMATIC)
            and limit is not None
            and (limit.lower > 0.0 or limit.upper < 0.0)
        ):
            return (limit.lower + limit.upper) / 2.0
        return 0.0

    def _on_source(self, msg: mc.JointState) -> None:
        for field, store in (
            (msg.position, self.source_positions),
            (msg.velocity, self._velocities),
            (msg.effort, self._efforts),
        ):
            for name, value in zip(msg.name, field, strict=False):
                store[str(name)] = float(value)

    def positions(self) -> Mapping[str, float]:
        """The positions the next message will carry, by joint name."""
        free = {
            j.name: self.source_positions.get(j.name, self.default_position(j))
            for j in self.joints
            if j.mimic is None
        }
        return {j.name: self.model.joint_position(j, free) for j in self.joints}

    def publish(self) -> None:
        """Publish one JointState now (the timer calls this every 1/rate s)."""
        self._pub.publish(self.message())

    def message(self) -> mc.JointState:
        """The JointState :meth:`publish` sends now (stamped with the node's clock)."""
        positions = self.positions()
        names = [j.name for j in self.joints]
        sec, nsec = divmod(self.get_clock().now_ns(), 1_000_000_000)
        f64 = np.float64
        # the builder, not the factory: the same fields and dtypes without re-checking
        # numbers this node computed (the factory's lists become float64 arrays too)
        return build.joint_state(
            sec,
            nsec,
            "",
            names,
            np.array([positions[n] for n in names], dtype=f64),
            np.array(
                [self._velocities.get(n, 0.0) for n in names] if self._velocities else [], f64
            ),
            np.array([self._efforts.get(n, 0.0) for n in names] if self._efforts else [], f64),
        )
