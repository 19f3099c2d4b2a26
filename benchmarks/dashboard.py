"""Dashboard benchmark: frames per second the page renders, and the server's CPU share.

    python benchmarks/dashboard.py [--seconds S] [--map-cells N] [--update-map-every S]
                                   [--view 3d|2d|both] [--cloud-max-points N]

Serves the dashboard for an in-process system publishing a latched N x N OccupancyGrid
(default 2,000 x 2,000), TF (``map -> odom -> base_link -> laser``, the robot driving a
circle), a 720-beam LaserScan at 10 Hz and a 640 x 480 depth PointCloud2 at 10 Hz (a
curved wall in front of the robot, AxisColor; the display's Max Points decimates it on the
server, 20,000 by default), opens the page in Debian's chromium (Playwright, headless,
software rendering), in the 3D view (rviz's Orbit, three.js / WebGL on SwiftShader) and in
the 2D view, and prints for each (the 3D view twice: with its adaptive resolution, which
lowers the drawing-buffer resolution down to half per axis while the frame rate is below 28,
and at fixed full resolution):

- frames per second the page renders when made to redraw every animation frame, with no
  Frame Rate cap (``viz.redraw.continuous``, ``maxFps = Infinity``): the render speed,
  counted as frames drawn (the views' own counters) over the window (target >= 30);
- frames drawn per second as the page is used (it draws only when something changed, at most
  rviz's Frame Rate, 30) with the data streaming, and with the publishers paused (idle: none),
  and chromium's CPU share in both (all processes below this one: the browser and
  Playwright's driver);
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
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
from playwright.sync_api import sync_playwright

from roverlab.core import Context, QoSProfile, Time
from roverlab.geometry import Transform3, quat_from_yaw
from roverlab.msgs import array_to_occupancy_grid, make_scan, stamp_to_msg, xyz_to_pointcloud2
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


def _config(cloud_max_points: int) -> DashboardConfig:
    return DashboardConfig(
        fixed_frame="map",
        displays=[
            DisplayConfig("grid", "Grid", True, "", {}),
            DisplayConfig("map", "Map", True, "/map", {}),
            DisplayConfig("laser_scan", "LaserScan", True, "/scan", {}),
            DisplayConfig(
                "point_cloud2", "Depth", True, "/depth/points", {"max_points": cloud_max_points}
            ),
            DisplayConfig("tf", "TF", True, "", {}),
        ],
    )


def _depth_cloud() -> np.ndarray:
    """A 640 x 480 depth camera's cloud (optical frame: z forward) of a curved wall."""
    u, v = np.meshgrid(np.arange(640), np.arange(480))
    fx = 525.0
    z = 3.0 + 0.5 * np.sin(u / 80.0)
    x, y = (u - 319.5) / fx * z, (v - 239.5) / fx * z
    return np.column_stack((x.ravel(), y.ravel(), z.ravel())).astype(np.float32)


def _system(
    ctx: Context, cells: int, update_every_s: float | None, paused: threading.Event
) -> None:
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
            transform_to_msg(  # optical frame: z forward, x right, y down
                "base_link",
                "camera_depth",
                Time(0),
                Transform3((0.1, 0.0, 0.4), (-0.5, 0.5, -0.5, 0.5)),
            ),
        ]
    )
    cloud_pub = node.create_publisher("sensor_msgs/msg/PointCloud2", "/depth/points", 2)
    cloud = _depth_cloud()
    tf = TransformBroadcaster(node)
    scan_pub = node.create_publisher("sensor_msgs/msg/LaserScan", "/scan", 5)
    state = {"k": 0}

    def tick() -> None:
        if paused.is_set():
            return
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
        cloud_pub.publish(xyz_to_pointcloud2(cloud, "camera_depth", stamp_to_msg(now)))
        state["k"] += 1
        if update_every_s and state["k"] % max(1, round(update_every_s * 10)) == 0:
            x0 = int(rng.integers(0, cells - 100))
            grid[x0 : x0 + 100, x0 : x0 + 100] = rng.choice([0, 100], size=(100, 100))
            map_pub.publish(array_to_occupancy_grid(grid, resolution=RESOLUTION_M, origin=origin))

    node.create_timer(0.1, tick)


