"""Exploration: `roverlab explore` on every bundled world with each SLAM method.

    python benchmarks/explore.py [--worlds maze,office,house,warehouse,apartment]
                                 [--slam gmapping,graph] [--seed N] [--duration S]
                                 [--json FILE]

One headless episode per (world, SLAM method): mybot, spawn at the world's origin,
robot_navigation's explore.launch (the SLAM node + move_base with the NanoRobot parameters +
explore_lite), as fast as the CPU allows, at most ``--duration`` simulated seconds (900:
issue 14's 15 minutes). Per episode: the share of the world's reachable free area the map
knows at the end and the sim time it first reached 95%, ``slam mapeval``'s share of known
cells correct, contacts with the world, distance, sim time, wall time and the real-time
ratio. `warehouse` and `apartment` are held out: nothing was tuned on them.
Acceptance (issue 14): coverage >= 95% within 900 s, mapeval >= 95%, 0 contacts.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
from pathlib import Path

from roverlab.autonomy.explore_run import ExploreResult, run_explore

HELD_OUT = ("warehouse", "apartment")


def _row(r: ExploreResult) -> str:
    t95 = f"{r.time_to_95_s:5.0f}" if math.isfinite(r.time_to_95_s) else "never"
    ok = r.coverage >= 0.95 and r.time_to_95_s <= 900 and r.accuracy >= 0.95 and not r.contacts
    world = r.world + (" *" if r.world in HELD_OUT else "")
    return (
        f"| {world:<11} | {r.slam:<8} | {100 * r.coverage:6.1f}% | {t95} s | "
        f"{100 * r.accuracy:6.1f}% | {r.contacts:8d} | {r.distance_m:6.1f} m | "
        f"{r.sim_s:5.0f} s | {r.wall_s:6.1f} s | {r.sim_s / max(r.wall_s, 1e-9):5.1f}x | "
        f"{'yes' if ok else 'NO':<4} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worlds", default="maze,office,house,warehouse,apartment")
    ap.add_argument("--slam", default="gmapping,graph")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--duration", type=float, default=900.0)
    ap.add_argument("--json", type=Path, default=None, help="also write the figures here")
    a = ap.parse_args()
    print(f"# explore: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"seed {a.seed}, at most {a.duration:.0f} s sim per episode (* held out)")  # fmt: skip
    print("| world       | SLAM     | known  | 95% at  | mapeval | contacts | distance | "
          "sim     | wall     | rate   | pass |")  # fmt: skip
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    results = []
    for world in a.worlds.split(","):
        for slam in a.slam.split(","):
            r = run_explore(world=world, slam=slam, seed=a.seed, duration_s=a.duration).result
            results.append(r.to_dict())
            print(_row(r), flush=True)
    if a.json is not None:
        tmp = a.json.with_suffix(a.json.suffix + ".part")
        tmp.write_text(json.dumps(results, indent=1) + "\n")
        tmp.replace(a.json)


if __name__ == "__main__":
    main()
