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

from roverlab.bag.errors import BagError
from roverlab.bag.files import bag_info, convert_bag, recover_bag
from roverlab.bag.player import Player, PlayOptions, parse_remaps
from roverlab.bag.recorder import BagRecorder
from roverlab.bag.writers import check_output
from roverlab.cli.common import Connection, network_options, stop_on_signals
from roverlab.core.graph import resolve_name

app = typer.Typer(
    help="Record and play topics; inspect, convert and reindex bags (rosbag / ros2 bag). "
    "The extension decides the format: .bag = ROS 1 bag, .mcap = MCAP, a folder or .db3 = "
    "ROS 2 bag.",
    no_args_is_help=True,
)

_DISCOVERY_PERIOD_S = 0.5


def _output_path(name: str | None) -> Path:
    if name is None:
        return Path(f"rosbag2_{dt.datetime.now():%Y_%m_%d-%H_%M_%S}.mcap")
    return Path(name)


_FORMATS_HELP = ".bag = ROS 1 bag, .mcap = MCAP, a folder or .db3 = ROS 2 bag"


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
            "--output",
            "-o",
            "-O",
            help=f"The bag to write ({_FORMATS_HELP}; default rosbag2_DATE_TIME.mcap).",
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
        str | None,
        typer.Option(
            "--compression",
            help="Chunk compression: bz2 or lz4 for .bag (default none, as rosbag), "
            "zstd (default), lz4 or none for .mcap, zstd or none for ROS 2 bags.",
        ),
    ] = None,
    use_sim_time: Annotated[
        bool,
        typer.Option("--use-sim-time", help="Stamp messages with /clock time, not wall time."),
    ] = False,
) -> None:
    """Record topics of the running system to a bag (rosbag record / ros2 bag record).

    SIGINT, SIGTERM and SIGHUP finish the file; chunks are flushed every second, so after
    a kill -9 `roverlab bag recover NAME.bag.part` (or .mcap.part) gets all but the last
    second back.
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
    check_output(path, compression)  # one clear line before joining the network
    with stop_on_signals(threading.Event()) as stop:
        conn = Connection(
            network_options(ctx), clock="external" if use_sim_time else "wall", node=True
        )
        recorder = BagRecorder(
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
    bag: Annotated[Path, typer.Argument(help="A ROS 1 .bag, a .mcap file or a ROS 2 bag folder.")],
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
    with (
        stop_on_signals(threading.Event()) as stop,
        Connection(network_options(ctx), node=True) as conn,
    ):
        player = Player(conn.context, bag, options, warn=lambda line: typer.echo(line, err=True))
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
    src: Annotated[Path, typer.Argument(help="ROS 1 .bag, .mcap or ROS 2 bag (folder / .db3).")],
    dst: Annotated[Path, typer.Argument(help=f"The bag to write: {_FORMATS_HELP}.")],
    compression: Annotated[
        str | None,
        typer.Option(
            "--compression",
            help="bz2 or lz4 for .bag (default none); zstd (default), lz4 or none for .mcap; "
            "zstd or none for ROS 2 bags.",
        ),
    ] = None,
) -> None:
    """Convert a bag into another format, chosen by DST's extension (ros2 bag convert;
    rosbag compress). Every direction: .bag <-> .mcap <-> ROS 2 bag; times are kept."""
    done = convert_bag(src, dst, compression=compression)
    for conn, n in done.skipped:
        typer.echo(
            f"{src}: skipped {n} messages on {conn.topic} [{conn.typename}]: {conn.problem}",
            err=True,
        )
    typer.echo(f"wrote {done.messages} messages to {done.path}")


def _recover(part: Path, output: Path | None) -> None:
    r = recover_bag(part, output)
    typer.echo(
        f"recovered {r.messages} messages in {r.chunks} chunks to {r.path}"
        + (f" ({r.dropped_bytes} bytes of a cut chunk dropped)" if r.dropped_bytes else "")
    )


_RECOVER_INPUT = "The NAME.bag.part / NAME.mcap.part a killed recorder left, or a damaged .bag."
_RECOVER_OUTPUT = "Output file (default NAME.bag / NAME.mcap; NAME.reindexed.bag for a .bag)."


@app.command("recover")
def recover(
    part: Annotated[Path, typer.Argument(help=_RECOVER_INPUT)],
    output: Annotated[Path | None, typer.Option("--output", "-o", help=_RECOVER_OUTPUT)] = None,
) -> None:
    """Write a new readable bag with every whole chunk of a killed or damaged recording
    (rosbag reindex; the input is never changed)."""
    _recover(part, output)


@app.command("reindex")
def reindex(
    part: Annotated[Path, typer.Argument(help=_RECOVER_INPUT)],
    output: Annotated[Path | None, typer.Option("--output", "-o", help=_RECOVER_OUTPUT)] = None,
) -> None:
    """rosbag reindex: the same as `roverlab bag recover` (a new file; the input is kept)."""
    _recover(part, output)