def _cpu_s() -> float:
    t = os.times()
    return t.user + t.system


def _descendants_cpu_s() -> float:
    """CPU seconds (user + system) of the processes below this one (chromium, Playwright's
    driver), from /proc; NaN where there is no /proc."""
    tick = os.sysconf("SC_CLK_TCK")
    parent: dict[int, int] = {}
    cpu: dict[int, float] = {}
    try:
        entries = [d for d in Path("/proc").iterdir() if d.name.isdigit()]
    except OSError:
        return math.nan
    for d in entries:
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        parent[int(d.name)] = int(fields[1])
        cpu[int(d.name)] = (int(fields[11]) + int(fields[12])) / tick
    me, total = os.getpid(), 0.0
    for pid, seconds in cpu.items():
        p = parent.get(pid)
        while p and p != me:
            p = parent.get(p)
        total += seconds if p == me else 0.0
    return total


_DRAWS_JS = """async ([view, ms]) => {
  const read = () => view === "3d" ? viz.cam.frames : viz.data.frames;
  const f0 = read(), t0 = performance.now();
  await new Promise((done) => setTimeout(done, ms));
  return (read() - f0) * 1000 / (performance.now() - t0);
}"""


def _draws(page: Any, view: str, seconds: float) -> tuple[float, float]:
    """Frames the view drew per second over ``seconds``, and chromium's CPU share (%)."""
    cpu0, wall0 = _descendants_cpu_s(), time.monotonic()
    fps = float(page.evaluate(_DRAWS_JS, [view, seconds * 1000]))
    return fps, 100 * (_descendants_cpu_s() - cpu0) / (time.monotonic() - wall0)


