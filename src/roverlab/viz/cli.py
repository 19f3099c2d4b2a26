"""``roverlab dashboard``: rviz in the browser, attached to the running system.

Mount it with ``app.command("dashboard")(roverlab.viz.cli.dashboard)``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.common import Connection, network_options
from roverlab.viz.config import DashboardConfig, default_config, load_config
from roverlab.viz.errors import DashboardError
from roverlab.viz.server import DashboardServer

__all__ = ["dashboard", "load_dashboard_config"]


def load_dashboard_config(path: Path | None, fixed_frame: str | None) -> DashboardConfig | None:
    """The display config of ``--rviz`` / ``-d`` with ``--fixed-frame`` applied.

    Raises:
        DashboardError: no such file, or a malformed one.
    """
    if path is None:
        if fixed_frame is None:
            return None
        return default_config(fixed_frame.lstrip("/"))
    if not path.is_file():
        raise DashboardError(f"no such display config (.rviz or .json): {path}")
    config = load_config(path)
    if fixed_frame:
        config.fixed_frame = fixed_frame.lstrip("/")
    return config


def dashboard(
    ctx: typer.Context,
    host: Annotated[
        str, typer.Option("--host", help="Address to bind; non-loopback needs a token.")
    ] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port to serve on.")] = 8080,
    rviz: Annotated[
        Path | None,
        typer.Option(
            "--rviz",
            "-d",
            help="Display config to load: an rviz .rviz file or a saved dashboard .json.",
        ),
    ] = None,
    token: Annotated[
        str | None, typer.Option("--token", help="Access token (made up for non-loopback).")
    ] = None,
    fixed_frame: Annotated[
        str | None,
        typer.Option("--fixed-frame", "-f", help="Fixed frame (overrides the config's)."),
    ] = None,
    save_config: Annotated[
        Path | None,
        typer.Option(
            "--save-config",
            help="Where the page's 'Save config' writes (default: the loaded .json, "
            "else ./dashboard.json).",
        ),
    ] = None,
    map_dir: Annotated[
        Path, typer.Option("--map-dir", help="Where the page's 'Save map' writes NAME.pgm/.yaml.")
    ] = Path("."),
) -> None:
    """Serve a web rviz (displays, tools, camera, drive) for the running system."""
    config = load_dashboard_config(rviz, fixed_frame)
    with Connection(network_options(ctx)) as conn:
        server = DashboardServer(
            conn.context,
            host,
            port,
            token,
            config=config,
            config_path=save_config,
            map_dir=map_dir,
            remote_graph=conn.graph,
        )
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
