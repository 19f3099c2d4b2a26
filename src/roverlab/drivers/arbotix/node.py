"""The ``arbotix`` node (``arbotix_python/arbotix_driver``) with ``sim: true``.

Parameters (private, arbotix's names): ``sim`` (bool, False: only ``true`` runs here,
see below), ``rate`` (Hz, 100: the driver loop that updates the controllers), ``port``,
``baud``, ``timeout``, ``read_rate``, ``write_rate`` (accepted: they configure the serial
link of a real board), and ``controllers/NAME/...`` for each controller
(:mod:`roverlab.drivers.arbotix.diff_controller`), usually loaded from a YAML file with
``<rosparam file="control.yaml" command="load"/>`` inside the ``<node>``.

Each ``diff_controller`` subscribes to ``cmd_vel`` (geometry_msgs/Twist) and publishes
``odom`` (nav_msgs/Odometry) and the ``odom_frame_id -> base_frame_id`` transform on
``/tf`` at its ``rate``. A NaN or infinite command is logged and ignored.
"""

from __future__ import annotations

from typing import Any

from roverlab.core import Context, Node, ParameterError
from roverlab.drivers.arbotix.diff_controller import (
    DIFF_CONTROLLER_KEYS,
    DiffController,
    parse_controllers,
)
from roverlab.drivers.errors import DriverError
from roverlab.drivers.odometry import odometry_messages
from roverlab.msgs import classes as mc
from roverlab.tf import TransformBroadcaster

__all__ = ["ArbotixDriver"]

_DRIVER_PARAMS = (
    ("port", "/dev/ttyUSB0"),
    ("baud", 115200),
    ("timeout", 0.1),
    ("read_rate", 10.0),
    ("write_rate", 10.0),
)


class ArbotixDriver(Node):
    """arbotix_driver with ``sim: true``: its diff controllers on a fake base.

    Args:
        context: the context the node joins.
        node_name: defaults to ``arbotix``.
        **node_kwargs: ``namespace``, ``parameter_overrides`` (where the
            ``controllers/...`` keys come from), ``remappings``.

    Raises:
        DriverError: ``sim`` is false (a real ArbotiX board is not driven by roverlab),
            or a controller's parameters are invalid.
        ParameterError: a non-positive ``rate``.
    """

    def __init__(self, context: Context, *, node_name: str = "arbotix", **node_kwargs: Any):
        overrides = dict(node_kwargs.get("parameter_overrides") or {})
        super().__init__(node_name, context=context, **node_kwargs)
        sim = bool(self.declare_parameter("sim", False).value)
        rate = float(self.declare_parameter("rate", 100.0).value)
        for name, default in _DRIVER_PARAMS:
            self.declare_parameter(name, default)
        if not sim:
            raise DriverError(
                f"{node_name}: only sim: true is supported (a fake base); a real ArbotiX "
                "board's serial protocol is not implemented: drive a DIY base with "
                "ros_arduino_python/arduino_node.py"
            )
        if not rate > 0:
            raise ParameterError(f"{node_name}: rate must be > 0, got {rate}")
        controller_params = {k: v for k, v in overrides.items() if k.startswith("controllers/")}
        diffs, notes = parse_controllers(controller_params)
        for key, value in controller_params.items():
            if key.rsplit("/", 1)[-1] in DIFF_CONTROLLER_KEYS or key.endswith("/type"):
                self.declare_parameter(key, value)
        for note in notes:
            self.get_logger().warning(f"{note}: only diff_controller is")
        if not diffs:
            self.get_logger().warning("no diff_controller in ~controllers: nothing to drive")
        now = self._now_s()
        self.controllers = [DiffController(p, now_s=now) for p in diffs]
        self._tf = TransformBroadcaster(self)
        self._odom_pubs = [self.create_publisher(mc.Odometry, "odom", 5) for _ in diffs]
        if self.controllers:
            self.create_subscription(mc.Twist, "cmd_vel", self._on_cmd_vel, 10)
        for c in self.controllers:
            self.get_logger().info(
                f"Started DiffController ({c.params.name}). Geometry: {c.params.base_width}m "
                f"wide, {c.params.ticks_meter} ticks/m."
            )
        self.create_timer(1.0 / rate, self._loop)

    def _now_s(self) -> float:
        return self.get_clock().now_ns() / 1e9

    def _on_cmd_vel(self, msg: mc.Twist) -> None:
        now = self._now_s()
        for c in self.controllers:
            try:
                c.command(float(msg.linear.x), float(msg.angular.z), now_s=now)
            except DriverError as err:
                self.get_logger().warning(f"{c.params.name}: {err}; ignored")

    def _loop(self) -> None:
        now_ns = self.get_clock().now_ns()
        now = now_ns / 1e9
        for c, pub in zip(self.controllers, self._odom_pubs, strict=True):
            if not c.due(now):
                continue
            state = c.update(now)
            odom, tf = odometry_messages(
                state,
                stamp_ns=now_ns,
                odom_frame=c.params.odom_frame_id,
                base_frame=c.params.base_frame_id,
            )
            self._tf.send_transform(tf)
            pub.publish(odom)
