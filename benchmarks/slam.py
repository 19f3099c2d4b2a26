"""SLAM speed: data duration / wall time per method and log, and peak memory.

    python benchmarks/slam.py [--logs intel fr079]

Each run happens in a fresh child process (so peak memory is that run's own); targets:
graph >= 15x real time on intel, hector >= 20x, gmapping (30 particles) >= 10x. Methods
that have not landed yet are reported as such.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "radish"
TARGETS = {"hector": 20.0, "gmapping": 10.0, "graph": 15.0}


def child(method: str, log: str) -> None:
    """One method on one log with default parameters, exactly as ``roverlab slam run``."""
    from roverlab.cli import slam_run
    from roverlab.slam.data.logs import load_log
    from roverlab.slam.data.reversing import ReversingRepair

    t0 = time.perf_counter()
    records = load_log(log, reversing=ReversingRepair())  # as slam run reads CARMEN logs
    t_load = time.perf_counter() - t0
    runner = getattr(slam_run, f"run_{method}", None)
    if runner is None:
        print(json.dumps({"error": "not available yet"}))
        return
    kwargs: dict[str, object] = {"seed": 0, "smooth": True} if method == "gmapping" else {}
    t1, c1 = time.perf_counter(), time.process_time()
    runner(records, {}, **kwargs)
    t_run, c_run = time.perf_counter() - t1, time.process_time() - c1
    peak_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps({
        "scans": len(records), "duration": float(records.timestamps[-1] - records.timestamps[0]),
        "load_s": t_load, "run_s": t_run, "cpu_s": c_run, "peak_mb": peak_kb / 1024,
    }))  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--logs", nargs="*", default=["intel", "fr079"])
    ap.add_argument("--methods", nargs="*", default=["hector", "gmapping", "graph"])
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(*args.child)
        return
    print(f"machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}")  # fmt: skip
    for log in args.logs:
        path = DATA / f"{log}.clf.bz2"
        if not path.is_file():
            print(f"{log}: {path} is absent; skipped")
            continue
        for method in args.methods:
            out = subprocess.run(
                [sys.executable, __file__, "--child", method, str(path)],
                capture_output=True, text=True, check=False,
            )  # fmt: skip
            try:
                res = json.loads(out.stdout.strip().splitlines()[-1])
            except (IndexError, json.JSONDecodeError):
                print(f"{method} on {log}: failed: {out.stderr.strip().splitlines()[-1:]}")
                continue
            if "error" in res:
                print(f"{method} on {log}: {res['error']}")
                continue
            factor = res["duration"] / res["run_s"]
            per_cpu = res["duration"] / res["cpu_s"]
            print(
                f"{method} on {log}: {res['duration']:.0f} s of data ({res['scans']} scans) in "
                f"{res['run_s']:.1f} s = {factor:.0f}x real time (target >= "
                f"{TARGETS[method]:.0f}x; {per_cpu:.0f}x per CPU second; log reading "
                f"{res['load_s']:.1f} s more); peak memory {res['peak_mb']:.0f} MB"
            )


if __name__ == "__main__":
    main()