def _measure(
    browser: Any,
    server: DashboardServer,
    view: str,
    seconds: float,
    paused: threading.Event,
    *,
    adaptive: bool = True,
) -> dict[str, float]:
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
    page.wait_for_function(
        "() => window.viz && viz.cam && viz.data.map && viz.data.scan"
        " && viz.data.layers.some(l => l && l.points && l.points.at(-1).stride === 3)",
        timeout=60000,
    )
    first_map_s = time.monotonic() - t0
    if view == "3d":  # rviz's Orbit, the whole 100 m map in view
        page.evaluate(
            "(adaptive) => { viz.setViewMode('Orbit'); viz.cam.distance = 90; viz.cam.pitch = 0.9;"
            " viz.cam.focal.set(0, 0, 0); viz.cam.adaptive = adaptive; }",
            adaptive,
        )
    else:
        page.evaluate("() => { viz.setViewMode('2D'); viz.view.scale = 12; }")
    # the render speed: a frame drawn every animation frame, no Frame Rate cap (a page
    # without viz.redraw, from before it drew only on change, redraws every frame anyway)
    page.evaluate(
        "() => { if (viz.redraw) { viz.redraw.continuous = true;"
        " viz.redraw.maxFps = Infinity; viz.requestDraw(); } }"
    )
    page.wait_for_timeout(4000)  # the adaptive resolution settles
    received["bytes"] = 0
    cpu0, wall0 = _cpu_s(), time.monotonic()
    fps = float(page.evaluate(_DRAWS_JS, [view, seconds * 1000]))
    wall = time.monotonic() - wall0
    cpu = _cpu_s() - cpu0
    drawn = page.evaluate("() => viz.data.layers[3].points.at(-1).n")  # the Depth display
    ms = page.evaluate("() => [viz.cam.msUpdate || 0, viz.cam.msRender || 0, viz.cam.resolution]")
    # frames drawn back to back, each waited for: the software GPU's own time per frame
    synced = page.evaluate("() => viz.renderSync(10)") if view == "3d" else 0.0
    # as used: frames only when something changed, at most the Frame Rate (30)
    page.evaluate(
        "() => { if (viz.redraw) { viz.redraw.continuous = false; viz.redraw.maxFps = null; } }"
    )
    live_fps, live_cpu = _draws(page, view, min(seconds, 5.0))
    paused.set()  # idle: nothing published, nothing moves (a slow page drains its backlog first)
    page.wait_for_timeout(3000)
    idle_fps, idle_cpu = _draws(page, view, min(seconds, 5.0))
    paused.clear()
    page.close()
    return {
        "fps": fps,
        "live_fps": live_fps,
        "live_browser_cpu": live_cpu,
        "idle_fps": idle_fps,
        "idle_browser_cpu": idle_cpu,
        "wall": wall,
        "cpu": 100 * cpu / wall,
        "kib": received["bytes"] / wall / 1024,
        "first_map": first_map_s,
        "cloud_points": float(drawn),
        "ms_update": float(ms[0]),
        "ms_render": float(ms[1]),
        "resolution": float(ms[2]),
        "ms_synced": float(synced),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="measuring window")
    ap.add_argument("--map-cells", type=int, default=2000, help="map side, cells")
    ap.add_argument("--update-map-every", type=float, default=None, help="seconds")
    ap.add_argument("--view", choices=("3d", "2d", "both"), default="both")
    ap.add_argument(
        "--cloud-max-points", type=int, default=20000, help="the cloud display's Max Points"
    )
    args = ap.parse_args()
    if not CHROMIUM.exists():
        sys.exit("needs /usr/bin/chromium (Debian's chromium package)")
    ctx = Context(clock="wall")
    paused = threading.Event()
    _system(ctx, args.map_cells, args.update_map_every, paused)
    server = DashboardServer(ctx, "127.0.0.1", 0, config=_config(args.cloud_max_points))
    ctx.spin_in_thread()
    server.start()
    pw = sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    try:
        print(
            f"dashboard benchmark ({platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}, chromium headless, software rendering)"
        )
        print(
            f"  map {args.map_cells} x {args.map_cells} cells, 720-beam scan at 10 Hz, "
            "640 x 480 depth cloud at 10 Hz, robot moving (TF at 10 Hz)"
        )
        runs = [("3d", True), ("3d", False), ("2d", True)]
        for view, adaptive in runs:
            if args.view not in ("both", view):
                continue
            r = _measure(browser, server, view, args.seconds, paused, adaptive=adaptive)
            what = (
                ""
                if view == "2d"
                else (", adaptive resolution" if adaptive else ", full resolution")
            )
            print(f"  {view.upper()} view{what} (window {r['wall']:.1f} s):")
            print(f"    first map on the page:    {r['first_map']:6.2f} s after page load")
            print(
                f"    page frame rate:          {r['fps']:6.1f} fps redrawing every frame"
                " (target >= 30)"
            )
            print(
                f"    as used, data streaming:  {r['live_fps']:6.1f} frames/s drawn (Frame Rate"
                f" 30), chromium {r['live_browser_cpu']:.0f} % of one core"
            )
            print(
                f"    idle, nothing published:  {r['idle_fps']:6.1f} frames/s drawn, chromium"
                f" {r['idle_browser_cpu']:.0f} % of one core"
            )
            print(f"    cloud points drawn:       {r['cloud_points']:6.0f} of 307200 per frame")
            if view == "3d":
                print(
                    f"    per frame:                {r['ms_update']:6.1f} ms scene update, "
                    f"{r['ms_render']:.1f} ms WebGL render"
                )
                print(f"    adaptive resolution:      {r['resolution']:6.3f} of full (per axis)")
                print(f"    synced frame (GPU work):  {r['ms_synced']:6.1f} ms")
            print(f"    server process CPU:       {r['cpu']:6.1f} % of one core")
            print(f"    websocket traffic:        {r['kib']:6.1f} KiB/s")
    finally:
        browser.close()
        pw.stop()
        server.stop()
        ctx.shutdown()


if __name__ == "__main__":
    main()
