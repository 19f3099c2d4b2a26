"""``roverlab tf``: tf2_echo and view_frames for the running system."""

from __future__ import annotations

import time
from typing import Annotated

import typer

from roverlab.cli.common import Connection, network_options
from roverlab.core import Time
from roverlab.tf import Buffer, TransformException, TransformListener, format_transform_echo

app = typer.Typer(help="Inspect transforms (tf2_echo, view_frames).", no_args_is_help=True)


@app.command("echo")
def echo(
    ctx: typer.Context,
    source_frame: Annotated[str, typer.Argument(help="Frame the result is expressed in.")],
    target_frame: Annotated[str, typer.Argument(help="Frame whose pose is printed.")],
    rate: Annotated[float, typer.Option("--rate", "-r", help="Prints per second.")] = 1.0,
    count: Annotated[
        int | None, typer.Option("--count", "-n", help="Exit after this many prints.")
    ] = None,
    timeout: Annotated[
        float | None,
        typer.Option("--timeout", help="Exit 1 if the transform is unavailable for S seconds."),
    ] = None,
) -> None:
    """Print the transform from SOURCE_FRAME to TARGET_FRAME, as tf2_echo."""
    if not rate > 0:
        raise typer.BadParameter("rate must be > 0", param_hint="--rate")
    with Connection(network_options(ctx)) as conn:
        buffer = Buffer()
        node = conn.context.create_node("roverlab_tf_echo")
        TransformListener(buffer, node)
        conn.context.spin_in_thread()
        printed = 0
        started = time.monotonic()
        last_error = ""
        try:
            while count is None or printed < count:
                try:
                    tf, stamp = buffer.lookup_transform(source_frame, target_frame, Time(0))
                except TransformException as err:
                    if str(err) != last_error:
                        typer.echo(
                            f"Waiting for transform {source_frame} -> {target_frame}: {err}",
                            err=True,
                        )
                        last_error = str(err)
                    if timeout is not None and time.monotonic() - started > timeout:
                        raise typer.Exit(1) from None
                    time.sleep(0.1)
                    continue
                typer.echo(format_transform_echo(tf, stamp))
                printed += 1
                if count is None or printed < count:
                    time.sleep(1.0 / rate)
        except KeyboardInterrupt:
            return


@app.command("frames")
def frames(
    ctx: typer.Context,
    wait: Annotated[float, typer.Option("--wait", help="Seconds to listen before printing.")] = 2.0,
) -> None:
    """Listen for a while, then print the TF tree as text (like view_frames)."""
    with Connection(network_options(ctx)) as conn:
        buffer = Buffer()
        node = conn.context.create_node("roverlab_view_frames")
        TransformListener(buffer, node)
        conn.context.spin_in_thread()
        time.sleep(wait)
        text = buffer.tree_as_text()
    typer.echo(text if text.strip() else "no transforms received")
