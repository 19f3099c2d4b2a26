"""Key -> velocity logic of ``teleop_twist_keyboard.py`` and of the ``mbot_teleop.py`` variant.

Pure: no terminal, no bus, no clock, no printing. A key goes in, a :class:`KeyResult` comes
out, holding the velocity to publish (a :class:`TwistCommand`, or ``None`` for "publish
nothing"), whether to quit, and the lines the original script would ``print``.

Two behaviours, each reproducing its ROS 1 script step for step:

:class:`TeleopTwistKeyboard`
    ``teleop_twist_keyboard.py``: ``u i o / j k l / m , .`` move, the shifted keys
    ``U I O / J K L / M < >`` strafe (holonomic), ``t``/``b`` go up/down, ``q z w x e c``
    scale the speeds by 10 %, any other key stops, Ctrl-C quits. Defaults ``speed`` 0.3 m/s
    and ``turn`` 0.5 rad/s, the script's ``rospy.get_param("~speed", 0.3)`` and
    ``rospy.get_param("~turn", 0.5)``.
:class:`SmoothTeleop`
    ``mbot_teleop.py``: the same non-holonomic keys, but the published velocity ramps
    towards ``speed * direction`` by at most 0.02 m/s and 0.1 rad/s per step, a step
    being one key or a 0.1 s wait for one; space and ``k`` stop at once; after five steps
    without a movement or speed key the target falls to zero (and the velocity ramps down).
    Defaults ``speed`` 0.2 and ``turn`` 1 as in the script. Its launch file passes
    ``scale_linear`` / ``scale_angular``, which the script never reads; roverlab's node
    takes them as these two starting maximum speeds (see :mod:`roverlab.teleop.node`).

Numbers in the ``currently:`` lines are formatted as Python 2's ``str(float)`` (12
significant digits) because both scripts are Python 2: ``0.4 * 1.1`` prints ``0.44``, not
``0.44000000000000006``. A speed key that would overflow a speed to infinity leaves it
unchanged (the original would end up publishing ``inf``); nothing here yields NaN or inf
from finite settings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final, Protocol

from roverlab.teleop.errors import TeleopError

CTRL_C: Final = "\x03"

HELP_TEXT: Final = """
Reading from the keyboard  and Publishing to Twist!
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

For Holonomic mode (strafing), hold down the shift key:
---------------------------
   U    I    O
   J    K    L
   M    <    >

t : up (+z)
b : down (-z)

anything else : stop

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%

CTRL-C to quit
"""
"""``msg`` of teleop_twist_keyboard.py, verbatim."""

SMOOTH_HELP_TEXT: Final = """
Control mbot!
---------------------------
Moving around:
   u    i    o
   j    k    l
   m    ,    .

q/z : increase/decrease max speeds by 10%
w/x : increase/decrease only linear speed by 10%
e/c : increase/decrease only angular speed by 10%
space key, k : force stop
anything else : stop smoothly

CTRL-C to quit
"""
"""``msg`` of mbot_teleop.py, verbatim."""

MOVE_BINDINGS: Final[dict[str, tuple[int, int, int, int]]] = {
    "i": (1, 0, 0, 0),
    "o": (1, 0, 0, -1),
    "j": (0, 0, 0, 1),
    "l": (0, 0, 0, -1),
    "u": (1, 0, 0, 1),
    ",": (-1, 0, 0, 0),
    ".": (-1, 0, 0, 1),
    "m": (-1, 0, 0, -1),
    "O": (1, -1, 0, 0),
    "I": (1, 0, 0, 0),
    "J": (0, 1, 0, 0),
    "L": (0, -1, 0, 0),
    "U": (1, 1, 0, 0),
    "<": (-1, 0, 0, 0),
    ">": (-1, -1, 0, 0),
    "M": (-1, 1, 0, 0),
    "t": (0, 0, 1, 0),
    "b": (0, 0, -1, 0),
}
"""Key -> (x, y, z, th) directions, teleop_twist_keyboard.py's ``moveBindings``."""

SPEED_BINDINGS: Final[dict[str, tuple[float, float]]] = {
    "q": (1.1, 1.1),
    "z": (0.9, 0.9),
    "w": (1.1, 1),
    "x": (0.9, 1),
    "e": (1, 1.1),
    "c": (1, 0.9),
}
"""Key -> (speed factor, turn factor), ``speedBindings`` of both scripts."""

SMOOTH_MOVE_BINDINGS: Final[dict[str, tuple[int, int]]] = {
    "i": (1, 0),
    "o": (1, -1),
    "j": (0, 1),
    "l": (0, -1),
    "u": (1, 1),
    ",": (-1, 0),
    ".": (-1, 1),
    "m": (-1, -1),
}
"""Key -> (x, th) directions, mbot_teleop.py's ``moveBindings``."""

