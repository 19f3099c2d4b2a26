"""``roverlab teleop``: drive a robot from the keyboard, as ``rosrun teleop_twist_keyboard``.

Both ROS habits work::

    roverlab teleop --speed 0.3 --turn 0.5
    roverlab teleop _speed:=0.3 _turn:=0.5 cmd_vel:=/robot1/cmd_vel
    roverlab teleop --smooth _scale_linear:=0.1 _scale_angular:=0.4    # mbot_teleop

ROS 1 style arguments: ``_param:=value`` sets a private parameter (the value is read as
YAML, as rosrun does), ``cmd_vel:=/other`` remaps the topic, ``__name:=`` and ``__ns:=``
rename the node and set its namespace. The command joins the roverlab network (the local
daemon unless the root command says otherwise), so a simulator in another process
receives the Twists. Mount it with ``app.command("teleop")(roverlab.cli.teleop.teleop)``;
``roverlab teleop`` runs it.
"""

from __future__ import annotations

import contextlib
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any, Final

import typer
import yaml

from roverlab.cli.apps import command_app, run_app
from roverlab.cli.common import Connection, network_options
from roverlab.core.graph import resolve_name, validate_node_name
from roverlab.teleop.errors import TeleopError
from roverlab.teleop.keyboard import check_speed
from roverlab.teleop.node import (
    CMD_VEL_TOPIC,
    MbotTeleopNode,
    TeleopNode,
    TeleopTwistKeyboardNode,
)
from roverlab.teleop.terminal import RawTerminal, Terminated, stdin_fd

__all__ = ["TeleopArgs", "app", "main", "parse_ros_args", "teleop"]

# Let the last Twist leave the Zenoh session before it closes (as `topic pub` does).
_LINGER_S: Final = 0.2


@dataclass(frozen=True)
class TeleopArgs:
    """What ROS-style command-line arguments ask of the node."""

    parameters: dict[str, float] = field(default_factory=dict)
    remappings: dict[str, str] = field(default_factory=dict)
    node_name: str | None = None
    namespace: str = "/"


def _parameter_value(name: str, text: str) -> float:
    try:
        value = yaml.safe_load(text) if text.strip() else None
    except yaml.YAMLError:
        value = text
    if isinstance(value, str):  # YAML 1.1 reads 1e-1 as a string; Python does not
        with contextlib.suppress(ValueError):
            value = float(value)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TeleopError(f"invalid value for _{name}:={text}: not a number")
    return float(check_speed(f"_{name}", value))


def parse_ros_args(
    args: Sequence[str],
    *,
    node_class: type[TeleopNode] = TeleopTwistKeyboardNode,
    topic: str = CMD_VEL_TOPIC,
) -> TeleopArgs:
    """Read rosrun-style ``name:=value`` arguments for a teleop node.

    Raises:
        TeleopError: an argument is not ``name:=value``, names an unknown parameter, gives
            a bad value or twice the same name, or remaps a topic the node does not use.
    """
    parameters: dict[str, float] = {}
    remappings: dict[str, str] = {}
    node_name: str | None = None
    namespace = "/"
    for arg in args:
        name, sep, value = arg.partition(":=")
        if not sep or not name:
            raise TeleopError(f"unexpected argument {arg!r} (expected NAME:=VALUE)")
        if name in ("__name", "__node"):
            node_name = validate_node_name(value)
        elif name == "__ns":
            namespace = value or "/"
        elif name.startswith("__"):
            raise TeleopError(f"unsupported special argument {arg!r} (use __name or __ns)")
        elif name.startswith("_"):
            pname = name[1:]
            if pname not in node_class.parameter_names:
                known = ", ".join(f"_{p}" for p in node_class.parameter_names)
                raise TeleopError(
                    f"unknown parameter {name!r} for {node_class.default_name} (known: {known})"
                )
            if pname in parameters:
                raise TeleopError(f"parameter {name!r} given twice")
            parameters[pname] = _parameter_value(pname, value)
        else:
            if name in remappings:
                raise TeleopError(f"topic {name!r} remapped twice")
            remappings[name] = value
    own = node_name or node_class.default_name
    published = resolve_name(topic, namespace, own)
    for src, dst in remappings.items():
        if resolve_name(src, namespace, own) != published:
            raise TeleopError(
                f"cannot remap {src!r}: {own} publishes only {topic!r} (try {topic}:={dst})"
            )
        resolve_name(dst, namespace, own)  # raises InvalidTopicNameError for a bad target
    return TeleopArgs(parameters, remappings, node_name, namespace)


def _print(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def _flag_value(flag: str, value: float | None) -> float | None:
    if value is None:
        return None
    if not math.isfinite(value) or value < 0:
        raise TeleopError(f"{flag} must be a finite number >= 0, got {value}")
    return value


def teleop(
    ctx: typer.Context,
    ros_args: Annotated[
        list[str] | None,
        typer.Argument(
            metavar="NAME:=VALUE",
            help="ROS 1 style arguments: _speed:=0.3 _turn:=0.5 _repeat_rate:=10 "
            "cmd_vel:=/other __name:=teleop __ns:=/robot1",
            show_default=False,
        ),
    ] = None,
    speed: Annotated[
        float | None,
        typer.Option(
            "--speed", help="Linear speed of a movement key, m/s (default 0.3; 0.2 with --smooth)."
        ),
    ] = None,
    turn: Annotated[
        float | None,
        typer.Option(
            "--turn", help="Angular speed of a movement key, rad/s (default 0.5; 1 with --smooth)."
        ),
    ] = None,
    smooth: Annotated[
        bool,
        typer.Option(
            "--smooth",
            help="mbot_teleop: ramp the velocities, stop with space or k "
            "(also takes _scale_linear:= / _scale_angular:=).",
        ),
    ] = False,
    topic: Annotated[
        str, typer.Option("--topic", help="Topic to publish geometry_msgs/Twist on.")
    ] = CMD_VEL_TOPIC,
) -> None:
    """Drive a robot from the keyboard: teleop_twist_keyboard (or mbot_teleop with --smooth)."""
    node_class: type[TeleopNode] = MbotTeleopNode if smooth else TeleopTwistKeyboardNode
    parsed = parse_ros_args(ros_args or [], node_class=node_class, topic=topic)
    parameters: dict[str, Any] = dict(parsed.parameters)
    for flag, pname, value in (("--speed", "speed", speed), ("--turn", "turn", turn)):
        checked = _flag_value(flag, value)
        if checked is None:
            continue
        if pname in parameters:
            raise TeleopError(f"{flag} and _{pname}:= both given; use one")
        parameters[pname] = checked
    fd = stdin_fd()  # fail before touching the network when there is no keyboard
    code = 0
    with Connection(network_options(ctx), node=True) as conn:
        node = node_class(
            context=conn.context,
            node_name=parsed.node_name,
            namespace=parsed.namespace,
            parameter_overrides=parameters,
            remappings=parsed.remappings,
            topic=topic,
        )
        conn.context.spin_in_thread()
        try:
            with RawTerminal(fd) as terminal:
                node.run(terminal, _print)
        except Terminated as sig:
            code = sig.exit_code
        except KeyboardInterrupt:  # SIGINT from outside the terminal: stop like Ctrl-C
            pass
        finally:
            node.stop()
            time.sleep(_LINGER_S)
    if code:
        raise typer.Exit(code)


app = command_app(
    name="teleop",
    add_completion=False,
)
app.command("teleop")(teleop)


def main(argv: list[str] | None = None) -> None:
    """``roverlab teleop`` on its own: user errors become one line on stderr and exit code 2."""
    run_app(app, argv, "roverlab teleop")
