"""``roverlab dashboard``: rviz in the browser, attached to the running system.

Mount it with ``app.command("dashboard")(roverlab.viz.cli.dashboard)``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.common import Connection, network_options
from roverlab.viz.errors import DashboardError
from roverlab.viz.server import DashboardServer

__all__ = ["dashboard"]


def dashboard(
    ctx: typer.Context,
    host: Annotated[
        str, typer.Option("--host", help="Address to bind; non-loopback needs a token.")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port to serve on.")] = 8080,
    rviz: Annotated[
        Path | None,
        typer.Option("--rviz", "-d", help=".rviz file to load (not read yet in this version)."),
    ] = None,
    token: Annotated[
        str | None, typer.Option("--token", help="Access token (made up for non-loopback).")
    ] = None,
    fixed_frame: Annotated[str, typer.Option("--fixed-frame", help="Fixed frame.")] = "map",
) -> None:
    """Serve a web rviz (map, scan, robot, TF, tools, camera, drive) for the running system."""
    if rviz is not None and not rviz.is_file():
        raise DashboardError(f"no such .rviz file: {rviz}")
    with Connection(network_options(ctx)) as conn:
        server = DashboardServer(conn.context, host, port, token, fixed_frame=fixed_frame)
        conn.context.spin_in_thread()
        server.start()
        typer.echo(f"dashboard: {server.url}")
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass
        finally:
            server.stop()