_HELP_EVERY: Final = 15  # the help text is printed again after every 15th speed change


def _py2_str(value: float) -> str:
    """``str(value)`` as Python 2.7 printed it (floats with 12 significant digits)."""
    if not isinstance(value, float):
        return str(value)
    text = f"{value:.12g}"
    if text.lstrip("-").isdigit():
        text += ".0"
    return text


def vels(speed: float, turn: float) -> str:
    """The status line both scripts print: ``currently:\\tspeed S\\tturn T ``."""
    return f"currently:\tspeed {_py2_str(speed)}\tturn {_py2_str(turn)} "


def check_speed(name: str, value: float) -> float:
    """Return ``value`` if it is a finite number >= 0, else raise :class:`TeleopError`."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TeleopError(f"{name} must be a number, got {value!r}")
    if not math.isfinite(value) or value < 0:
        raise TeleopError(f"{name} must be a finite number >= 0, got {value!r}")
    return value


def _scaled(value: float, factor: float) -> float:
    scaled = value * factor
    return scaled if math.isfinite(scaled) else value


@dataclass(frozen=True, slots=True)
class TwistCommand:
    """The four Twist fields teleop sets (m/s and rad/s); the others are always zero."""

    linear_x: float = 0.0
    linear_y: float = 0.0
    linear_z: float = 0.0
    angular_z: float = 0.0

    @property
    def is_zero(self) -> bool:
        return not (self.linear_x or self.linear_y or self.linear_z or self.angular_z)


STOP: Final = TwistCommand()


@dataclass(frozen=True, slots=True)
class KeyResult:
    """What one key (or one empty wait) does.

    Attributes:
        twist: the velocity to publish now, or ``None`` to publish nothing (Ctrl-C).
        quit: the loop ends here; the caller then publishes a zero Twist.
        lines: text the original prints, one ``print`` statement per entry.
    """

    twist: TwistCommand | None
    quit: bool = False
    lines: tuple[str, ...] = ()


class TeleopLogic(Protocol):
    """What a teleop loop needs from a key -> velocity behaviour."""

    @property
    def key_timeout_s(self) -> float | None:
        """How long one step waits for a key (``None``: until a key comes)."""
        ...

    @property
    def speed(self) -> float: ...

    @property
    def turn(self) -> float: ...

    def banner(self) -> tuple[str, ...]:
        """The lines printed at start: the help text and the ``currently:`` line."""
        ...

    def handle_key(self, key: str) -> KeyResult:
        """One step; ``key`` is ``''`` when the wait for a key timed out."""
        ...


def twist_for_key(key: str, speed: float, turn: float) -> TwistCommand | None:
    """The velocity teleop_twist_keyboard publishes for ``key`` with no state kept.

    A movement key gives its direction times ``speed`` / ``turn``; a speed key
    (:data:`SPEED_BINDINGS`) gives ``None``, since it keeps the current direction and only
    rescales (use :class:`TeleopTwistKeyboard` for that); any other key gives a zero Twist.
    """
    direction = MOVE_BINDINGS.get(key)
    if direction is not None:
        x, y, z, th = direction
        return TwistCommand(x * speed, y * speed, z * speed, th * turn)
    if key in SPEED_BINDINGS:
        return None
    return STOP


class _KeyboardSpeeds:
    """What both keyboard loops keep: the speed and turn the speed keys scale, and a count of
    speed changes (the help is reprinted every 15th).

    Raises:
        TeleopError: ``speed`` or ``turn`` is not a finite number >= 0.
    """

    help_text: str = HELP_TEXT

    def __init__(self, speed: float, turn: float) -> None:
        self._speed = check_speed("speed", speed)
        self._turn = check_speed("turn", turn)
        self._status = 0

    @property
    def speed(self) -> float:
        return self._speed

    @property
    def turn(self) -> float:
        return self._turn

    @property
    def status(self) -> int:
        """Speed changes so far, modulo 15 (the help is reprinted when it wraps)."""
        return self._status

    def banner(self) -> tuple[str, ...]:
        return (self.help_text, vels(self._speed, self._turn))

    def _change_speed(self, key: str) -> list[str]:
        """Apply speed key ``key``: the new ``vels`` line, and the help when it is due."""
        speed_factor, turn_factor = SPEED_BINDINGS[key]
        self._speed = _scaled(self._speed, speed_factor)
        self._turn = _scaled(self._turn, turn_factor)
        lines = [vels(self._speed, self._turn)]
        if self._status == _HELP_EVERY - 1:
            lines.append(self.help_text)
        self._status = (self._status + 1) % _HELP_EVERY
        return lines


class TeleopTwistKeyboard(_KeyboardSpeeds):
    """teleop_twist_keyboard.py's loop body, one key at a time.

    Args:
        speed: linear speed (m/s) a movement key commands; ``~speed`` in ROS.
        turn: angular speed (rad/s) a movement key commands; ``~turn`` in ROS.

    Raises:
        TeleopError: ``speed`` or ``turn`` is not a finite number >= 0.
    """

    key_timeout_s: float | None = None  # getKey() blocks until a key comes
    help_text: str = HELP_TEXT

    def __init__(self, *, speed: float = 0.3, turn: float = 0.5) -> None:
        super().__init__(speed, turn)
        self._direction: tuple[int, int, int, int] = (0, 0, 0, 0)

    @property
    def direction(self) -> tuple[int, int, int, int]:
        """The last movement key's (x, y, z, th), zeros after a stop."""
        return self._direction

    def command(self) -> TwistCommand:
        """The velocity for the current direction, speed and turn."""
        x, y, z, th = self._direction
        return TwistCommand(x * self._speed, y * self._speed, z * self._speed, th * self._turn)

    def handle_key(self, key: str) -> KeyResult:
        lines: list[str] = []
        if key in MOVE_BINDINGS:
            self._direction = MOVE_BINDINGS[key]
        elif key in SPEED_BINDINGS:
            lines.extend(self._change_speed(key))
        else:
            self._direction = (0, 0, 0, 0)
            if key == CTRL_C:
                return KeyResult(None, quit=True)
        return KeyResult(self.command(), lines=tuple(lines))


