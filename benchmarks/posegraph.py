"""Pose-graph optimisation: wall time to the reference chi2 on the benchmark graphs.

    python benchmarks/posegraph.py [--repeat 3]

Each graph in ../shared/data/posegraphs is optimised from the file's own start with
``roverlab.slam.data.optimize`` (what ``roverlab slam graph`` runs), after one warm-up run;
target: city10000 (10,000 poses, 20,687 edges) <= 1 s. When GTSAM is installed (the
``bench`` extra), its Gauss-Newton optimiser (Levenberg-Marquardt where Gauss-Newton
meets an indeterminate step) runs on the same graphs in the same run, with
the first pose fixed as roverlab fixes it, and the ratio is printed.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

from roverlab.slam.data import read_g2o
from roverlab.slam.data.pose_solver import optimize
from roverlab.slam.data.posegraph import chi2

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "posegraphs"
GRAPHS = {  # file -> reference chi2 (the SE-Sync / g2o papers' optima)
    "input_INTEL_g2o.g2o": 215.83,
    "input_M3500_g2o.g2o": 137.91,
    "sesync_CSAIL.g2o": 40.56,
    "sesync_city10000.g2o": 511.99,
}
TARGET_S = {"sesync_city10000.g2o": 1.0}


def _gtsam_time(path: Path, repeat: int) -> tuple[float, float] | None:
    """GTSAM's Gauss-Newton from the file's start: (median seconds, final chi2 as g2o)."""
    try:
        import gtsam  # type: ignore[import-not-found]
    except ImportError:
        return None
    graph, initial = gtsam.readG2o(str(path), False)
    first = initial.keys()[0]
    graph.add(
        gtsam.PriorFactorPose2(
            first, initial.atPose2(first), gtsam.noiseModel.Isotropic.Sigma(3, 1e-6)
        )
    )
    times = []
    result = initial
    for _ in range(repeat + 1):
        t0 = time.perf_counter()
        try:
            params = gtsam.GaussNewtonParams()
            params.setRelativeErrorTol(1e-9)
            params.setMaxIterations(100)
            result = gtsam.GaussNewtonOptimizer(graph, initial, params).optimize()
        except RuntimeError:  # an indeterminate step from a poor start: its LM instead
            lm = gtsam.LevenbergMarquardtParams()
            lm.setRelativeErrorTol(1e-9)
            lm.setMaxIterations(100)
            result = gtsam.LevenbergMarquardtOptimizer(graph, initial, lm).optimize()
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:]), 2.0 * graph.error(result)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per graph (median)")
    args = ap.parse_args()
    print(
        f"machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
        f"Python {platform.python_version()}, load average {os.getloadavg()[0]:.1f}"
    )
    if not DATA.is_dir():
        print(f"skipped: {DATA} is absent")
        return
    for name, reference in GRAPHS.items():
        path = DATA / name
        graph = read_g2o(path)
        optimize(graph)  # warm-up
        times, final = [], 0.0
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            poses, report = optimize(graph)
            times.append(time.perf_counter() - t0)
            final = chi2(graph, poses)
        median = statistics.median(times)
        target = TARGET_S.get(name)
        verdict = "" if target is None else (" OK" if median <= target else " MISSED")
        line = (
            f"{name}: {graph.num_vertices} poses, {graph.num_edges} edges: "
            f"{median:.3f} s median of {args.repeat} (min {min(times):.3f})"
            f"{'' if target is None else f', target <= {target:.1f} s'}{verdict}; "
            f"chi2 {final:.3f} (reference {reference}), {report.iterations} iterations"
        )
        peer = _gtsam_time(path, args.repeat)
        if peer is not None:
            line += (
                f"; GTSAM {peer[0]:.3f} s, chi2 {peer[1]:.3f} ({median / peer[0]:.2f}x its time)"
            )
        print(line)


if __name__ == "__main__":
    main()
