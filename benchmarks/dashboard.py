"""Dashboard benchmark: frames per second the page renders, and the server's CPU share.

    python benchmarks/dashboard.py [--seconds S] [--map-cells N] [--update-map-every S]

Serves the dashboard for an in-process system publishing a latched N x N OccupancyGrid
(default 2,000 x 2,000), TF (``map -> odom -> base_link -> laser``, the robot driving a
circle) and a 720-beam LaserScan at 10 Hz, opens the page in Debian's chromium (Playwright,
headless, software rendering) and prints:

- frames per second the page renders, counted with ``requestAnimationFrame`` in the browser
  over the window (target >= 30);
- the server's CPU share while one page is connected: CPU time of this process (the
  dashboard plus the tiny publishers) over the wall time of the window, in % of one core;
- bytes the websocket carried per second, and how long the first map took to appear.

With ``--update-map-every S`` the map changes (a 100 x 100 cell window) every S seconds, so
map patches travel too.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
from playwright.sync_api import sync_playwright

from roverlab.core import Context, QoSProfile, Time
from roverlab.geometry import Transform3, quat_from_yaw
from roverlab.msgs import array_to_occupancy_grid, make_scan, stamp_to_msg
from roverlab.tf import StaticTransformBroadcaster, TransformBroadcaster
from roverlab.tf.convert import transform_to_msg
from roverlab.viz import DashboardServer
from roverlab.viz.config import DashboardConfig, DisplayConfig

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
]
RESOLUTION_M = 0.05


def _config() -> DashboardConfig:
    return DashboardConfig(
        fixed_frame="map",
        displays=[
            DisplayConfig("grid", "Grid", True, "", {}),
            DisplayConfig("map", "Map", True, "/map", {}),
            DisplayConfig("laser_scan", "LaserScan", True, "/scan", {}),
            DisplayConfig("tf", "TF", True, "", {}),
        ],
    )


def _system(ctx: Context, cells: int, update_every_s: float | None) -> None:
    node = ctx.create_node("bench_pub")
    rng = np.random.default_rng(0)
    grid = np.zeros((cells, cells), dtype=np.int8)
    grid[rng.random((cells, cells)) < 0.02] = 100
    grid[: cells // 10] = -1
    origin = (-cells * RESOLUTION_M / 2, -cells * RESOLUTION_M / 2, 0.0)
    map_pub = node.create_publisher(
        "nav_msgs/msg/OccupancyGrid", "/map", QoSProfile(depth=1, durability="transient_local")
    )
    map_pub.publish(array_to_occupancy_grid(grid, resolution=RESOLUTION_M, origin=origin))
    static = StaticTransformBroadcaster(node)
    static.send_transform(
        [
            transform_to_msg("map", "odom", Time(0), Transform3()),
            transform_to_msg("base_link", "laser", Time(0), Transform3((0.1, 0.0, 0.2))),
        ]
    )
    tf = TransformBroadcaster(node)
    scan_pub = node.create_publisher("sensor_msgs/msg/LaserScan", "/scan", 5)
    state = {"k": 0}

    def tick() -> None:
        now = ctx.now()
        t = now.nanoseconds * 1e-9
        pose = Transform3(
            (2.0 * math.cos(0.2 * t), 2.0 * math.sin(0.2 * t), 0.0),
            tuple(quat_from_yaw(0.2 * t + math.pi / 2)),
        )
        tf.send_transform(transform_to_msg("odom", "base_link", now, pose))
        ranges = 4.0 + 0.5 * np.sin(np.linspace(0, 12 * np.pi, 720) + t) + rng.normal(0, 0.02, 720)
        scan_pub.publish(
            make_scan(
                ranges,
                angle_min=-math.pi,
                angle_max=math.pi,
                range_min=0.1,
                range_max=12.0,
                stamp=stamp_to_msg(now),
            )
        )
        state["k"] += 1
        if update_every_s and state["k"] % max(1, round(update_every_s * 10)) == 0:
            x0 = int(rng.integers(0, cells - 100))
            grid[x0 : x0 + 100, x0 : x0 + 100] = rng.choice([0, 100], size=(100, 100))
            map_pub.publish(array_to_occupancy_grid(grid, resolution=RESOLUTION_M, origin=origin))

    node.create_timer(0.1, tick)


def _cpu_s() -> float:
    t = os.times()
    return t.user + t.system


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="measuring window")
    ap.add_argument("--map-cells", type=int, default=2000, help="map side, cells")
    ap.add_argument("--update-map-every", type=float, default=None, help="seconds")
    args = ap.parse_args()
    if not CHROMIUM.exists():
        sys.exit("needs /usr/bin/chromium (Debian's chromium package)")
    ctx = Context(clock="wall")
    _system(ctx, args.map_cells, args.update_map_every)
    server = DashboardServer(ctx, "127.0.0.1", 0, config=_config())
    ctx.spin_in_thread()
    server.start()
    pw = sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    try:
        page = browser.new_page(viewport={"width": 1600, "height": 900})
        cdp: Any = page.context.new_cdp_session(page)
        cdp.send("Network.enable")
        received = {"bytes": 0}

        def on_frame(e: dict[str, Any]) -> None:
            data = e["response"]["payloadData"]  # binary frames come base64-encoded
            received["bytes"] += len(data) * 3 // 4 if e["response"]["opcode"] == 2 else len(data)

        cdp.on("Network.webSocketFrameReceived", on_frame)
        t0 = time.monotonic()
        page.goto(server.url)
        page.wait_for_function("() => window.viz && viz.data.map && viz.data.scan", timeout=60000)
        first_map_s = time.monotonic() - t0
        page.evaluate("() => { viz.view.scale = 12; }")  # the whole 100 m map in view
        page.wait_for_timeout(1000)
        received["bytes"] = 0
        cpu0, wall0 = _cpu_s(), time.monotonic()
        frames = page.evaluate(
            """(ms) => new Promise((done) => {
                 let n = 0; const end = performance.now() + ms;
                 function tick(t) {
                   n += 1;
                   if (t < end) requestAnimationFrame(tick); else done(n);
                 }
                 requestAnimationFrame(tick);
               })""",
            args.seconds * 1000,
        )
        wall = time.monotonic() - wall0
        cpu = _cpu_s() - cpu0
        fps = frames / wall
        print(
            f"dashboard benchmark ({platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}, chromium headless, software rendering)"
        )
        print(
            f"  map {args.map_cells} x {args.map_cells} cells, 720-beam scan at 10 Hz, "
            f"robot moving (TF at 10 Hz), window {wall:.1f} s"
        )
        print(f"  first map on the page:      {first_map_s:6.2f} s after page load")
        print(f"  page frame rate:            {fps:6.1f} fps (target >= 30)")
        print(f"  server process CPU:         {100 * cpu / wall:6.1f} % of one core")
        print(f"  websocket traffic:          {received['bytes'] / wall / 1024:6.1f} KiB/s")
    finally:
        browser.close()
        pw.stop()
        server.stop()
        ctx.shutdown()


if __name__ == "__main__":
    main()
