"""``roverlab sim``: Gazebo + spawn_model + robot_state_publisher in one command."""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import Annotated

import typer

from roverlab.bag.writers import check_output
from roverlab.cli.common import (
    StartGuard,
    expose_if_asked,
    report_notes,
    report_warnings,
    run_context,
    stop_on_signals,
)
from roverlab.core import Context, configure_logging
from roverlab.description.check import robot_notes, robot_warnings
from roverlab.sim.app import Simulation, SimulationError
from roverlab.sim.node import SpawnPose
from roverlab.world import world_warnings


def parse_rate(text: str) -> float:
    """``max`` (as fast as the CPU allows) or a positive real-time factor."""
    if text.strip().lower() == "max":
        return math.inf
    try:
        rate = float(text)
    except ValueError:
        raise SimulationError(f"--rate must be a positive number or 'max', got {text!r}") from None
    if not (rate > 0 and math.isfinite(rate)):
        raise SimulationError(f"--rate must be a positive number or 'max', got {text!r}")
    return rate


def parse_args(items: list[str] | None) -> dict[str, str]:
    """xacro arguments ``name:=value``."""
    out: dict[str, str] = {}
    for item in items or []:
        name, sep, value = item.partition(":=")
        if not sep or not name:
            raise SimulationError(f"--arg expects name:=value, got {item!r}")
        out[name] = value
    return out


def sim(
    ctx: typer.Context,
    world: Annotated[
        str,
        typer.Option(
            "--world",
            "-w",
            help="Bundled world (maze, office, house, empty) or a .world/.sdf/.yaml file.",
        ),
    ] = "maze",
    robot: Annotated[
        str,
        typer.Option(
            "--robot", "-r", help="Bundled robot (mbot, mybot, mycar) or a URDF/xacro file."
        ),
    ] = "mybot",
    x: Annotated[float, typer.Option("-x", help="Spawn x (m), as spawn_model -x.")] = 0.0,
    y: Annotated[float, typer.Option("-y", help="Spawn y (m), as spawn_model -y.")] = 0.0,
    yaw: Annotated[
        float, typer.Option("-Y", "--yaw", help="Spawn yaw (rad), as spawn_model -Y.")
    ] = 0.0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of every random draw.")] = 0,
    rate: Annotated[
        str,
        typer.Option(
            "--rate",
            help="Sim seconds per wall second: 1 = real time, 'max' = as fast as possible.",
        ),
    ] = "1",
    duration: Annotated[
        float | None, typer.Option("--duration", help="Stop after this many sim seconds.")
    ] = None,
    record: Annotated[
        Path | None,
        typer.Option(
            "--record",
            help="Record every topic to this bag: .bag = ROS 1 bag, .mcap = MCAP, "
            "a folder or .db3 = ROS 2 bag.",
        ),
    ] = None,
    arg: Annotated[
        list[str] | None,
        typer.Option("--arg", help="xacro argument name:=value (repeatable)."),
    ] = None,
    expose: Annotated[
        bool | None,
        typer.Option(
            "--expose/--no-expose",
            help="Make the topics visible to other processes (roverlab topic echo, teleop). "
            "Default: yes, except at --rate max, which runs privately.",
        ),
    ] = None,
    dashboard: Annotated[
        bool,
        typer.Option("--dashboard", help="Serve the web dashboard (rviz) from this process."),
    ] = False,
    dashboard_port: Annotated[
        int | None,
        typer.Option(
            "--dashboard-port",
            help="Port of the --dashboard (127.0.0.1; 0: any free one). Default: "
            "$ROVERLAB_DASHBOARD_PORT, else 8080, or the next free port when it is taken.",
            show_default=False,
        ),
    ] = None,
    strict: Annotated[
        bool,
        typer.Option(
            "--strict",
            help="Make every world and robot warning (a model or mesh not found, an "
            "unsupported element or plugin) an error.",
        ),
    ] = False,
) -> None:
    """Simulate a robot in a world: /cmd_vel in; /odom, /tf, /scan, /imu, cameras, /clock out."""
    pace = parse_rate(rate)
    if record is not None:
        check_output(record)  # an unknown extension is refused before anything runs
    if duration is not None and not (duration > 0 and math.isfinite(duration)):
        raise SimulationError(f"--duration must be a positive number of seconds, got {duration}")
    configure_logging()
    context = Context(
        clock="sim" if math.isinf(pace) else "paced", rate=1.0 if math.isinf(pace) else pace
    )
    # a signal while the world loads stops the run before it starts; the file is still finished
    with stop_on_signals(threading.Event(), context.executor.stop):
        _run(
            ctx,
            context,
            record=record,
            world=world,
            robot=robot,
            spawn=SpawnPose(x, y, yaw),
            seed=seed,
            args=parse_args(arg),
            expose=expose,
            pace=pace,
            rate=rate,
            dashboard=dashboard,
            dashboard_port=dashboard_port,
            duration=duration,
            strict=strict,
        )


def _run(
    ctx: typer.Context,
    context: Context,
    *,
    record: Path | None,
    world: str,
    robot: str,
    spawn: SpawnPose,
    seed: int,
    args: dict[str, str],
    expose: bool | None,
    pace: float,
    rate: str,
    dashboard: bool,
    dashboard_port: int | None,
    duration: float | None,
    strict: bool,
) -> None:
    guard = StartGuard(context)
    with guard:
        if record is not None:
            guard.record(record)
        simulation = Simulation(
            context=context,
            world=world,
            robot=robot,
            spawn=spawn,
            seed=seed,
            robot_args=args,
        )
        report_warnings(
            f"world {simulation.world_model.name}", world_warnings(simulation.world_model), strict
        )
        report_warnings(
            f"robot {simulation.robot_model.name}", robot_warnings(simulation.robot_model), strict
        )
        report_notes([*simulation.world_model.notes, *robot_notes(simulation.robot_model)])
        expose_if_asked(ctx, context, expose, pace)
    recorder = guard.recorder
    cfg = simulation.config
    sensors = [s.topic for s in cfg.lidars] + [s.topic for s in cfg.imus]
    sensors += [c.image_topic for c in cfg.cameras] + [d.points_topic for d in cfg.depth_cameras]
    typer.echo(
        f"simulating {simulation.robot_model.name} in {simulation.world_model.name} "
        f"(rate {rate}, seed {seed}); sensors: {', '.join(sensors) or 'none'}",
        err=True,
    )
    if dashboard:  # the context's shutdown (end of run_context) stops it
        from roverlab.viz.ports import choose_port, start_page
        from roverlab.viz.server import DashboardServer  # FastAPI: only with --dashboard

        try:
            choice = choose_port(dashboard_port, option_name="--dashboard-port")
            server = DashboardServer(context, "127.0.0.1", choice.port)
            start_page(server, choice, say=lambda text: typer.echo(text, err=True))
        except BaseException:
            context.shutdown()
            raise
        typer.echo(f"dashboard: {server.url}", err=True)
    wall = run_context(context, duration)
    sim_s = context.now().seconds
    typer.echo(
        f"simulated {sim_s:.1f} s in {wall:.3g} s wall ({sim_s / max(wall, 1e-9):.1f}x real time)"
        + (f"; recorded {recorder.messages} messages to {record}" if recorder else ""),
        err=True,
    )
