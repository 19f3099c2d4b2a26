"""``roverlab nav``: navigation tools; ``roverlab nav bench`` is the navigation benchmark."""

from __future__ import annotations

import logging
import signal
import sys
import threading
from dataclasses import replace
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
from roverlab.cli.common import stop_on_signals
from roverlab.navbench import LOCALIZATIONS, PARAM_SETS, PLANNERS, BenchConfig, run_bench
from roverlab.navbench.batch import PLOT_COLUMNS, nav_episode
from roverlab.navbench.fixed import FixedConfig
from roverlab.navbench.harness import BenchError
from roverlab.navbench.suite import SUITES, barn_configs, run_suite

__all__ = ["app", "bench"]

app = command_app(
    name="nav",
    help="Navigation (move_base) tools: the benchmark.",
    no_args_is_help=True,
)


def _pose(
    text: str | None, option: str, *, yaw_required: bool
) -> tuple[float, float, float] | None:
    """``X,Y[,YAW]`` -> floats (yaw 0 when left out and not required)."""
    if text is None:
        return None
    parts = text.split(",")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        vals = ()
    if len(vals) not in ((3,) if yaw_required else (2, 3)):
        form = "X,Y,YAW" if yaw_required else "X,Y[,YAW]"
        raise BenchError(f"{option} must be {form} (numbers), got {text!r}")
    return (vals[0], vals[1], vals[2] if len(vals) == 3 else 0.0)


def _world_files(worlds: list[str]) -> list[str]:
    """``--worlds`` values: folders (every .world / .sdf / .yaml in them, by name) or
    files."""
    out: list[str] = []
    for w in worlds:
        p = Path(w)
        if p.is_dir():
            found = sorted(
                (q for q in p.iterdir() if q.suffix in (".world", ".sdf", ".yaml")),
                key=lambda q: (len(q.stem), q.stem),
            )
            if not found:
                raise BenchError(f"{p}: no .world, .sdf or .yaml files")
            out += [str(q) for q in found]
        else:
            out.append(w)
    return out


def _fixed(
    *,
    out: Path,
    worlds: list[str],
    suite: str | None,
    robot: str | None,
    planner: str,
    localization: str | None,
    seed: int,
    params: Path | None,
    launch: Path | None,
    start: str | None,
    goal: str | None,
    goal_tolerance: float | None,
    time_limit: float | None,
    on_collision: str,
    max_speed: float | None,
    max_worlds: int | None,
    workers: int,
    ray_address: str | None,
    quiet: bool,
) -> None:
    """The fixed start -> goal mode: a suite, or --start/--goal over --worlds."""
    loc = (localization or ("odom" if suite else "amcl")).replace("-", "_")
    if suite is not None and suite not in SUITES:
        raise BenchError(f"unknown suite {suite!r}: use {', '.join(SUITES)}")
    if suite is not None and len(worlds) != 1:
        raise BenchError("--suite barn needs --worlds DIR (the folder of world_N.world)")
    bot = robot or ("jackal" if suite else "mybot")
    if params is None and suite is None and bot in PARAM_SETS and loc != "odom":
        from roverlab.description import find_package

        params = find_package("robot_navigation") / "param" / PARAM_SETS[bot]
    base = FixedConfig(
        world="", out=out, start=(0.0, 0.0, 0.0), goal=(0.0, 0.0, 0.0), robot=bot,
        planner=planner, localization=loc, params_dir=params, launch=launch,
        max_speed=max_speed, on_collision=on_collision, seed=seed,
    )  # fmt: skip
    if suite == "barn":
        configs = barn_configs(Path(worlds[0]), base, only=max_worlds)
        if localization is not None and loc != "odom":
            raise BenchError("--suite barn runs on odometry alone (no --localization)")
    else:
        p0 = _pose(start, "--start", yaw_required=True)
        p1 = _pose(goal, "--goal", yaw_required=False)
        if p0 is None or p1 is None:
            raise BenchError("--start and --goal are needed without --suite")
        files = _world_files(worlds)[:max_worlds]
        names = [Path(w).stem for w in files]
        if len(set(names)) != len(names):
            names = [f"{i:03d}_{n}" for i, n in enumerate(names)]
        configs = [
            replace(base, world=w, name=n, start=p0, goal=p1, goal_tolerance_m=1.0)
            for w, n in zip(files, names, strict=True)
        ]
    overrides: dict[str, float] = {}
    if goal_tolerance is not None:
        overrides["goal_tolerance_m"] = goal_tolerance
    if time_limit is not None:
        overrides["time_limit_s"] = time_limit
    if overrides:
        configs = [replace(c, **overrides) for c in configs]  # type: ignore[arg-type]
    with stop_on_signals(threading.Event()) as stop:
        summary = run_suite(
            configs, out, workers=workers, address=ray_address, stop=stop,
            log=(lambda _l: None) if quiet else (lambda line: print(line, file=sys.stderr)),
            extra={"suite": suite},
        )  # fmt: skip

    print(
        f"{summary['worlds']} worlds"
        + (f" ({summary['errors']} failed to run)" if summary["errors"] else "")
        + f", {planner}: success {percent(summary['success_rate'])}, "
        f"collisions {percent(summary['collision_rate'])}, "
        f"timeouts {percent(summary['timeout_rate'])}"
        + (f", score {summary['score_mean']:.3f}" if summary["score_mean"] is not None else "")
        + (f", control p99 max {summary['control_ms_p99_max']:.1f} ms"
           if summary["control_ms_p99_max"] is not None else "")
        + (f", {summary['rtf_per_cpu_s']:.1f}x real time per CPU s"
           if summary["rtf_per_cpu_s"] is not None else "")
        + f"; {out / 'summary.json'}"
    )  # fmt: skip
    if stop.is_set():
        raise typer.Exit(130)


