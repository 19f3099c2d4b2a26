"""``roverlab foxglove``: serve the running system to Foxglove (foxglove_bridge)."""

from __future__ import annotations

import secrets
import sys
import threading
from typing import Annotated

import typer

from roverlab.cli.common import Connection, HostOption, network_options, stop_on_signals
from roverlab.foxglove.bridge import FoxgloveBridge, FoxgloveError
from roverlab.foxglove.proxy import TokenRelay
from roverlab.viz.server import is_loopback

__all__ = ["foxglove"]


def foxglove(
    ctx: typer.Context,
    host: HostOption = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port (Foxglove's default 8765).")] = 8765,
    token: Annotated[
        str | None,
        typer.Option(
            "--token", help="Token required off loopback (made up and printed if not given)."
        ),
    ] = None,
) -> None:
    """Serve every topic to Foxglove over its WebSocket protocol (ROS 2 CDR + ros2msg
    schemas); clients may publish (teleop on /cmd_vel, goals, /initialpose), call every
    service (e.g. /move_base/clear_costmaps) and get / set node parameters (/node.param).

    In Foxglove: Open connection -> Foxglove WebSocket -> ws://HOST:PORT (add ?token=T off
    loopback). SIGINT / SIGTERM / SIGHUP stop it.
    """
    if not 0 <= port <= 65535:
        raise FoxgloveError(f"--port must be 0..65535, got {port}")
    local = is_loopback(host)
    if local and token is not None:
        typer.echo("note: --token is only checked off loopback", err=True)
    with (
        stop_on_signals(threading.Event()) as stop,
        Connection(network_options(ctx), node=True) as conn,
    ):
        conn.context.spin_in_thread()
        bridge = FoxgloveBridge(
            conn.context, host if local else "127.0.0.1", port if local else 0,
            remote_graph=conn.graph,
        )  # fmt: skip
        relay: TokenRelay | None = None
        try:
            if not local:
                secret = token or secrets.token_urlsafe(16)
                try:
                    relay = TokenRelay(host, port, bridge.port, secret)
                except OSError as err:
                    raise FoxgloveError(f"cannot listen on {host}:{port}: {err}") from err
                if token is None:
                    print(f"foxglove token (required by every client): {secret}", file=sys.stderr)
                typer.echo(f"foxglove: ws://{host}:{relay.port}/?token=<token>")
            else:
                typer.echo(f"foxglove: ws://{host}:{bridge.port}")
            typer.echo(
                f"serving {len(bridge.topics)} topics and {len(bridge.services)} services"
                " (more as they appear)",
                err=True,
            )
            stop.wait()
        finally:
            if relay is not None:
                relay.stop()
            bridge.stop()
