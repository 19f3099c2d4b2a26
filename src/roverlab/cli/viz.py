"""``roverlab dashboard``: rviz in the browser, attached to the running system.

Mount it with ``app.command("dashboard")(roverlab.cli.viz.dashboard)``.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.common import Connection, HostOption, network_options
from roverlab.viz.config import DashboardConfig, default_config, load_config
from roverlab.viz.errors import DashboardError
from roverlab.viz.launcher import image_view_config
from roverlab.viz.ports import check_port, choose_port, start_page
from roverlab.viz.server import DashboardServer

__all__ = ["PortOption", "dashboard", "image_app", "image_view", "load_dashboard_config"]

# the options of the pages (dashboard, image view; demo's --port too) besides --host
PortOption = Annotated[
    int | None,
    typer.Option(
        "--port",
        help="TCP port to serve on (0: any free one). Default: $ROVERLAB_DASHBOARD_PORT, "
        "else 8080, or the next free port after 8080 when it is taken.",
        show_default=False,
    ),
]
TokenOption = Annotated[
    str | None, typer.Option("--token", help="Access token (made up for non-loopback).")
]


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
    host: HostOption = "127.0.0.1",
    port: PortOption = None,
    rviz: Annotated[
        Path | None,
        typer.Option(
            "--rviz",
            "-d",
            help="Display config to load: an rviz .rviz file or a saved dashboard .json.",
        ),
    ] = None,
    token: TokenOption = None,
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
    _serve(ctx, host, port, token, config, save_config, map_dir)


def _serve(
    ctx: typer.Context,
    host: str,
    port: int | None,
    token: str | None,
    config: DashboardConfig | None,
    save_config: Path | None,
    map_dir: Path,
) -> None:
    choice = choose_port(port)
    check_port(host, choice)  # before the network: a taken port fails at once
    with Connection(network_options(ctx), node=True) as conn:
        server = DashboardServer(
            conn.context,
            host,
            choice.port,
            token,
            config=config,
            config_path=save_config,
            map_dir=map_dir,
            remote_graph=conn.graph,
            remote_counts=conn.topic_counts,
        )
        conn.context.spin_in_thread()
        start_page(server, choice, say=typer.echo)
        typer.echo(f"dashboard: {server.url}")
        try:
            while True:
                time.sleep(1.0)
        except KeyboardInterrupt:
            pass
        finally:
            server.stop()


def image_view(
    ctx: typer.Context,
    topic: Annotated[
        str | None,
        typer.Argument(
            help="Image topic (sensor_msgs/Image or CompressedImage), e.g. "
            "/usb_cam/image_raw; omitted: pick one in the page."
        ),
    ] = None,
    host: HostOption = "127.0.0.1",
    port: PortOption = None,
    token: TokenOption = None,
) -> None:
    """rqt_image_view: the dashboard with its image panel on TOPIC."""
    _serve(ctx, host, port, token, image_view_config(topic), None, Path("."))


image_app = typer.Typer(
    help="Camera images (rqt_image_view) in the dashboard's image panel.", no_args_is_help=True
)
image_app.command("view")(image_view)