class SmoothTeleop(_KeyboardSpeeds):
    """mbot_teleop.py's loop body: ramped velocities, one step per key or 0.1 s wait.

    Args:
        speed: maximum linear speed (m/s) a movement key ramps to (``scale_linear``).
        turn: maximum angular speed (rad/s) a movement key ramps to (``scale_angular``).
        linear_step: largest change of the linear velocity per step (m/s).
        angular_step: largest change of the angular velocity per step (rad/s).
        idle_steps: steps without a movement or speed key after which the target is zero.

    Raises:
        TeleopError: a setting is not a finite number >= 0 (``idle_steps`` >= 1).
    """

    key_timeout_s: float | None = 0.1  # getKey()'s select() timeout
    help_text: str = SMOOTH_HELP_TEXT

    def __init__(
        self,
        *,
        speed: float = 0.2,
        turn: float = 1,
        linear_step: float = 0.02,
        angular_step: float = 0.1,
        idle_steps: int = 5,
    ) -> None:
        super().__init__(speed, turn)
        self.linear_step = check_speed("linear_step", linear_step)
        self.angular_step = check_speed("angular_step", angular_step)
        if isinstance(idle_steps, bool) or not isinstance(idle_steps, int) or idle_steps < 1:
            raise TeleopError(f"idle_steps must be an integer >= 1, got {idle_steps!r}")
        self.idle_steps = idle_steps
        self._x = 0
        self._th = 0
        self._count = 0
        self._control_speed: float = 0.0
        self._control_turn: float = 0.0

    @property
    def idle_count(self) -> int:
        """Steps since the last movement or speed key."""
        return self._count

    def command(self) -> TwistCommand:
        """The ramped velocity of the last step."""
        return TwistCommand(linear_x=self._control_speed, angular_z=self._control_turn)

    def handle_key(self, key: str) -> KeyResult:
        lines: list[str] = []
        if key in SMOOTH_MOVE_BINDINGS:
            self._x, self._th = SMOOTH_MOVE_BINDINGS[key]
            self._count = 0
        elif key in SPEED_BINDINGS:
            lines.extend(self._change_speed(key))
            self._count = 0
        elif key in (" ", "k"):
            self._x = self._th = 0
            self._control_speed = self._control_turn = 0.0
        else:
            self._count += 1
            if self._count >= self.idle_steps:
                self._x = self._th = 0
            if key == CTRL_C:
                return KeyResult(None, quit=True)
        self._control_speed = _ramp(self._control_speed, self._speed * self._x, self.linear_step)
        self._control_turn = _ramp(self._control_turn, self._turn * self._th, self.angular_step)
        return KeyResult(self.command(), lines=tuple(lines))


def _ramp(control: float, target: float, step: float) -> float:
    """Move ``control`` towards ``target`` by at most ``step``, as mbot_teleop.py does."""
    if target > control:
        return min(target, control + step)
    if target < control:
        return max(target, control - step)
    return target
