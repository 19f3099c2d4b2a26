"""``roverlab daemon``: the background router that lets processes find each other."""

from __future__ import annotations

import typer

from roverlab.core.transport.daemon import daemon_running, ensure_daemon, stop_daemon
from roverlab.core.transport.zenoh import daemon_endpoint

app = typer.Typer(
    help="Start, stop or check the roverlab daemon (started on demand by the CLI).",
    no_args_is_help=True,
)


@app.command("start")
def start() -> None:
    """Start the daemon on ROVERLAB_DAEMON (default tcp/127.0.0.1:7447) if not running."""
    ep = ensure_daemon()
    typer.echo(f"daemon running on {ep}")


@app.command("stop")
def stop() -> None:
    """Stop the daemon."""
    if stop_daemon():
        typer.echo("daemon stopped")
    else:
        typer.echo(f"no daemon running on {daemon_endpoint()}")


@app.command("status")
def status() -> None:
    """Tell whether the daemon is running (exit 1 if not)."""
    if daemon_running():
        typer.echo(f"daemon running on {daemon_endpoint()}")
    else:
        typer.echo(f"no daemon running on {daemon_endpoint()}")
        raise typer.Exit(1)
