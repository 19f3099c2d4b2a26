"""The ``roverlab`` command."""

from __future__ import annotations

from typing import Annotated

import typer

from roverlab.cli import (
    action,
    amcl_run,
    daemon,
    demo,
    explore,
    graph,
    launch,
    nav,
    patrol,
    run,
    service,
    sim,
    slam_mapeval,
    slam_run,
    tf,
    topic,
)
from roverlab.cli import bag as bag_cli
from roverlab.cli import description as urdf_cli
from roverlab.cli import foxglove as foxglove_cli
from roverlab.cli import maps as map_cli
from roverlab.cli import slam as slam_cli
from roverlab.cli import teleop as teleop_cli
from roverlab.cli import viz as viz_cli
from roverlab.cli.apps import command_app, run_app
from roverlab.cli.common import NetworkOptions

app = command_app(
    name="roverlab",
    help="The classic ROS mobile-robot stack, pip-installable, no ROS needed.",
    no_args_is_help=True,
)
app.add_typer(topic.app, name="topic")
app.add_typer(service.app, name="service")
app.add_typer(action.app, name="action")
app.add_typer(graph.node_app, name="node")
app.add_typer(graph.param_app, name="param")
app.add_typer(tf.app, name="tf")
app.add_typer(daemon.app, name="daemon")
app.command("demo")(demo.demo)
app.command("sim")(sim.sim)
app.command("launch")(launch.launch)
app.command("patrol")(patrol.patrol)
app.command("explore")(explore.explore)
app.command(
    "run",
    context_settings={"allow_extra_args": True, "ignore_unknown_options": True},
)(run.run)
app.command("dashboard")(viz_cli.dashboard)
image_app = typer.Typer(
    help="Camera images (rqt_image_view) in the dashboard's image panel.", no_args_is_help=True
)
image_app.command("view")(viz_cli.image_view)
app.add_typer(image_app, name="image")
app.add_typer(urdf_cli.app, name="urdf")
app.add_typer(map_cli.app, name="map")
slam_cli.app.command("run")(slam_run.run)
slam_cli.app.command("mapeval")(slam_mapeval.mapeval)
app.add_typer(slam_cli.app, name="slam")
app.command("teleop")(teleop_cli.teleop)
app.add_typer(amcl_run.app, name="amcl")
app.add_typer(nav.app, name="nav")
app.add_typer(bag_cli.app, name="bag")
app.command("foxglove")(foxglove_cli.foxglove)


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
) -> None:
    """roverlab: simulate, map, localise, navigate and inspect robots the ROS way."""
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
    )


def main(argv: list[str] | None = None) -> None:
    """Entry point: user errors become one line on stderr and exit code 2."""
    run_app(app, argv, "roverlab")
