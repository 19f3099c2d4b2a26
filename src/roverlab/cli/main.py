"""The ``roverlab`` command."""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from functools import cache
from typing import Annotated, Any

import typer
import typer.main
from typer.core import TyperGroup

from roverlab.cli.apps import command_app, run_app
from roverlab.cli.common import NetworkOptions

# The subcommands, in the order ``roverlab --help`` lists them: name -> (module, attribute).
# A command's module is imported only when that command runs (or the root help lists them
# all), so ``roverlab topic echo`` does not pay for the simulator, the planners and the web
# server: about 1 s to start instead of 3-4 s on a 2-core machine.
_COMMANDS: dict[str, tuple[str, str]] = {
    "demo": ("roverlab.cli.demo", "demo"),
    "sim": ("roverlab.cli.sim", "sim"),
    "launch": ("roverlab.cli.launch", "launch"),
    "patrol": ("roverlab.cli.patrol", "patrol"),
    "explore": ("roverlab.cli.explore", "explore"),
    "run": ("roverlab.cli.run", "run"),
    "dashboard": ("roverlab.cli.viz", "dashboard"),
    "teleop": ("roverlab.cli.teleop", "teleop"),
    "foxglove": ("roverlab.cli.foxglove", "foxglove"),
    "topic": ("roverlab.cli.topic", "app"),
    "service": ("roverlab.cli.service", "app"),
    "action": ("roverlab.cli.action", "app"),
    "node": ("roverlab.cli.graph", "node_app"),
    "param": ("roverlab.cli.graph", "param_app"),
    "tf": ("roverlab.cli.tf", "app"),
    "daemon": ("roverlab.cli.daemon", "app"),
    "roscore": ("roverlab.cli.roscore", "roscore"),
    "master": ("roverlab.cli.roscore", "roscore"),
    "image": ("roverlab.cli.viz", "image_app"),
    "urdf": ("roverlab.cli.description", "app"),
    "map": ("roverlab.cli.maps", "app"),
    "slam": ("roverlab.cli.slam_group", "app"),
    "amcl": ("roverlab.cli.amcl_run", "app"),
    "nav": ("roverlab.cli.nav", "app"),
    "bag": ("roverlab.cli.bag", "app"),
}
# Commands that take arguments of their own after the target (``roverlab run pkg node.py
# _param:=1 __name:=x``).
_PASS_THROUGH = {"run": {"allow_extra_args": True, "ignore_unknown_options": True}}


@cache
def _load(name: str) -> Any:
    """The click command for ``name``, built from its module once per process."""
    module, attr = _COMMANDS[name]
    target: typer.Typer | Callable[..., Any] = getattr(importlib.import_module(module), attr)
    if isinstance(target, typer.Typer):
        group = typer.main.get_group(target)
        group.name = name
        return group
    single = typer.Typer(add_completion=False)
    single.command(name, context_settings=_PASS_THROUGH.get(name))(target)
    return typer.main.get_command(single)


class _LazyRoot(TyperGroup):
    """The root group: its subcommands are imported on first use (see ``_COMMANDS``)."""

    def list_commands(self, ctx: Any) -> list[str]:
        return [*super().list_commands(ctx), *_COMMANDS]

    def get_command(self, ctx: Any, cmd_name: str) -> Any:
        if cmd_name in _COMMANDS:
            return _load(cmd_name)
        return super().get_command(ctx, cmd_name)


app = command_app(
    name="roverlab",
    help="The classic ROS mobile-robot stack, pip-installable, no ROS needed.",
    no_args_is_help=True,
    cls=_LazyRoot,
)


@app.callback()
def root(
    ctx: typer.Context,
    connect: Annotated[
        list[str] | None,
        typer.Option(
            "--connect",
            "-e",
            help="Zenoh endpoint to connect to, e.g. tcp/192.168.1.41:7447 (repeatable). "
            "Default: the local daemon, started if needed.",
            envvar="ROVERLAB_CONNECT",
        ),
    ] = None,
    listen: Annotated[
        list[str] | None,
        typer.Option(
            "--listen",
            "-l",
            help="Zenoh endpoint to listen on (repeatable; default tcp/127.0.0.1:0).",
            envvar="ROVERLAB_LISTEN",
        ),
    ] = None,
    user: Annotated[
        str | None, typer.Option("--user", help="Zenoh user name (user/password auth).")
    ] = None,
    password: Annotated[
        str | None,
        typer.Option("--password", help="Zenoh password.", envvar="ROVERLAB_PASSWORD"),
    ] = None,
    tls_root_ca: Annotated[
        str | None, typer.Option("--tls-root-ca", help="CA certificate for tls/ endpoints.")
    ] = None,
    tls_cert: Annotated[
        str | None, typer.Option("--tls-cert", help="Certificate for listening on tls/.")
    ] = None,
    tls_key: Annotated[
        str | None, typer.Option("--tls-key", help="Private key for listening on tls/.")
    ] = None,
    multicast: Annotated[
        bool,
        typer.Option(
            "--multicast", help="Find peers by UDP multicast on the LAN (off by default)."
        ),
    ] = False,
    insecure: Annotated[
        bool,
        typer.Option(
            "--insecure",
            help="Allow --listen beyond loopback without --user/--password (a trusted "
            "network only: anyone on it can read and drive the robot).",
        ),
    ] = False,
    ros_master: Annotated[
        str | None,
        typer.Option(
            "--ros-master",
            help="Join the ROS 1 graph of this master, e.g. http://127.0.0.1:11311/ "
            "(default: ROS_MASTER_URI when set; without either, no ROS 1).",
        ),
    ] = None,
    client_of: Annotated[
        str | None,
        typer.Option(
            "--client-of",
            hidden=True,
            help="Join as a Zenoh client of this endpoint only (a launch's script nodes: "
            "they join the launch's graph through the launch).",
        ),
    ] = None,
) -> None:
    """roverlab: simulate, map, localise, navigate and inspect robots the ROS way."""
    if ros_master:
        os.environ["ROS_MASTER_URI"] = ros_master  # as roslaunch: child processes inherit
    ctx.obj = NetworkOptions(
        connect=tuple(connect or ()),
        listen=tuple(listen or ("tcp/127.0.0.1:0",)),
        user=user,
        password=password,
        tls_root_ca=tls_root_ca,
        tls_cert=tls_cert,
        tls_key=tls_key,
        multicast=multicast,
        insecure=insecure,
        client_of=client_of,
    )


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors become one line on stderr and exit code 2."""
    run_app(app, argv, "roverlab")
