"""Soak: one simulated hour of the whole stack at full speed, watched for leaks and drops.

    python benchmarks/soak.py [--sim-seconds 3600] [--out soak_out] [--no-browser]

What runs, in one process on simulated time (``--rate max``), as ``roverlab demo`` but for
an hour: mybot in seed 003's maze explores with gmapping + move_base + explore_lite, the
map is saved, the robot restarts on it with map_server + amcl + move_base and patrols seed
002's places until the simulated hour is over. All along the web dashboard (rviz's
navigation.rviz) is open in Debian's chromium (headless, Playwright) and every topic is
recorded to ``run.mcap``.

Prints, every simulated 5 minutes, the process's resident memory and chromium's, and at
the end: memory at the start of the patrol (after warm-up: compiled kernels, the maps
allocated) and at the end, with the growth (target < 5 %); messages dropped per topic by
every subscription's queue (target 0 on /cmd_vel and /tf); the stages' results and the
patrol's goals; the recording's message count (read back with rosbags); and page errors.
Exit status 1 when a target is missed.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import sys
import tempfile
import threading
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from roverlab.autonomy.story import DemoStory
from roverlab.bag import BagRecorder
from roverlab.core import Context
from roverlab.description import find_package
from roverlab.viz.config import DisplayConfig, load_rviz
from roverlab.viz.server import DashboardServer

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run"]
GROWTH_TARGET = 0.05
ZERO_DROP_TOPICS = ("/cmd_vel", "/tf")


def _rss_kb(pid: int) -> int:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        pass
    return 0


def _js_heap_mb(cdp: Any) -> float:
    """The page's JavaScript heap after a full garbage collection, MB (0 without a page)."""
    if cdp is None:
        return 0.0
    cdp.send("HeapProfiler.collectGarbage")
    return float(cdp.send("Runtime.getHeapUsage")["usedSize"]) / 2**20


