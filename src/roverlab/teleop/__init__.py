"""Keyboard teleoperation: ``teleop_twist_keyboard`` and the ``mbot_teleop`` ramping variant.

Layers, as everywhere in roverlab:

* :mod:`.keyboard` -- pure key -> velocity logic (:class:`TeleopTwistKeyboard`,
  :class:`SmoothTeleop`, :func:`twist_for_key` for other front ends such as the web
  dashboard), reproducing the ROS 1 scripts key for key;
* :mod:`.terminal` -- raw single-key input from a TTY that always restores the terminal;
* :mod:`.node` -- the ROS-named nodes publishing ``geometry_msgs/Twist`` on ``cmd_vel``;
* :mod:`.cli` -- the ``roverlab teleop`` command (imported on its own, it needs typer).
"""

from roverlab.teleop.errors import NotATerminalError, TeleopError
from roverlab.teleop.keyboard import (
    CTRL_C,
    HELP_TEXT,
    MOVE_BINDINGS,
    SMOOTH_HELP_TEXT,
    SMOOTH_MOVE_BINDINGS,
    SPEED_BINDINGS,
    KeyResult,
    SmoothTeleop,
    TeleopLogic,
    TeleopTwistKeyboard,
    TwistCommand,
    twist_for_key,
    vels,
)
from roverlab.teleop.node import (
    KeySource,
    MbotTeleopNode,
    TeleopNode,
    TeleopTwistKeyboardNode,
    command_to_twist,
)
from roverlab.teleop.terminal import RawTerminal, Terminated

__all__ = [
    "CTRL_C",
    "HELP_TEXT",
    "MOVE_BINDINGS",
    "SMOOTH_HELP_TEXT",
    "SMOOTH_MOVE_BINDINGS",
    "SPEED_BINDINGS",
    "KeyResult",
    "KeySource",
    "MbotTeleopNode",
    "NotATerminalError",
    "RawTerminal",
    "SmoothTeleop",
    "TeleopError",
    "TeleopLogic",
    "TeleopNode",
    "TeleopTwistKeyboard",
    "TeleopTwistKeyboardNode",
    "Terminated",
    "TwistCommand",
    "command_to_twist",
    "twist_for_key",
    "vels",
]
