"""``roverlab explore``: a robot maps a world on its own (explore_lite), headless."""

from __future__ import annotations

import math
import threading
from pathlib import Path
from typing import Annotated

import typer

from roverlab.autonomy.explore_batch import PLOT_COLUMNS, explore_episode
from roverlab.autonomy.explore_run import run_explore, write_explore_outputs
from roverlab.autonomy.stack import SLAM_METHODS, AutonomyError
from roverlab.cli.batch import (
    EpisodesOption,
    RayAddressOption,
    WorkersOption,
    absolute,
    is_batch,
    run_episodes,
)
from roverlab.cli.common import stop_on_signals
from roverlab.cli.sim import parse_rate
from roverlab.core import configure_logging
from roverlab.sim.node import SpawnPose


def explore(
    world: Annotated[
        str,
        typer.Option(
            "--world",
            "-w",
            help="Bundled world (maze, office, house) or a .world/.sdf/.yaml file.",
        ),
    ] = "maze",
    robot: Annotated[
        str,
        typer.Option("--robot", "-r", help="Bundled robot (mybot, mbot) or a URDF/xacro file."),
    ] = "mybot",
    slam: Annotated[
        str, typer.Option("--slam", help="The SLAM node: gmapping, hector or graph.")
    ] = "gmapping",
    duration: Annotated[
        float, typer.Option("--duration", help="Stop after this many simulated seconds.")
    ] = 900.0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of every random draw.")] = 0,
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder.")] = Path("explore_out"),
    rate: Annotated[
        str,
        typer.Option("--rate", help="Sim seconds per wall second; 'max': as fast as possible."),
    ] = "max",
    x: Annotated[float, typer.Option("-x", help="Spawn x (m).")] = 0.0,
    y: Annotated[float, typer.Option("-y", help="Spawn y (m).")] = 0.0,
    yaw: Annotated[float, typer.Option("-Y", "--yaw", help="Spawn yaw (rad).")] = 0.0,
    episodes: EpisodesOption = 1,
    workers: WorkersOption = 1,
    ray_address: RayAddressOption = None,
) -> None:
    """Explore a world with explore_lite + move_base + a SLAM node, then score the map.

    Writes OUT/map.yaml + map.pgm (as map_saver), map.png (the map with the robot's true
    path), coverage.png (known share of the reachable free area over time) and
    summary.json; prints one summary line. Ctrl-C (or SIGTERM/SIGHUP) ends the episode
    early and still writes everything.
    """
    if slam not in SLAM_METHODS:
        raise AutonomyError(f"unknown --slam {slam!r} (one of {', '.join(SLAM_METHODS)})")
    if not (duration > 0 and math.isfinite(duration)):
        raise AutonomyError(f"--duration must be a positive number of seconds, got {duration}")
    if out.exists() and not out.is_dir():
        raise AutonomyError(f"--out {out}: not a folder")
    pace = parse_rate(rate)
    configure_logging()
    if is_batch(episodes, workers, ray_address):
        if not math.isinf(pace):
            raise AutonomyError("--episodes/--workers run at --rate max only")
        config = {
            "world": absolute(world), "robot": absolute(robot), "slam": slam,
            "duration_s": duration,
            "spawn": [x, y, yaw],
        }  # fmt: skip
        run_episodes(
            explore_episode, config, episodes=episodes, seed=seed, workers=workers,
            address=ray_address, out=out, plot=PLOT_COLUMNS,
            title=f"explore {Path(world).stem} / {slam}: {episodes} episodes",
        )  # fmt: skip
        return
    with stop_on_signals(threading.Event()) as stop:
        episode = run_explore(
            world=world, robot=robot, slam=slam, seed=seed, duration_s=duration, rate=pace,
            spawn=SpawnPose(x, y, yaw), stop=stop,
        )  # fmt: skip
        written = write_explore_outputs(episode, out)
    typer.echo(episode.result.summary())
    typer.echo(f"wrote {', '.join(str(p) for p in written)}", err=True)
