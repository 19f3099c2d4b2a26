"""``roverlab map``: ``server`` (map_server), ``save`` (map_saver) and ``info``.

Mounted by the root command as ``roverlab map``::

    roverlab map server office.yaml               # rosrun map_server map_server office.yaml
    roverlab map save -f office                   # rosrun map_server map_saver -f office
    roverlab map info office.yaml

``server`` exposes ``/map`` and ``/map_metadata`` to the other roverlab processes (through
the local daemon unless the root command says otherwise); ``save`` joins them, waits for one
map and writes it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.apps import command_app, run_app
from roverlab.cli.common import Connection, network_options, run_context
from roverlab.core import Context, configure_logging
from roverlab.core.graph import resolve_name
from roverlab.core.transport.zenoh import ZenohTransport
from roverlab.maps.errors import MapError
from roverlab.maps.map_io import ImageFormat, check_save_thresholds, load_map
from roverlab.maps.node import MapSaver, MapServer

__all__ = ["app", "main"]

app = command_app(
    help="Serve, save and inspect map_server maps (YAML + PGM/PNG).",
    no_args_is_help=True,
    add_completion=False,
)


@app.command("server")
def server(
    ctx: typer.Context,
    yaml_file: Annotated[Path, typer.Argument(metavar="MAP.yaml", help="The map's YAML file.")],
    frame_id: Annotated[
        str, typer.Option("--frame-id", help="Frame of the published map (parameter frame_id).")
    ] = "map",
    expose: Annotated[
        bool,
        typer.Option(
            "--expose/--no-expose",
            help="Make /map visible to other processes (roverlab map save, topic echo).",
        ),
    ] = True,
) -> None:
    """Publish a map on /map and /map_metadata (latched) until Ctrl-C, as map_server."""
    configure_logging()
    context = Context(clock="wall")
    try:
        node = MapServer(context, yaml_path=yaml_file, frame_id=frame_id)
        if expose:
            context.add_transport(ZenohTransport(network_options(ctx).zenoh_options()))
    except BaseException:
        context.shutdown()
        raise
    m = node.map
    typer.echo(
        f"map_server: publishing a {m.width} X {m.height} map @ {m.info.resolution:.3f} m/cell "
        f"from {yaml_file} on {node.map_publisher.topic_name} (frame '{node.frame_id}'). "
        "Ctrl-C to stop."
    )
    run_context(context, None)


@app.command("save")
def save(
    ctx: typer.Context,
    file: Annotated[
        str,
        typer.Option(
            "-f", "--file", metavar="NAME", help="Output name: writes NAME.pgm, NAME.yaml."
        ),
    ] = "map",
    occ: Annotated[
        int, typer.Option("--occ", help="Cells >= this are occupied (black), 1..100.")
    ] = 65,
    free: Annotated[
        int, typer.Option("--free", help="Cells 0..this are free (white), 0..100.")
    ] = 25,
    topic: Annotated[str, typer.Option("--topic", help="The map topic.")] = "/map",
    image_format: Annotated[
        str, typer.Option("--fmt", help="Image format: pgm (as map_saver) or png.")
    ] = "pgm",
    timeout: Annotated[
        float | None,
        typer.Option("--timeout", help="Give up (exit 2) if no map arrives within S seconds."),
    ] = None,
) -> None:
    """Wait for one map and write NAME.pgm and NAME.yaml, as map_saver -f NAME."""
    check_save_thresholds(occ, free)
    if image_format not in ("pgm", "png"):
        raise MapError(f"--fmt must be pgm or png, got {image_format!r}")
    fmt: ImageFormat = "png" if image_format == "png" else "pgm"
    if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
        raise MapError(f"--timeout must be a positive number of seconds, got {timeout}")
    name = resolve_name(topic)
    with Connection(network_options(ctx), node=True) as conn:
        saver = MapSaver(
            conn.context,
            path_prefix=file,
            map_topic=name,
            threshold_occupied=occ,
            threshold_free=free,
            image_format=fmt,
            report=typer.echo,
        )
        try:
            conn.context.spin_until_condition(lambda: saver.finished, timeout_sec=timeout)
        except KeyboardInterrupt:
            raise typer.Exit(130) from None
    if saver.error is not None:
        raise saver.error
    if not saver.done:
        raise MapError(f"no map received on {name} within {timeout:g} s")


@app.command("info")
def info(
    yaml_file: Annotated[Path, typer.Argument(metavar="MAP.yaml", help="The map's YAML file.")],
) -> None:
    """Print a map's size, resolution, origin and free / occupied / unknown cell counts."""
    m = load_map(yaml_file)
    i = m.info
    counts = m.counts()
    x, y, yaw = i.origin
    typer.echo(f"map:        {yaml_file}")
    typer.echo(f"image:      {i.image}")
    typer.echo(
        f"size:       {m.width} x {m.height} cells "
        f"({m.width * i.resolution:.3f} x {m.height * i.resolution:.3f} m)"
    )
    typer.echo(f"resolution: {i.resolution:g} m/cell")
    typer.echo(f"origin:     [{x:g}, {y:g}, {yaw:g}]")
    typer.echo(
        f"mode:       {i.mode.value} (negate {int(i.negate)}, "
        f"occupied_thresh {i.occupied_thresh:g}, free_thresh {i.free_thresh:g})"
    )
    line = f"cells:      {counts.free} free, {counts.occupied} occupied, {counts.unknown} unknown"
    if counts.other:
        line += f", {counts.other} other"
    typer.echo(line)


def main(argv: list[str] | None = None) -> None:
    """``roverlab map`` on its own: user errors become one line on stderr and exit code 2."""
    run_app(app, argv, "roverlab map")
