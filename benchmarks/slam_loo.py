"""Graph SLAM's loop-closure and scan-matching choices, checked leave-one-out.

    python benchmarks/slam_loo.py [--configs default smear-0.05 ...] [--sets intel fr079
        mit-csail sim] [--jobs 2] [--cache FILE]

Every candidate setting (:data:`CONFIGS`: the shipped defaults and one change each to
the loop closing or the scan matcher) maps every set exactly as ``roverlab slam run
--method graph`` does:

* ``intel``, ``fr079``: the whole Radish log, scored with the relations metric (m);
* ``mit-csail``: the whole log (no relations), scored by its corridors' straightness
  (:mod:`roverlab.slam.data.straightness`: the largest angle between two stretches of its
  long corridor and the corridors crossing it, modulo 90 degrees; above
  :data:`BEND_TOLERANCE_DEG` the map is bent);
* ``sim``: the simulated buildings of :data:`SIM_LOGS` (``roverlab slam simulate``), the
  mean of their relations metric against the simulator's ground truth (m).

Leave-one-out: for each set, the setting is chosen on the other three (the lowest mean
of each set's error relative to the shipped defaults' on it; a setting that bends
mit-csail's map is not eligible while mit-csail is among them) and scored on the held-out
set. Results are cached per (setting, set) in ``--cache``, so a run can be resumed or
extended (default: ``roverlab_slam_loo.json`` in the temporary directory). Prints one
line per run and the markdown tables for docs/slam.md. A full run (the six settings
of docs/slam.md) took about an hour on the shared 2-core machine with ``--jobs 2``.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from roverlab.cli.slam_run import run_graph
from roverlab.slam.data import evaluate, load_log, read_relations
from roverlab.slam.data.reversing import ReversingRepair
from roverlab.slam.data.straightness import STRAIGHT_CORRIDORS, straightness
from roverlab.slam.data.trajectory import Trajectory
from roverlab.slam.simulated import LASERS, NOISE_LEVELS, building, simulate

RADISH = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "radish"
#: mit-csail's map counts as bent above this (three independent methods: 4.6-5.0).
BEND_TOLERANCE_DEG = 8.0
#: (building, laser, odometry noise, seed): corridors, junctions, a loop, both lasers.
SIM_LOGS = (
    ("corridor", "360", "radish", 0),
    ("t_junction", "180", "radish", 0),
    ("x_junction", "360", "radish", 0),
    ("loop", "180", "low", 0),
)
#: Candidate settings: the shipped defaults and one change each.
CONFIGS: dict[str, dict[str, object]] = {
    "default": {},
    "smear-0.05": {"correlation_search_space_smear_deviation": 0.05},
    "karto-corridors": {"degenerate_eigen_ratio": 0.0},
    "loop-distance-6": {"loop_search_maximum_distance": 6.0},
    "no-residual-check": {"loop_closure_max_residual": 0.0},
    "loop-chain-5": {"loop_match_minimum_chain_size": 5},
}
SETS = ("intel", "fr079", "mit-csail", "sim")


def score(config: str, name: str) -> dict[str, float]:
    """Run one setting on one set; return its score and wall time."""
    params = CONFIGS[config]
    t0 = time.perf_counter()
    if name == "sim":
        errs = []
        for b, laser, noise, seed in SIM_LOGS:
            sim = simulate(building(b), laser=LASERS[laser], noise=NOISE_LEVELS[noise],
                           rng=np.random.default_rng(seed))  # fmt: skip
            res = run_graph(sim.log, dict(params))
            errs.append(evaluate(res.trajectory, sim.true_relations()).trans_mean)
        value = float(np.mean(errs))
    else:
        log = load_log(RADISH / f"{name}.clf.bz2", reversing=ReversingRepair())
        res = run_graph(log, dict(params))
        if name == "mit-csail":
            value = straightness(log, res.poses, STRAIGHT_CORRIDORS[name]).bend_deg
        else:
            rel = read_relations(RADISH / f"{name}.relations")
            traj = Trajectory.from_poses(list(log.timestamp_texts), res.poses)
            value = evaluate(traj, rel).trans_mean
    return {"value": value, "wall_s": time.perf_counter() - t0}


def _choose(results: dict[str, dict[str, dict[str, float]]], held: str) -> str:
    """The setting chosen on every set but ``held``."""
    best, best_cost = "default", float("inf")
    for config, by_set in results.items():
        if any(s not in by_set for s in SETS if s != held):
            continue
        if held != "mit-csail" and by_set["mit-csail"]["value"] > BEND_TOLERANCE_DEG:
            continue
        rel = [
            by_set[s]["value"] / results["default"][s]["value"]
            for s in SETS
            if s not in (held, "mit-csail")
        ]
        cost = float(np.mean(rel))
        if cost < best_cost - 1e-12:
            best, best_cost = config, cost
    return best


def _fmt(name: str, value: float) -> str:
    if name == "mit-csail":
        bent = "bent" if value > BEND_TOLERANCE_DEG else "straight"
        return f"{value:.1f} deg ({bent})"
    return f"{value:.4f} m"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--configs", nargs="*", default=list(CONFIGS))
    ap.add_argument("--sets", nargs="*", default=list(SETS))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument(
        "--cache", type=Path, default=Path(tempfile.gettempdir()) / "roverlab_slam_loo.json"
    )
    args = ap.parse_args()
    results: dict[str, dict[str, dict[str, float]]] = {}
    if args.cache.is_file():
        results = json.loads(args.cache.read_text())
    todo = [(c, s) for c in args.configs for s in args.sets if s not in results.get(c, {})]
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = {pool.submit(score, c, s): (c, s) for c, s in todo}
        for fut, (c, s) in futures.items():
            out = fut.result()
            results.setdefault(c, {})[s] = out
            print(f"{c} {s}: {_fmt(s, out['value'])} ({out['wall_s']:.0f} s)", flush=True)
            args.cache.parent.mkdir(parents=True, exist_ok=True)
            tmp = args.cache.with_suffix(".tmp")
            tmp.write_text(json.dumps(results, indent=1))
            tmp.replace(args.cache)
    print("\n| setting | " + " | ".join(SETS) + " |")
    print("|---|" + "---|" * len(SETS))
    for c, by_set in results.items():
        cells = [_fmt(s, by_set[s]["value"]) if s in by_set else "-" for s in SETS]
        print(f"| {c} | " + " | ".join(cells) + " |")
    if not all(s in results.get("default", {}) for s in SETS):
        return
    print("\n| held out | chosen on the other three | held-out score | shipped default |")
    print("|---|---|---|---|")
    for held in SETS:
        chosen = _choose(results, held)
        print(f"| {held} | {chosen} | {_fmt(held, results[chosen][held]['value'])} | "
              f"{_fmt(held, results['default'][held]['value'])} |")  # fmt: skip


if __name__ == "__main__":
    main()
