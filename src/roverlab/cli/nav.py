"""``roverlab nav``: navigation tools; ``roverlab nav bench`` is the navigation benchmark."""

from __future__ import annotations

import logging
import signal
import sys
from pathlib import Path
from typing import Annotated

import typer

from roverlab.cli.apps import command_app
from roverlab.cli.batch import (
    EpisodesOption,
    RayAddressOption,
    WorkersOption,
    absolute,
    is_batch,
    run_episodes,
)
from roverlab.navbench import LOCALIZATIONS, PLANNERS, BenchConfig, run_bench
from roverlab.navbench.batch import PLOT_COLUMNS, nav_episode

__all__ = ["app", "bench"]

app = command_app(
    name="nav",
    help="Navigation (move_base) tools: the benchmark.",
    no_args_is_help=True,
)


@app.command("bench")
def bench(
    out: Annotated[Path, typer.Option("--out", help="Output folder: bench.json, bench.png.")],
    world: Annotated[
        str, typer.Option("--world", help="Bundled world (maze, office, house) or a world file.")
    ] = "maze",
    robot: Annotated[str, typer.Option("--robot", help="Bundled robot or URDF/xacro.")] = "mybot",
    map_yaml: Annotated[
        Path | None,
        typer.Option("--map", help="Map YAML for map_server and amcl (default: from the world)."),
    ] = None,
    planner: Annotated[
        str, typer.Option("--planner", help=f"Local planner: {', '.join(PLANNERS)}.")
    ] = "dwa",
    localization: Annotated[
        str, typer.Option("--localization", help=f"{', '.join(LOCALIZATIONS)}.")
    ] = "amcl",
    goals: Annotated[int, typer.Option("--goals", help="Number of goals.")] = 100,
    seed: Annotated[int, typer.Option("--seed", help="Seed of goals, simulator, amcl.")] = 0,
    goal_timeout: Annotated[
        float | None,
        typer.Option(
            "--goal-timeout",
            help="Per-goal timeout, simulated s (default: 60 + 5 per metre of shortest path).",
        ),
    ] = None,
    params: Annotated[
        Path | None,
        typer.Option("--params", help="Folder of robot_navigation parameter files."),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No per-goal lines.")] = False,
    episodes: EpisodesOption = 1,
    workers: WorkersOption = 1,
    ray_address: RayAddressOption = None,
) -> None:
    """Run simulator + map_server + amcl + move_base on seeded random goals, as fast as
    the CPU allows; print one summary line (per-goal lines go to stderr)."""
    logging.getLogger("roverlab").setLevel(logging.ERROR)
    if is_batch(episodes, workers, ray_address):
        BenchConfig(
            world=world,
            out=out,
            robot=robot,
            map_yaml=map_yaml,
            planner=planner,
            localization=localization,
            goals=goals,
            goal_timeout_s=goal_timeout,
            params_dir=params,
        ).validate()  # bad options: one line before any episode starts
        config: dict[str, object] = {
            "world": absolute(world), "robot": absolute(robot), "planner": planner,
            "localization": localization, "goals": goals, "goal_timeout_s": goal_timeout,
            "map_yaml": str(map_yaml.resolve()) if map_yaml else None,
            "params_dir": str(params.resolve()) if params else None,
        }  # fmt: skip
        run_episodes(
            nav_episode, config, episodes=episodes, seed=seed, workers=workers,
            address=ray_address, out=out, plot=PLOT_COLUMNS,
            title=f"nav bench {Path(world).stem} / {planner}: {episodes} episodes",
        )  # fmt: skip
        return
    report = run_bench(
        BenchConfig(
            world=world, out=out, robot=robot, map_yaml=map_yaml, planner=planner,
            localization=localization, goals=goals, seed=seed, goal_timeout_s=goal_timeout,
            params_dir=params,
        ),
        log=(lambda _l: None) if quiet else (lambda line: print(line, file=sys.stderr)),
    )  # fmt: skip
    print(report.summary_line())
    if report.interrupted:
        raise typer.Exit(128 + signal.Signals[report.interrupted].value)
