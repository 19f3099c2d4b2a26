"""SLAM on simulated buildings with ground truth: hector, gmapping and graph side by side.

    python benchmarks/slam_buildings.py [--buildings corridor loop ...] [--lasers 360 180]
        [--noise low radish] [--methods hector gmapping graph] [--seed 0]

Every building of :mod:`roverlab.slam.simulated` (a 60 m bare corridor, T and X junctions,
a 100 m loop, an open hall) is driven with each laser and odometry noise level; each method
runs with its defaults exactly as ``roverlab slam run`` runs it (hector also with
``use_odometry:=false``: ROS's pure scan matching). Printed per run: the relations metric
(true relative pose of each scan to the scan 1 s later, as ``roverlab slam eval``), the
largest and final distance to the true position (after the first pose, which every
trajectory shares), and wall time. A markdown table follows, for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from roverlab.cli.slam_run import MethodResult, run_gmapping, run_graph, run_hector
from roverlab.slam.data import evaluate
from roverlab.slam.data.errors import SlamError
from roverlab.slam.simulated import (
    BUILDINGS,
    LASERS,
    NOISE_LEVELS,
    SimulatedLog,
    building,
    simulate,
)

METHODS = {
    "hector": lambda log: run_hector(log, {}),
    "hector-pure": lambda log: run_hector(log, {"use_odometry": False}),
    "gmapping": lambda log: run_gmapping(log, {}, seed=0, smooth=True),
    "graph": lambda log: run_graph(log, {}),
}


def one(method: str, sim: SimulatedLog) -> tuple[str, float]:
    """Run ``method`` on a simulated log; return the table cell and the wall time."""
    t0 = time.perf_counter()
    try:
        res: MethodResult = METHODS[method](sim.log)
    except SlamError as err:
        return f"failed: {err}"[:60], time.perf_counter() - t0
    wall = time.perf_counter() - t0
    n = len(res.trajectory)
    err = np.hypot(*(res.trajectory.poses[:, :2] - sim.truth.poses[:n, :2]).T)
    rel = evaluate(res.trajectory, sim.true_relations())
    stopped = "" if n == len(sim.log) else f", stopped at scan {n}"
    return f"{rel.trans_mean:.3f} / {err.max():.2f} / {err[-1]:.2f}{stopped}", wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--buildings", nargs="*", default=list(BUILDINGS))
    ap.add_argument("--lasers", nargs="*", default=["360", "180"])
    ap.add_argument("--noise", nargs="*", default=["low", "radish"])
    ap.add_argument("--methods", nargs="*", default=list(METHODS))
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    rows = []
    for name in args.buildings:
        for laser in args.lasers:
            for noise in args.noise:
                sim = simulate(building(name), laser=LASERS[laser], noise=NOISE_LEVELS[noise],
                               rng=np.random.default_rng(args.seed))  # fmt: skip
                cells = []
                for method in args.methods:
                    cell, wall = one(method, sim)
                    print(f"{name} {laser} {noise} {method}: {cell} ({wall:.1f} s)", flush=True)
                    cells.append(cell)
                rows.append(f"| {name} | {laser} | {noise} | " + " | ".join(cells) + " |")
    print("\n| building | laser | odometry | " + " | ".join(args.methods) + " |")
    print("|---|---|---|" + "---|" * len(args.methods))
    print("\n".join(rows))


if __name__ == "__main__":
    main()