def percent(v: float | None) -> str:
    """A rate as a percentage to 0.1, never rounded to 0 % or 100 % unless it is exactly
    that (one failed world in 250 is not "100 %")."""
    if v is None:
        return "-"
    p = 100.0 * v
    if 0.0 < p < 0.05:
        return "<0.1 %"
    if 99.95 <= p < 100.0:
        return ">99.9 %"
    return f"{p:.1f} %"


@app.command("bench")
def bench(
    out: Annotated[Path, typer.Option("--out", help="Output folder: bench.json, bench.png.")],
    world: Annotated[
        str, typer.Option("--world", help="Bundled world (maze, office, house) or a world file.")
    ] = "maze",
    robot: Annotated[
        str | None,
        typer.Option("--robot", help="Bundled robot (mybot; jackal for --suite) or URDF/xacro."),
    ] = None,
    map_yaml: Annotated[
        Path | None,
        typer.Option("--map", help="Map YAML for map_server and amcl (default: from the world)."),
    ] = None,
    planner: Annotated[
        str, typer.Option("--planner", help=f"Local planner: {', '.join(PLANNERS)}.")
    ] = "dwa",
    localization: Annotated[
        str | None,
        typer.Option(
            "--localization",
            help="amcl (default), ground-truth, or odom (no map: costmaps from the laser; "
            "--start/--goal and --suite only; the suite's default).",
        ),
    ] = None,
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
    suite: Annotated[
        str | None,
        typer.Option("--suite", help="A published benchmark: barn (BARN's run.py rules)."),
    ] = None,
    worlds: Annotated[
        list[str] | None,
        typer.Option(
            "--worlds",
            help="Worlds of a fixed-goal run: a folder (BARN's worlds for --suite barn) or "
            "files; repeatable.",
        ),
    ] = None,
    start: Annotated[
        str | None, typer.Option("--start", help="Start pose X,Y,YAW in the world.")
    ] = None,
    goal: Annotated[
        str | None, typer.Option("--goal", help="Goal X,Y[,YAW] in the world (one goal).")
    ] = None,
    goal_tolerance: Annotated[
        float | None,
        typer.Option(
            "--goal-tolerance",
            help="Success radius of a fixed goal, m (true position; default 1.0; random "
            "goals count 0.25).",
        ),
    ] = None,
    time_limit: Annotated[
        float | None,
        typer.Option(
            "--time-limit",
            help="Per-goal limit, simulated s (fixed goals: from the first 0.1 m; default "
            "100 s); random goals: as --goal-timeout.",
        ),
    ] = None,
    on_collision: Annotated[
        str,
        typer.Option(
            "--on-collision", help="end (a contact ends a fixed-goal episode) or continue."
        ),
    ] = "end",
    max_speed: Annotated[
        float | None,
        typer.Option("--max-speed", help="The local planner's max_vel_x, m/s (fixed goals)."),
    ] = None,
    launch: Annotated[
        Path | None,
        typer.Option(
            "--launch",
            help="Your launch file starting move_base (fixed goals; gets param_dir, planner, "
            "odom_topic, cmd_vel_topic, max_speed as args).",
        ),
    ] = None,
    max_worlds: Annotated[
        int | None, typer.Option("--max-worlds", help="Run only the first N worlds.")
    ] = None,
    episodes: EpisodesOption = 1,
    workers: WorkersOption = 1,
    ray_address: RayAddressOption = None,
) -> None:
    """Run simulator + map_server + amcl + move_base on seeded random goals, as fast as
    the CPU allows; print one summary line (per-goal lines go to stderr).

    With --start/--goal (or --suite barn --worlds DIR): one fixed goal per world, as
    published benchmarks run it; per world NAME.json/.csv/.png and summary.json."""
    logging.getLogger("roverlab").setLevel(logging.ERROR)
    if suite is not None or worlds or start is not None or goal is not None:
        if episodes != 1:
            raise BenchError("--episodes is for random goals; fixed goals run once per world")
        _fixed(
            out=out, worlds=list(worlds or [world]), suite=suite, robot=robot,
            planner=planner, localization=localization, seed=seed, params=params,
            launch=launch, start=start, goal=goal, goal_tolerance=goal_tolerance,
            time_limit=time_limit, on_collision=on_collision, max_speed=max_speed,
            max_worlds=max_worlds, workers=workers, ray_address=ray_address, quiet=quiet,
        )  # fmt: skip
        return
    if goal_tolerance is not None:
        raise BenchError("--goal-tolerance is for fixed goals (--start/--goal, --suite)")
    robot = robot or "mybot"
    localization = (localization or "amcl").replace("-", "_")
    if localization not in LOCALIZATIONS:
        raise BenchError(
            f"unknown localization {localization!r}: use {' or '.join(LOCALIZATIONS)} "
            "(odom: with --start/--goal or --suite)"
        )
    goal_timeout = goal_timeout if time_limit is None else time_limit
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
