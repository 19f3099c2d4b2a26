"""``roverlab slam``: score trajectories, optimise pose graphs, export odometry.

::

    roverlab slam eval trajectory.tum intel.relations
    roverlab slam graph input_M3500_g2o.g2o --out optimized.g2o
    roverlab slam odometry intel.clf.bz2 --out odometry.tum
    roverlab slam simulate corridor --laser 360 --noise radish --out sim/

Mounted by the root command as ``roverlab slam``. User errors are
:class:`~roverlab.errors.RoverlabError` subclasses, turned into one ``error:`` line and
exit code 2 by :func:`main` (or the root command).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from roverlab.cli.apps import command_app, run_app
from roverlab.slam.data.errors import LogError
from roverlab.slam.data.evaluation import evaluate, read_relations
from roverlab.slam.data.logs import load_log
from roverlab.slam.data.pose_solver import optimize
from roverlab.slam.data.posegraph import chi2, read_g2o, write_g2o
from roverlab.slam.data.trajectory import read_tum, write_tum
from roverlab.slam.simulated import BUILDINGS, LASERS, NOISE_LEVELS, building, simulate, write_log

__all__ = ["app", "eval_command", "graph_command", "main", "odometry_command", "simulate_command"]

app = command_app(
    name="slam",
    help="SLAM data: score trajectories (Kuemmerle metric), optimise g2o pose graphs.",
    no_args_is_help=True,
)


def _print(line: str) -> None:
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


@app.command("eval")
def eval_command(
    trajectory: Annotated[
        Path, typer.Argument(help="TUM trajectory (timestamp x y z qx qy qz qw per line).")
    ],
    relations: Annotated[
        Path, typer.Argument(help="Ground-truth relations (timestamp1 timestamp2 x y z r p y).")
    ],
) -> None:
    """Relative-pose error of a trajectory (Kuemmerle et al. 2009), as the Radish tables."""
    metrics = evaluate(read_tum(trajectory), read_relations(relations))
    for line in metrics.lines():
        _print(line)


@app.command("graph")
def graph_command(
    graph_file: Annotated[Path, typer.Argument(metavar="FILE.g2o", help="2-D g2o pose graph.")],
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Write the optimised graph here (g2o).")
    ] = None,
    init: Annotated[
        str,
        typer.Option(
            "--init",
            help="Start from the file's vertices (none), a chordal solve (chordal) or the "
            "chained odometry edges (odometry).",
        ),
    ] = "none",
    method: Annotated[
        str,
        typer.Option(
            "--method", help="auto (Gauss-Newton, falling back to LM) or levenberg-marquardt."
        ),
    ] = "auto",
    max_iterations: Annotated[
        int, typer.Option("--max-iterations", min=0, help="Most linear solves.")
    ] = 100,
    tolerance: Annotated[
        float, typer.Option("--tolerance", help="Stop when chi2 changes by less (relative).")
    ] = 1e-9,
) -> None:
    """Optimise a g2o pose graph (first vertex fixed); print chi2 before and after."""
    t0 = time.perf_counter()
    graph = read_g2o(graph_file)
    read_s = time.perf_counter() - t0
    start = "vertices" if graph.vertices_given else "chained odometry edges"
    _print(
        f"graph: {graph.num_vertices} vertices, {graph.num_edges} edges "
        f"(read in {read_s:.2f} s, start: {start})"
    )
    _print(f"initial chi2: {chi2(graph):.4f}")
    poses, report = optimize(
        graph,
        max_iterations=max_iterations,
        tolerance=tolerance,
        init=init,  # type: ignore[arg-type]  # validated by optimize
        method=method,  # type: ignore[arg-type]
    )
    if init != "none":
        _print(f"chi2 after {init} initialisation: {report.initial_chi2:.4f}")
    _print(f"final chi2: {report.final_chi2:.4f}")
    _print(
        f"iterations: {report.iterations} ({report.gauss_newton_steps} Gauss-Newton), "
        f"{report.reason}"
    )
    _print(f"time: {report.time_s:.2f} s")
    if out is not None:
        write_g2o(out, graph, poses)
        _print(f"wrote {out}")


@app.command("odometry")
def odometry_command(
    log: Annotated[Path, typer.Argument(help="Laser log: CARMEN .clf[.gz|.bz2], .bag, .mcap.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="TUM file to write.")],
    frame: Annotated[
        str, typer.Option("--frame", help="Poses of the robot (base) or of the laser.")
    ] = "robot",
) -> None:
    """Write the raw odometry pose of every scan of a log as a TUM trajectory."""
    if frame not in ("robot", "laser"):
        raise LogError(f"unknown --frame {frame!r} (robot or laser)")
    laser_log = load_log(log)
    write_tum(out, laser_log.odometry(frame=frame))
    _print(f"wrote {len(laser_log)} poses to {out}")


@app.command("simulate")
def simulate_command(
    name: Annotated[str, typer.Argument(help=f"Building: {', '.join(BUILDINGS)}.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Folder to write into.")] = Path("."),
    length: Annotated[
        float | None,
        typer.Option(
            "--length", help="Corridor length, loop length or hall width (m); default per building."
        ),
    ] = None,
    laser: Annotated[
        str, typer.Option("--laser", help="180 (SICK-like, 30 m) or 360 (12 m lidar).")
    ] = "360",
    noise: Annotated[
        str,
        typer.Option("--noise", help=f"Odometry noise: {', '.join(NOISE_LEVELS)}."),
    ] = "radish",
    seed: Annotated[int, typer.Option("--seed", help="Seed of the noise draws.")] = 0,
) -> None:
    """Simulate a robot in a building: NAME.clf (CARMEN), NAME.relations, NAME.gt.tum.

    ``roverlab slam run NAME.clf`` maps it; ``roverlab slam eval trajectory.tum
    NAME.relations`` scores the result against the ground truth.
    """
    if laser not in LASERS:
        raise LogError(f"unknown --laser {laser!r} ({', '.join(LASERS)})")
    if noise not in NOISE_LEVELS:
        raise LogError(f"unknown --noise {noise!r} ({', '.join(NOISE_LEVELS)})")
    sim = simulate(
        building(name, length),
        laser=LASERS[laser],
        noise=NOISE_LEVELS[noise],
        rng=np.random.default_rng(seed),
    )
    paths = write_log(sim, out, f"{name}_{laser}_{noise}")
    _print(f"{len(sim.log)} scans: wrote {', '.join(str(p) for p in paths)}")


def main(argv: list[str] | None = None) -> None:
    """``roverlab slam``: user errors become one line on stderr and exit code 2."""
    run_app(app, argv, "roverlab slam")
