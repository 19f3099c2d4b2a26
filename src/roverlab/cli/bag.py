"""``roverlab bag``: record, play, info, convert, recover — the ros2 bag / rosbag habits."""

from __future__ import annotations

import datetime as dt
import functools
import math
import re
import threading
import time
from pathlib import Path
from typing import Annotated

import typer

from roverlab.bag.files import bag_info, convert_bag, recover_bag
from roverlab.bag.player import Player, PlayOptions, parse_remaps
from roverlab.bag.recorder import BagError, McapRecorder
from roverlab.cli.common import Connection, network_options, stop_on_signals
from roverlab.core.graph import resolve_name

app = typer.Typer(
    help="Record and play topics in MCAP files; inspect, convert and recover bags "
    "(ros2 bag / rosbag).",
    no_args_is_help=True,
)

_DISCOVERY_PERIOD_S = 0.5


def _output_path(name: str | None) -> Path:
    if name is None:
        name = f"rosbag2_{dt.datetime.now():%Y_%m_%d-%H_%M_%S}"
    p = Path(name)
    return p if p.suffix.lower() == ".mcap" else p.with_name(p.name + ".mcap")


@app.command("record")
def record(
    ctx: typer.Context,
    topics: Annotated[
        list[str] | None, typer.Argument(help="Topics to record (or -a for every topic).")
    ] = None,
    all_topics: Annotated[
        bool, typer.Option("--all", "-a", help="Record every topic, present and future.")
    ] = False,
    output: Annotated[
        str | None,
        typer.Option(
            "--output", "-o", help="Bag name: NAME.mcap (default rosbag2_DATE_TIME.mcap)."
        ),
    ] = None,
    exclude: Annotated[
        str | None,
        typer.Option("--exclude", "-x", help="Regular expression of topics not to record."),
    ] = None,
    duration: Annotated[
        float | None, typer.Option("--duration", "-d", help="Stop after S seconds.")
    ] = None,
    compression: Annotated[
        str, typer.Option("--compression", help="Chunk compression: zstd, lz4 or none.")
    ] = "zstd",
    use_sim_time: Annotated[
        bool,
        typer.Option("--use-sim-time", help="Stamp messages with /clock time, not wall time."),
    ] = False,
) -> None:
    """Record topics of the running system to one MCAP file (ros2 bag record -s mcap).

    SIGINT, SIGTERM and SIGHUP finish the file; chunks are flushed every second, so after
    a kill -9 `roverlab bag recover NAME.mcap.part` gets all but the last second back.
    """
    if not all_topics and not topics:
        raise BagError("give topics to record, or -a for every topic")
    if duration is not None and not (duration > 0 and math.isfinite(duration)):
        raise BagError(f"--duration must be a positive number of seconds, got {duration}")
    try:
        pattern = re.compile(exclude) if exclude else None
    except re.error as err:
        raise BagError(f"--exclude {exclude!r} is not a regular expression: {err}") from None
    wanted = None if all_topics else {resolve_name(t) for t in topics or []}
    path = _output_path(output)
    with stop_on_signals(threading.Event()) as stop:
        conn = Connection(network_options(ctx), clock="external" if use_sim_time else "wall")
        recorder = McapRecorder(
            path,
            compression=compression,
            clock=None if use_sim_time else time.time_ns,
            topics=wanted,
        )
        try:
            conn.context.add_transport(recorder)
            conn.context.spin_in_thread()
            typer.echo(f"recording to {recorder.path} (Ctrl-C to stop)", err=True)
            end = None if duration is None else time.monotonic() + duration
            seen: set[str] = set()
            while not stop.is_set() and (end is None or time.monotonic() < end):
                for e in conn.graph(timeout_s=0.3):
                    if e.kind != "publisher" or e.topic in seen:
                        continue
                    if pattern is not None and pattern.search(e.topic):
                        continue
                    if wanted is not None and e.topic not in wanted:
                        continue
                    seen.add(e.topic)
                    topic, tname = e.topic, e.typename
                    conn.context.executor.call_soon_threadsafe(
                        functools.partial(recorder.record, topic, tname)
                    )
                    typer.echo(f"subscribed to {topic} [{tname}]", err=True)
                wait = (
                    _DISCOVERY_PERIOD_S
                    if end is None
                    else min(_DISCOVERY_PERIOD_S, end - time.monotonic())
                )
                stop.wait(max(0.0, wait))
        finally:
            conn.close()  # the context's shutdown finishes the file
    typer.echo(
        f"recorded {recorder.messages} messages on {len(recorder.topics)} topics to "
        f"{recorder.path}",
        err=True,
    )


