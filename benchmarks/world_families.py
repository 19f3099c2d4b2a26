"""Navigation over the seeded world families of ``roverlab.world.generate``.

    python benchmarks/world_families.py [--worlds 20] [--families barn,corridor,office,clutter]
        [--planners dwa,teb] [--robot mybot] [--localization ground_truth]
        [--workers 1] [--out DIR]

Per family and local planner: ``--worlds`` worlds (seeds 0 .. N-1), each one fixed goal
from the world's start (``roverlab nav bench --start/--goal`` underneath: move_base with
the robot's robot_navigation parameters on the world's map, 0.25 m success radius,
120 s limit, contacts counted and the episode going on). Prints one row per family and
planner against issue 28's targets: >= 98 % of goals, 0 collisions, no goal given up
with 0 m driven. The issue's figure is 300 worlds per family (``--worlds 300``); the
default keeps a run short. Each run's files land in ``--out`` (default: a temporary
folder, printed).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import tempfile
import time
from pathlib import Path

from roverlab.description import find_package
from roverlab.navbench import PARAM_SETS
from roverlab.navbench.fixed import FixedConfig
from roverlab.navbench.suite import run_suite
from roverlab.world.generate import FAMILIES, generate_family


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--worlds", type=int, default=20)
    ap.add_argument("--families", default=",".join(FAMILIES))
    ap.add_argument("--planners", default="dwa,teb")
    ap.add_argument("--robot", default="mybot")
    ap.add_argument("--radius", type=float, default=0.2, help="robot radius for connectivity")
    ap.add_argument("--localization", default="ground_truth")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    logging.getLogger("roverlab").setLevel(logging.ERROR)
    out = args.out or Path(tempfile.mkdtemp(prefix="world_families_"))
    params = find_package("robot_navigation") / "param" / PARAM_SETS[args.robot]
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"{os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}; output in {out}")  # fmt: skip
    print(f"{'family':<10}{'planner':<9}{'worlds':>7}{'success':>9}{'coll.':>7}"
          f"{'0 m':>5}{'s mean':>8}{'ctrl p99':>10}{'x/CPU s':>9}{'wall s':>8}  ok")  # fmt: skip
    for family in args.families.split(","):
        worlds = generate_family(family, args.worlds, robot_radius_m=args.radius)
        folder = out / family / "worlds"
        paths = [w.write(folder) for w in worlds]
        for planner in args.planners.split(","):
            configs = [
                FixedConfig(
                    world=str(p),
                    out=out / family / planner,
                    start=w.start,
                    goal=w.goal,
                    name=w.name,
                    robot=args.robot,
                    planner=planner,
                    localization=args.localization,
                    params_dir=params,
                    goal_tolerance_m=0.25,
                    time_limit_s=120.0,
                    start_move_m=0.0,
                    on_collision="continue",
                )
                for w, p in zip(worlds, paths, strict=True)
            ]
            t0 = time.perf_counter()
            s = run_suite(configs, out / family / planner, workers=args.workers)
            rows = [
                json.loads((out / family / planner / f"{c.name}.json").read_text())
                for c in configs
                if (out / family / planner / f"{c.name}.json").is_file()
            ]
            zero = sum(1 for r in rows if not r["succeeded"] and r["driven_m"] < 0.05)
            collided = sum(1 for r in rows if r["contacts"] > 0)
            rate = s["success_rate"] or 0.0
            ok = rate >= 0.98 and collided == 0 and zero == 0
            print(f"{family:<10}{planner:<9}{s['worlds']:>7}{100 * rate:>8.1f}%{collided:>7}"
                  f"{zero:>5}{s['time_mean_s'] or 0:>8.1f}{s['control_ms_p99_max'] or 0:>10.1f}"
                  f"{s['rtf_per_cpu_s'] or 0:>9.1f}{time.perf_counter() - t0:>8.0f}  "
                  f"{'yes' if ok else 'NO'}")  # fmt: skip


if __name__ == "__main__":
    main()
