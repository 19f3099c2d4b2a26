"""``roverlab demo``: a small live system to try the CLI on."""

from __future__ import annotations

from typing import Annotated

import typer

from roverlab.cli.common import network_options, run_context
from roverlab.core import Context, configure_logging
from roverlab.core.transport.zenoh import ZenohTransport
from roverlab.demo import DemoRobot, Talker


def demo(
    ctx: typer.Context,
    rate: Annotated[
        float, typer.Option("--rate", help="Sim seconds per wall second (1 = real time).")
    ] = 1.0,
    duration: Annotated[
        float | None, typer.Option("--duration", help="Stop after S sim seconds.")
    ] = None,
    expose: Annotated[
        bool,
        typer.Option(
            "--expose/--no-expose",
            help="Make the topics visible to other terminals (roverlab topic echo ...).",
        ),
    ] = True,
) -> None:
    """Run a kinematic robot in a walled room: /cmd_vel in; /odom, /scan, /tf, /chatter out."""
    if not rate > 0:
        raise typer.BadParameter("rate must be > 0", param_hint="--rate")
    configure_logging()
    context = Context(clock="paced", rate=rate)
    DemoRobot(context=context)
    Talker(context=context)
    if expose:
        context.add_transport(ZenohTransport(network_options(ctx).zenoh_options()))
    typer.echo(
        "roverlab demo running. In another terminal try:\n"
        "  roverlab topic list\n"
        "  roverlab topic echo /odom --once\n"
        '  roverlab topic pub -r 10 /cmd_vel geometry_msgs/Twist "{linear: {x: 0.2}, '
        'angular: {z: 0.5}}"\n'
        "  roverlab tf echo odom base_link\n"
        "Ctrl-C to stop.",
        err=True,
    )
    wall = run_context(context, duration)
    typer.echo(f"demo stopped after {wall:.1f} s", err=True)
