"""``roverlab demo``: the seeds' whole story in one command (what ``make run`` runs)."""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import Annotated

import typer

from roverlab.autonomy.story import DemoStory
from roverlab.bag import BagRecorder
from roverlab.cli.common import StartGuard, expose_if_asked, stop_on_signals
from roverlab.cli.sim import parse_rate
from roverlab.cli.viz import PortOption
from roverlab.core import Context, configure_logging
from roverlab.description import find_package
from roverlab.errors import RoverlabError
from roverlab.viz.config import DisplayConfig, load_rviz
from roverlab.viz.ports import choose_port, start_page
from roverlab.viz.server import DashboardServer


def demo(
    ctx: typer.Context,
    rate: Annotated[
        str,
        typer.Option(
            "--rate",
            help="Sim seconds per wall second: 3 (default) lets you follow it and ends in "
            "about a minute and a half; 1 = real time; 'max' = as fast as the CPU allows.",
        ),
    ] = "3",
    places: Annotated[int, typer.Option("--places", help="Places to patrol.")] = 4,
    seed: Annotated[int, typer.Option("--seed", help="Seed of every random draw.")] = 0,
    out: Annotated[
        Path, typer.Option("--out", "-o", help="Output folder (map, PNGs, statistics, MCAP).")
    ] = Path("demo_out"),
    dashboard: Annotated[
        bool,
        typer.Option(
            "--dashboard/--no-dashboard",
            help="Serve the web dashboard (rviz in the browser) and keep it up after the "
            "report until Ctrl-C; --no-dashboard runs headless and exits after the report.",
        ),
    ] = True,
    port: PortOption = None,
    expose: Annotated[
        bool | None,
        typer.Option(
            "--expose/--no-expose",
            help="Make the topics visible to other terminals (roverlab topic echo ...). "
            "Default: yes, except at --rate max.",
        ),
    ] = None,
    verbose: Annotated[
        bool, typer.Option("--verbose", "-v", help="Show the nodes' log lines (warnings too).")
    ] = False,
) -> None:
    """The seeds' story: mybot explores seed 003's maze (gmapping + move_base +
    explore_lite), saves the map (map_saver), restarts on it (map_server + amcl + move_base),
    patrols places as seed 002's slam.py does, and reports.

    OUT gets map.yaml + map.pgm, map.png (the map and the robot's path), coverage.png,
    patrol.json, report.json and run.mcap (every topic; open it in Foxglove or with
    `roverlab bag`). Exit status 0 when every stage succeeded.
    """
    if places < 1:
        raise RoverlabError(f"--places must be >= 1, got {places}")
    pace = parse_rate(rate)
    configure_logging("INFO" if verbose else "ERROR")
    out.mkdir(parents=True, exist_ok=True)
    context = Context(clock="sim") if math.isinf(pace) else Context(clock="paced", rate=pace)
    recorder = BagRecorder(out / "run.mcap")
    server: DashboardServer | None = None
    with StartGuard(context, recorder):
        context.add_transport(recorder)
        if dashboard:
            config = load_rviz(find_package("robot_navigation") / "rviz" / "navigation.rviz")
            config.displays.append(  # explore_lite's frontiers while it explores
                DisplayConfig(kind="marker_array", name="Frontiers", topic="/explore/frontiers")
            )
            choice = choose_port(port)
            server = DashboardServer(context, "127.0.0.1", choice.port, config=config, map_dir=out)
            start_page(server, choice, say=typer.echo)
            typer.echo(f"dashboard: {server.url}  (open it in a browser)")
        expose_if_asked(ctx, context, expose, pace)
        story = DemoStory(context, out, places=places, seed=seed, log=typer.echo)
        story.start()
    typer.echo(f"roverlab demo: mybot in seed 003's maze, rate {rate}; writing {out}/")
    context.spin_in_thread()
    with stop_on_signals(threading.Event()) as stop:
        story.stop = stop
        try:
            report = story.run()
        finally:
            story.on_executor(recorder.close)  # between two messages
        report.files.append(str(out / "run.mcap"))
        typer.echo("report:")
        for line in report.lines():
            typer.echo(f"  {line}")
        typer.echo(f"  files: {', '.join(Path(f).name for f in report.files)} in {out}/")
        if server is not None and not stop.is_set():
            typer.echo(f"the robot waits in the maze; dashboard still at {server.url}; Ctrl-C ends")
            stop.wait()
    context.shutdown()
    if not report.ok:
        raise typer.Exit(1)
