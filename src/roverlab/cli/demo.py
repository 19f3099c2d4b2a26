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
from roverlab.core.transport.daemon import daemon_running, stop_daemon
from roverlab.core.transport.zenoh import ZenohTransport
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
            help="Sim seconds per wall second: 3 (default) lets you follow it; 1 = real "
            "time; 'max' = as fast as the CPU allows. The story is about 200 simulated "
            "seconds (seed 0): at rate 3 no less than 67 s wall. Measured on a 2-core "
            "machine shared with other jobs (load average 10 to 14): rate 3 took 3 to 5 "
            "minutes wall, --rate max 1.5 minutes.",
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
            help="Serve the web dashboard (rviz in the browser) while the story runs; "
            "--no-dashboard runs headless.",
        ),
    ] = True,
    stay: Annotated[
        bool,
        typer.Option(
            "--stay",
            help="After the report keep the dashboard up until Ctrl-C, showing the last "
            "state: the simulation and every node stop, so it takes no CPU beyond "
            "serving the page. Without it the demo ends once its report is written.",
        ),
    ] = False,
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
    `roverlab bag`). The demo ends once its report is written (exit status 0 when every
    stage succeeded), stopping the transport daemon if it started it (as roslaunch stops
    the roscore it started); --stay keeps the dashboard up with the last state.
    """
    if places < 1:
        raise RoverlabError(f"--places must be >= 1, got {places}")
    if stay and not dashboard:
        raise RoverlabError("--stay keeps the dashboard up: it cannot go with --no-dashboard")
    pace = parse_rate(rate)
    configure_logging("INFO" if verbose else "ERROR")
    out.mkdir(parents=True, exist_ok=True)
    context = Context(clock="sim") if math.isinf(pace) else Context(clock="paced", rate=pace)
    recorder = BagRecorder(out / "run.mcap")
    server: DashboardServer | None = None
    daemon_before = daemon_running()
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
        # roslaunch stops the roscore it started: the demo stops the daemon it started
        own_daemon = not daemon_before and daemon_running()
        story = DemoStory(context, out, places=places, seed=seed, log=typer.echo)
        story.start()
    typer.echo(f"roverlab demo: mybot in seed 003's maze, rate {rate}; writing {out}/")
    spinner = context.spin_in_thread()
    try:
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
            if server is not None and stay and not stop.is_set():
                _pause(context, spinner, own_daemon)
                own_daemon = False
                typer.echo(
                    f"the simulation is stopped; the dashboard shows its last state at "
                    f"{server.url}; Ctrl-C ends"
                )
                stop.wait()
    finally:
        context.shutdown()
        if own_daemon:
            stop_daemon()
    if not report.ok:
        raise typer.Exit(1)


def _pause(context: Context, spinner: threading.Thread, own_daemon: bool) -> None:
    """Stop the executor (the simulator, every node's timers) and leave the network, so
    that only the dashboard's web server runs: it serves the last state it received."""
    context.executor.stop()
    spinner.join(timeout=5)
    for transport in [t for t in context.transports if isinstance(t, ZenohTransport)]:
        transport.close()
        context.transports.remove(transport)
    if own_daemon:
        stop_daemon()