def _descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (chromium's zygote, renderer and GPU processes)."""
    children: dict[int, list[int]] = defaultdict(list)
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children[int(fields[1])].append(int(entry.name))
    out, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            out.append(child)
            todo.append(child)
    return out


class Watcher:
    """Samples memory and per-subscription drops on simulated time, from its own thread."""

    def __init__(self, context: Context, period_s: float) -> None:
        self.context = context
        self.period_s = period_s
        self.samples: list[tuple[float, int, int]] = []  # sim s, own RSS kB, chromium kB
        self.dropped: dict[str, int] = defaultdict(int)  # topic -> drops
        self._seen: dict[int, int] = {}  # id(subscription) -> drops counted
        self._subs: dict[int, Any] = {}
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True, name="soak-watcher")

    def sample(self) -> tuple[float, int, int]:
        me = os.getpid()
        browser = sum(_rss_kb(p) for p in _descendants(me))
        s = (self.context.now().seconds, _rss_kb(me), browser)
        self.samples.append(s)
        self.count_drops()
        return s

    def count_drops(self) -> None:
        for topic in list(self.context.graph.topics.values()):
            for sub in list(topic.subscriptions):
                key = id(sub)
                self._subs[key] = sub  # keeps it alive so that id() stays unique
                new = sub.dropped - self._seen.get(key, 0)
                if new > 0:
                    self.dropped[topic.name] += new
                    self._seen[key] = sub.dropped

    def _run(self) -> None:
        next_t = self.period_s
        while not self.done.is_set():
            self.context.wait_for(
                lambda t=next_t: self.done.is_set() or self.context.now().seconds >= t, None
            )
            if self.done.is_set():
                return
            t, rss, browser = self.sample()
            mb, browser_mb = rss / 1024, browser / 1024
            print(f"  t = {t:6.0f} s sim: roverlab {mb:7.1f} MB, chromium {browser_mb:7.1f} MB")
            next_t += self.period_s


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim-seconds", type=float, default=3600.0, help="simulated time to run")
    ap.add_argument("--out", type=Path, default=None, help="output folder (default: temporary)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-browser", action="store_true", help="no chromium on the dashboard")
    ap.add_argument("--port", type=int, default=8765)
    args = ap.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="roverlab-soak-"))
    out.mkdir(parents=True, exist_ok=True)
    print(f"machine: {os.cpu_count()} cores, {platform.processor() or platform.machine()}, "
          f"Python {platform.python_version()}, load average {os.getloadavg()[0]:.1f}; "
          f"{args.sim_seconds:.0f} s of simulated time, writing {out}/")  # fmt: skip

    context = Context(clock="sim")
    recorder = BagRecorder(out / "run.mcap")
    context.add_transport(recorder)
    config = load_rviz(find_package("robot_navigation") / "rviz" / "navigation.rviz")
    config.displays.append(
        DisplayConfig(kind="marker_array", name="Frontiers", topic="/explore/frontiers")
    )
    server = DashboardServer(context, "127.0.0.1", args.port, config=config, map_dir=out)
    server.start()
    story = DemoStory(
        context, out, places=0, seed=args.seed, explore_limit_s=900.0, goal_timeout_s=120.0,
        log=lambda s: print(f"  {s}", flush=True),
    )  # fmt: skip
    story.start()
    watcher = Watcher(context, 300.0)
    context.spin_in_thread()
    pw = browser = page = cdp = None
    page_errors: list[str] = []
    if not args.no_browser:
        if not CHROMIUM.is_file():
            sys.exit("needs /usr/bin/chromium (Debian's chromium package), or --no-browser")
        from playwright.sync_api import sync_playwright

        pw = sync_playwright().start()
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        page = browser.new_page(viewport={"width": 1280, "height": 800})
        page.on("pageerror", lambda e: page_errors.append(str(e)))
        page.goto(server.url)
        cdp = page.context.new_cdp_session(page)
    t_wall = time.perf_counter()
    start_sample = watcher.sample()
    watcher.thread.start()
    stages: dict[str, str] = {}
    patrol_start: tuple[float, int, int] | None = None
    heap_start = 0.0
    try:
        for name, fn in (
            ("explore", story.explore),
            ("save_map", story.save_map),
            ("restart", story.restart),
        ):
            stages[name] = "ok" if fn() else "failed"
            print(f"  [{name}] {stages[name]} at {context.now().seconds:.0f} s sim", flush=True)
        # the patrol until the simulated hour is over
        until = args.sim_seconds

        def end_patrol() -> None:
            context.wait_for(lambda: context.now().seconds >= until, None)
            story.stop.set()

        ender = threading.Thread(target=end_patrol, daemon=True)
        ender.start()
        context.wait_for(lambda: True, 60.0)  # warm-up of the new stack
        patrol_start = watcher.sample()
        heap_start = _js_heap_mb(cdp)
        story.patrol()
        stages["patrol"] = "ok"
    except Exception as err:  # reported, the figures still printed
        stages[next(s for s in ("explore", "save_map", "restart", "patrol") if s not in stages)] = (
            f"failed: {err}"
        )
    end_sample = watcher.sample()
    heap_end = _js_heap_mb(cdp)
    watcher.done.set()
    wall = time.perf_counter() - t_wall
    story.on_executor(recorder.close)
    report = story.finish()
    if page is not None:
        page_errors += [] if page.evaluate("() => !!window.viz") else ["the page has no viz"]
        assert browser is not None and pw is not None
        browser.close()
        pw.stop()
    server.stop()
    context.shutdown()

    from rosbags.highlevel import AnyReader

    with AnyReader([out / "run.mcap"]) as reader:
        recorded = sum(c.msgcount for c in reader.connections)

    sim = end_sample[0]
    print(f"\nsimulated {sim:.0f} s in {wall:.0f} s wall ({sim / wall:.1f}x real time)")
    base = patrol_start or start_sample
    growth = (end_sample[1] - base[1]) / base[1] if base[1] else 0.0
    b_growth = (end_sample[2] - base[2]) / base[2] if base[2] else 0.0
    print(f"memory, roverlab process: start {start_sample[1] / 1024:.1f} MB, patrol start "
          f"(t = {base[0]:.0f} s) {base[1] / 1024:.1f} MB, end {end_sample[1] / 1024:.1f} MB: "
          f"growth {100 * growth:+.1f} % (target < {100 * GROWTH_TARGET:.0f} %)")  # fmt: skip
    if not args.no_browser:
        print(f"memory, chromium (all its processes): patrol start {base[2] / 1024:.1f} MB, "
              f"end {end_sample[2] / 1024:.1f} MB ({100 * b_growth:+.1f} %); the page's "
              f"JavaScript heap after garbage collection: {heap_start:.1f} MB -> "
              f"{heap_end:.1f} MB")  # fmt: skip
    watcher.count_drops()
    drops = dict(sorted(watcher.dropped.items()))
    print("dropped by subscription queues: "
          + (", ".join(f"{t} {n}" for t, n in drops.items()) or "none"))  # fmt: skip
    size_mb = (out / "run.mcap").stat().st_size / 1e6
    print(f"recording: {recorded} messages in run.mcap ({size_mb:.1f} MB), read back with rosbags")
    print("stages: " + ", ".join(f"{k} {v}" for k, v in stages.items()))
    for line in report.lines()[1:]:
        print(f"  {line}")
    print(f"page errors: {page_errors or 'none'}")
    missed = []
    if growth >= GROWTH_TARGET:
        missed.append("memory growth")
    if any(drops.get(t, 0) for t in ZERO_DROP_TOPICS):
        missed.append("drops on /cmd_vel or /tf")
    if any(v != "ok" for v in stages.values()) or page_errors:
        missed.append("a stage or the page")
    print("result: " + ("all targets met" if not missed else "MISSED: " + ", ".join(missed)))
    if args.out is None:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
