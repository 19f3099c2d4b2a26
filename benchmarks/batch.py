"""Batch runs on Ray: the same episodes serially and on K workers, their wall times and the
ratio, and a check that every episode's figures are identical.

    python benchmarks/batch.py [--what explore|nav] [--episodes 8] [--workers 2]

Target (issue 14): `nav bench --episodes 8 --workers 2` takes <= 0.65x the serial wall time
on a 2-core machine, with per-episode results identical to `--workers 1`. Each batch runs
through the real command in a fresh process, so Ray's start-up counts.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMANDS = {
    # short episodes of each command; 'nav' needs `roverlab nav bench`
    "explore": ["explore", "--world", "maze", "--slam", "gmapping", "--duration", "120"],
    "nav": ["nav", "bench", "--world", "maze", "--goals", "5", "--quiet"],
}


def run(what: str, episodes: int, workers: int, out: Path) -> tuple[float, list[dict[str, object]]]:
    cmd = [sys.executable, "-m", "roverlab.cli", *COMMANDS[what], "--episodes", str(episodes),
           "--workers", str(workers), "--seed", "0", "--out", str(out)]  # fmt: skip
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t0
    if done.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed: {done.stderr.strip().splitlines()[-1:]}")
    rows = json.loads((out / "episodes.json").read_text())["episodes"]
    return wall, rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--what", choices=sorted(COMMANDS), default="nav")
    ap.add_argument("--episodes", type=int, default=8)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        serial_wall, serial = run(args.what, args.episodes, 1, Path(tmp) / "serial")
        par_wall, par = run(args.what, args.episodes, args.workers, Path(tmp) / "parallel")

    def strip(rows: list[dict[str, object]]) -> list[dict[str, object]]:
        # measured compute and wall times are the only figures allowed to differ
        return [{k: v for k, v in r.items() if "wall" not in k and "_ms" not in k}
                for r in rows]  # fmt: skip

    same = strip(serial) == strip(par)
    walls = [float(r["wall_s"]) for r in serial if isinstance(r.get("wall_s"), (int, float))]
    mean = sum(walls) / max(len(walls), 1)
    ratio = par_wall / serial_wall
    print(f"machine: {os.cpu_count()} cores; {args.what}, {args.episodes} episodes")
    print(f"serial (1 worker, no Ray):  {serial_wall:7.1f} s wall")
    print(f"Ray, {args.workers} workers:           {par_wall:7.1f} s wall")
    print(f"ratio parallel / serial:    {ratio:7.2f}  (target <= 0.65)")
    print(f"per-episode results identical: {'yes' if same else 'NO'}")
    print(f"mean episode cost: {mean:.1f} s on one core; 10,000 episodes: "
          + ", ".join(f"{mean * -(-10_000 // n) / 3600:.1f} h on {n} cores"
                      for n in (16, 64, 256)))  # fmt: skip
    if not same:
        raise SystemExit(1)


if __name__ == "__main__":
    main()