@app.command("play", context_settings={"allow_extra_args": True})
def play(
    ctx: typer.Context,
    bag: Annotated[Path, typer.Argument(help="A .mcap file, a ROS 1 .bag or a ROS 2 bag folder.")],
    rate: Annotated[float, typer.Option("--rate", "-r", help="Playback speed factor.")] = 1.0,
    clock: Annotated[
        bool,
        typer.Option("--clock", help="Publish /clock (100 Hz) with the bag's time, for sim time."),
    ] = False,
    loop: Annotated[bool, typer.Option("--loop", "-l", help="Play again at the end.")] = False,
    topics: Annotated[
        list[str] | None,
        typer.Option("--topics", help="Play only these topics: --topics /scan /tf (or repeated)."),
    ] = None,
    start_offset: Annotated[
        float, typer.Option("--start-offset", help="Start S seconds into the bag.")
    ] = 0.0,
    remap: Annotated[
        list[str] | None,
        typer.Option("--remap", "-m", help="Publish topic a as b: a:=b (repeatable)."),
    ] = None,
) -> None:
    """Publish a bag's messages with their recorded timing (ros2 bag play / rosbag play)."""
    if ctx.args:  # ros2 bag play's `--topics a b c`: the words after the first are extra
        if not topics:
            raise BagError(f"unexpected arguments: {' '.join(ctx.args)}")
        topics = [*topics, *ctx.args]
    options = PlayOptions(
        rate=rate,
        clock=clock,
        loop=loop,
        topics=[resolve_name(t) for t in topics] if topics else None,
        start_offset_s=start_offset,
        remaps=parse_remaps(remap or []),
    )
    bag_info(bag)  # one clear error before joining the network
    with stop_on_signals(threading.Event()) as stop, Connection(network_options(ctx)) as conn:
        player = Player(conn.context, bag, options)
        conn.context.spin_in_thread()
        time.sleep(0.3)  # subscribers' declarations reach the new publishers

        def started(t0: int, t1: int) -> None:
            typer.echo(
                f"playing {bag} ({(t1 - t0) / 1e9:.1f} s) at rate {rate:g}"
                + (" with /clock" if clock else ""),
                err=True,
            )

        n = player.run(stop, started)
        time.sleep(0.3)  # the last messages leave before the session closes
    typer.echo(f"published {n} messages", err=True)


@app.command("info")
def info(
    bag: Annotated[Path, typer.Argument(help="A .mcap file, a ROS 1 .bag or a ROS 2 bag folder.")],
) -> None:
    """Print a bag's duration, start, end, message count and topics (ros2 bag info)."""
    for line in bag_info(bag).lines():
        typer.echo(line)


@app.command("convert")
def convert(
    src: Annotated[Path, typer.Argument(help="ROS 1 .bag, ROS 2 bag (sqlite3 / MCAP) or .mcap.")],
    dst: Annotated[Path, typer.Argument(help="The MCAP file to write.")],
    compression: Annotated[str, typer.Option("--compression", help="zstd, lz4 or none.")] = "zstd",
) -> None:
    """Convert a bag to one MCAP file with ROS 2 CDR messages (ros2 bag convert)."""
    n = convert_bag(src, dst, compression=compression)
    typer.echo(f"wrote {n} messages to {dst}")


@app.command("recover")
def recover(
    part: Annotated[Path, typer.Argument(help="The NAME.mcap.part a killed recorder left.")],
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Output file (default NAME.mcap).")
    ] = None,
) -> None:
    """Write a readable MCAP with every complete chunk of a killed recording (rosbag reindex)."""
    r = recover_bag(part, output)
    typer.echo(
        f"recovered {r.messages} messages in {r.chunks} chunks to {r.path}"
        + (f" ({r.dropped_bytes} bytes of a cut chunk dropped)" if r.dropped_bytes else "")
    )
