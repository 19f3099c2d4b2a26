"""The teleop nodes: keys in, ``geometry_msgs/Twist`` on ``cmd_vel`` out.

:class:`TeleopTwistKeyboardNode` is ROS 1's ``teleop_twist_keyboard`` (package and node
``teleop_twist_keyboard``); :class:`MbotTeleopNode` is the ``mbot_teleop.py`` ramping variant
(node ``mbot_teleop``). Both publish on the relative topic ``cmd_vel`` (remappable;
``/cmd_vel`` in the root namespace) and read their parameters once, at start:

============== ======== =========================================================
parameter      default  meaning
============== ======== =========================================================
speed          0.3      linear speed of a movement key, m/s (mbot_teleop: 0.2)
turn           0.5      angular speed of a movement key, rad/s (mbot_teleop: 1.0)
scale_linear   = speed  mbot_teleop only: its launch file's name for ``speed``
scale_angular  = turn   mbot_teleop only: its launch file's name for ``turn``
repeat_rate    0.0      re-publish the last Twist at this rate (Hz) after the
                        first key; 0 publishes on key events only, as ROS 1 does
============== ======== =========================================================

``mbot_teleop.launch`` sets ``scale_linear`` / ``scale_angular``, which the original script
ignores (it hard-codes 0.2 and 1); here they are the maximum speeds the ramp aims for, and
take precedence over ``speed`` / ``turn`` when both are given. Every value must be a finite
number >= 0, so NaN or inf can never reach ``cmd_vel``.

:meth:`TeleopNode.run` is the scripts' main loop over any :class:`KeySource` (a
:class:`~roverlab.teleop.terminal.RawTerminal`, or a list of keys in tests); however it ends
it publishes a zero Twist, as the scripts' ``finally:`` does.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Final, Protocol

from roverlab.core import Context, Node, ParameterDescriptor, Publisher, Timer
from roverlab.core.errors import ParameterError
from roverlab.msgs import Twist
from roverlab.teleop.errors import TeleopError
from roverlab.teleop.keyboard import (
    STOP,
    KeyResult,
    SmoothTeleop,
    TeleopLogic,
    TeleopTwistKeyboard,
    TwistCommand,
    check_speed,
)

__all__ = [
    "CMD_VEL_TOPIC",
    "KeySource",
    "MbotTeleopNode",
    "TeleopNode",
    "TeleopTwistKeyboardNode",
    "command_to_twist",
]

CMD_VEL_TOPIC: Final = "cmd_vel"
_FLUSH_TIMEOUT_S: Final = 1.0


class KeySource(Protocol):
    """Where keys come from: ``read_key(timeout_s)`` returns one key, ``''`` on timeout,
    and raises ``EOFError`` when no more keys will come."""

    def read_key(self, timeout_s: float | None = None) -> str: ...


def command_to_twist(command: TwistCommand) -> Any:
    """The ``geometry_msgs/msg/Twist`` for a :class:`TwistCommand`.

    Raises:
        TeleopError: a field is NaN or infinite.
    """
    values = (command.linear_x, command.linear_y, command.linear_z, command.angular_z)
    if not all(math.isfinite(v) for v in values):
        raise TeleopError(f"refusing to publish a non-finite velocity: {command}")
    return Twist(
        linear_x=float(command.linear_x),
        linear_y=float(command.linear_y),
        linear_z=float(command.linear_z),
        angular_z=float(command.angular_z),
    )


class TeleopNode(Node):
    """Publishes a behaviour's velocities on ``cmd_vel``; subclasses pick the behaviour.

    Args:
        context: the context (graph, executor, transports) the node joins.
        node_name: the node's name; the class's ROS name when omitted.
        namespace: prefix of the relative ``cmd_vel`` topic.
        parameter_overrides: values for the parameters in the module docstring.
        remappings: topic renames, e.g. ``{"cmd_vel": "/robot1/cmd_vel"}``.
        topic: the topic to publish on before remapping.

    Raises:
        ParameterError: an override names an unknown parameter or has a bad value.
    """

    default_name: ClassVar[str]
    parameter_names: ClassVar[tuple[str, ...]]
    queue_size: ClassVar[int] = 1

    def __init__(
        self,
        *,
        context: Context,
        node_name: str | None = None,
        namespace: str = "/",
        parameter_overrides: Mapping[str, Any] | None = None,
        remappings: Mapping[str, str] | None = None,
        topic: str = CMD_VEL_TOPIC,
    ) -> None:
        super().__init__(
            node_name or self.default_name,
            context=context,
            namespace=namespace,
            parameter_overrides=parameter_overrides,
            remappings=remappings,
        )
        self.logic = self._create_logic()
        repeat_rate = self._declare_rate("repeat_rate", 0.0)
        self.check_parameter_overrides()
        self.publisher: Publisher = self.create_publisher(Twist, topic, self.queue_size)
        self._last: TwistCommand | None = None
        self._stopped = False
        self._repeat_timer: Timer | None = None
        if repeat_rate > 0:
            self._repeat_timer = self.create_timer(1.0 / repeat_rate, self._repeat)

    # ----------------------------------------------------------------- set-up
    def _create_logic(self) -> TeleopLogic:
        raise NotImplementedError

    def _declare_rate(self, name: str, default: float, description: str = "") -> float:
        """Declare a double parameter that must be a finite number >= 0."""
        param = self.declare_parameter(
            name, float(default), ParameterDescriptor(description=description, min_value=0.0)
        )
        try:
            return check_speed(f"parameter '{name}'", param.value)
        except TeleopError as err:
            raise ParameterError(f"node '{self.get_name()}': {err}") from err

    # ----------------------------------------------------------------- publishing
    def publish_command(self, command: TwistCommand) -> None:
        """Publish ``command`` as a Twist (and remember it for ``repeat_rate``)."""
        msg = command_to_twist(command)
        self._last = command
        self.publisher.publish(msg)

    def _repeat(self) -> None:
        last = self._last
        if last is not None and not self._stopped:
            self.publisher.publish(command_to_twist(last))

    def handle_key(self, key: str) -> KeyResult:
        """Feed one key to the behaviour and publish what it commands."""
        result = self.logic.handle_key(key)
        if result.twist is not None:
            self.publish_command(result.twist)
        return result

    def stop(self) -> None:
        """Publish a zero Twist once and stop repeating; waits until it has been handed on.

        When the executor spins in another thread, the message is published from that
        thread after everything queued before it, and this call waits (up to 1 s) for it.
        Calling it again does nothing.
        """
        if self._stopped:
            return
        self._stopped = True
        if self._repeat_timer is not None:
            self._repeat_timer.cancel()
        executor = self.context.executor
        if executor.on_executor_thread():
            self.publish_command(STOP)
            return
        done = threading.Event()

        def send() -> None:
            try:
                self.publish_command(STOP)
            finally:
                done.set()

        executor.call_soon_threadsafe(send)
        done.wait(_FLUSH_TIMEOUT_S)

    # ----------------------------------------------------------------- main loop
    def run(self, keys: KeySource, write: Callable[[str], None]) -> None:
        """The scripts' main loop: print the help, then one step per key until Ctrl-C.

        Args:
            keys: where keys come from; end of input ends the loop as Ctrl-C does.
            write: prints one line (called with each text the original ``print``-s).
        """
        try:
            for line in self.logic.banner():
                write(line)
            while True:
                try:
                    key = keys.read_key(self.logic.key_timeout_s)
                except EOFError:
                    break
                result = self.handle_key(key)
                for line in result.lines:
                    write(line)
                if result.quit:
                    break
        finally:
            self.stop()


class TeleopTwistKeyboardNode(TeleopNode):
    """``teleop_twist_keyboard``: holonomic keys, speed keys, stop on any other key."""

    default_name: ClassVar[str] = "teleop_twist_keyboard"
    parameter_names: ClassVar[tuple[str, ...]] = ("speed", "turn", "repeat_rate")
    queue_size: ClassVar[int] = 1

    def _create_logic(self) -> TeleopLogic:
        speed = self._declare_rate("speed", 0.3, "linear speed of a movement key (m/s)")
        turn = self._declare_rate("turn", 0.5, "angular speed of a movement key (rad/s)")
        return TeleopTwistKeyboard(speed=speed, turn=turn)


class MbotTeleopNode(TeleopNode):
    """``mbot_teleop``: velocities ramp up and down; space / ``k`` stop at once."""

    default_name: ClassVar[str] = "mbot_teleop"
    parameter_names: ClassVar[tuple[str, ...]] = (
        "speed",
        "turn",
        "scale_linear",
        "scale_angular",
        "repeat_rate",
    )
    queue_size: ClassVar[int] = 5

    def _create_logic(self) -> TeleopLogic:
        speed = self._declare_rate("speed", 0.2, "maximum linear speed (m/s)")
        turn = self._declare_rate("turn", 1.0, "maximum angular speed (rad/s)")
        speed = self._declare_rate("scale_linear", speed, "maximum linear speed (m/s)")
        turn = self._declare_rate("scale_angular", turn, "maximum angular speed (rad/s)")
        return SmoothTeleop(speed=speed, turn=turn)
