"""The dashboard in Debian's chromium (Playwright) against a live in-process simulation."""

from __future__ import annotations

import io
import math
import socket
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from roverlab.core import Context, QoSProfile
from roverlab.msgs import array_to_occupancy_grid, xytheta_from_pose
from roverlab.sim.app import Simulation
from roverlab.viz import DashboardServer

CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
RESOLUTION_M = 0.05

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
browser_only = pytest.mark.skipif(
    not CHROMIUM.exists(),
    reason="/usr/bin/chromium is absent (run scripts/install-system-deps.sh)",
)


@dataclass
class Live:
    ctx: Context
    sim: Simulation
    server: DashboardServer
    grid: np.ndarray
    origin: tuple[float, float]
    got: dict[str, list[Any]] = field(default_factory=dict)


def _wait(cond: Callable[[], bool], timeout_s: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if cond():
            return True
        time.sleep(0.05)
    return cond()


@pytest.fixture(scope="module")
def live() -> Iterator[Live]:
    ctx = Context(clock="paced")
    sim = Simulation(context=ctx, world="maze", robot="mybot")
    grid, origin = sim.world_model.occupancy(RESOLUTION_M)
    node = ctx.create_node("test_viz")
    map_pub = node.create_publisher(
        "nav_msgs/msg/OccupancyGrid", "/map", QoSProfile(depth=1, durability="transient_local")
    )
    map_pub.publish(
        array_to_occupancy_grid(
            np.where(grid, 100, 0).astype(np.int8),
            resolution=RESOLUTION_M,
            origin=(origin[0], origin[1], 0.0),
        )
    )
    got: dict[str, list[Any]] = {"goal": [], "initialpose": [], "odom": []}
    node.create_subscription(
        "geometry_msgs/msg/PoseStamped", "/move_base_simple/goal", got["goal"].append, 10
    )
    node.create_subscription(
        "geometry_msgs/msg/PoseWithCovarianceStamped", "/initialpose", got["initialpose"].append, 10
    )
    node.create_subscription("nav_msgs/msg/Odometry", "/odom", got["odom"].append, 10)
    server = DashboardServer(ctx, "127.0.0.1", 0)
    ctx.spin_in_thread()
    server.start()
    yield Live(ctx, sim, server, grid, (float(origin[0]), float(origin[1])), got)
    server.stop()
    ctx.shutdown()


@pytest.fixture(scope="module")
def page(live: Live) -> Iterator[Any]:
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (run scripts/install-system-deps.sh)")
    pw = playwright_sync.sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    pg = browser.new_page(viewport={"width": 1280, "height": 800})
    pg.goto(live.server.url)
    # drawn: the map, a scan, and the robot outline have all arrived and been painted
    pg.wait_for_function(
        "() => window.viz && viz.data.map && viz.data.scan && viz.data.state"
        " && viz.data.state.robot.length > 0 && viz.view.placed && viz.data.frames > 5",
        timeout=20000,
    )
    pg.wait_for_timeout(300)
    yield pg
    browser.close()
    pw.stop()


def _canvas_shot(page: Any, path: Path) -> np.ndarray:
    png = page.locator("#view").screenshot(path=str(path))
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.int16)


def _view(page: Any) -> dict[str, float]:
    v: dict[str, float] = page.evaluate(
        "() => ({cx: viz.view.cx, cy: viz.view.cy, scale: viz.view.scale,"
        " w: document.getElementById('view').width, h: document.getElementById('view').height})"
    )
    return v


def _to_screen(v: dict[str, float], x: Any, y: Any) -> tuple[Any, Any]:
    return v["w"] / 2 + (x - v["cx"]) * v["scale"], v["h"] / 2 - (y - v["cy"]) * v["scale"]


def _to_world(v: dict[str, float], px: float, py: float) -> tuple[float, float]:
    return v["cx"] + (px - v["w"] / 2) / v["scale"], v["cy"] - (py - v["h"] / 2) / v["scale"]


@browser_only
def test_map_scan_and_robot_are_drawn(live: Live, page: Any, tmp_path: Path) -> None:
    img = _canvas_shot(page, tmp_path / "dashboard.png")
    v = _view(page)
    h, w, _ = img.shape
    rows, cols = np.indices(live.grid.shape)
    wx = live.origin[0] + (cols + 0.5) * RESOLUTION_M
    wy = live.origin[1] + (rows + 0.5) * RESOLUTION_M
    px, py = _to_screen(v, wx, wy)
    inside = (px > 5) & (px < w - 5) & (py > 5) & (py < h - 5)
    grey = img.max(axis=2)
    walls = inside & live.grid
    free = inside & ~live.grid
    assert walls.sum() > 100 and free.sum() > 100
    wall_px = grey[py[walls].astype(int), px[walls].astype(int)]
    free_px = img[py[free].astype(int), px[free].astype(int)].min(axis=1)
    assert np.mean(wall_px < 90) > 0.7, "map walls are not dark where the world has walls"
    assert np.mean(free_px > 180) > 0.6, "free cells are not light"
    red = (img[..., 0] > 240) & (img[..., 1] < 30) & (img[..., 2] < 30)
    assert red.sum() > 30, "no scan points in the scan colour"
    cy, cx = h // 2, w // 2
    centre = img[cy - 30 : cy + 30, cx - 30 : cx + 30]
    blue = (centre[..., 2] > 170) & (centre[..., 0] < 40) & (centre[..., 1] < 40)
    assert blue.sum() > 20, "the robot's blue base is not drawn near the centre"


def _drag_tool(
    page: Any, tool: str, start: tuple[int, int], delta: tuple[int, int]
) -> tuple[float, float]:
    page.click(f"#toolbar button[data-tool='{tool}']")
    box = page.locator("#view").bounding_box()
    v = _view(page)
    x0, y0 = box["x"] + start[0], box["y"] + start[1]
    page.mouse.move(x0, y0)
    page.mouse.down()
    page.mouse.move(x0 + delta[0], y0 + delta[1], steps=6)
    page.mouse.up()
    return _to_world(v, start[0], start[1])


@browser_only
def test_nav_goal_tool_publishes_the_clicked_pose(live: Live, page: Any) -> None:
    v = _view(page)
    start = (int(v["w"] / 2 + 150), int(v["h"] / 2 - 100))
    wx, wy = _drag_tool(page, "goal", start, (60, -60))
    assert _wait(lambda: len(live.got["goal"]) > 0), "no /move_base_simple/goal"
    msg = live.got["goal"][-1]
    x, y, yaw = xytheta_from_pose(msg.pose)
    assert msg.header.frame_id in ("map", "odom")
    assert math.hypot(x - wx, y - wy) < 0.04
    assert abs(yaw - math.pi / 4) < 0.05  # dragged up and to the right on screen


@browser_only
def test_pose_estimate_tool_publishes_initialpose(live: Live, page: Any) -> None:
    v = _view(page)
    start = (int(v["w"] / 2 - 120), int(v["h"] / 2 + 80))
    wx, wy = _drag_tool(page, "initialpose", start, (-80, 40))
    assert _wait(lambda: len(live.got["initialpose"]) > 0), "no /initialpose"
    msg = live.got["initialpose"][-1]
    x, y, yaw = xytheta_from_pose(msg.pose.pose)
    assert math.hypot(x - wx, y - wy) < 0.04
    assert abs(yaw - math.atan2(-40, -80)) < 0.05
    cov = np.asarray(msg.pose.covariance)
    assert cov[0] == 0.25 and cov[7] == 0.25 and cov[35] == 0.06853891945200942


@browser_only
def test_image_panel_shows_camera_frames(page: Any, tmp_path: Path) -> None:
    page.wait_for_function(
        "() => document.getElementById('camera').naturalWidth > 0", timeout=15000
    )
    png = page.locator("#camera").screenshot(path=str(tmp_path / "camera.png"))
    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(float)
    assert pixels.shape[0] > 50 and pixels.std() > 5.0, "camera image is blank"
    assert page.eval_on_selector("#image-topic", "e => e.value") == "/image_raw"


@browser_only
def test_key_i_drives_the_robot_forward(live: Live, page: Any) -> None:
    assert _wait(lambda: len(live.got["odom"]) > 0)
    x0, y0, yaw0 = xytheta_from_pose(live.got["odom"][-1].pose.pose)
    page.locator("#view").click(position={"x": 5, "y": 5})  # focus; Move Camera tool is active
    page.keyboard.down("i")
    time.sleep(2.0)
    page.keyboard.up("i")
    time.sleep(0.5)
    x1, y1, _ = xytheta_from_pose(live.got["odom"][-1].pose.pose)
    forward = (x1 - x0) * math.cos(yaw0) + (y1 - y0) * math.sin(yaw0)
    assert forward > 0.1, f"robot moved {forward:.3f} m forward on 'i'"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _ws_handshake_status(port: int, path: str) -> int:
    request = (
        f"GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
        "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
        "Sec-WebSocket-Version: 13\r\n\r\n"
    )
    with socket.create_connection(("127.0.0.1", port), timeout=5) as s:
        s.sendall(request.encode())
        status_line = s.recv(4096).split(b"\r\n", 1)[0]
    return int(status_line.split()[1])


def _http_status(url: str) -> int:
    try:
        with urllib.request.urlopen(url, timeout=5) as resp:
            return int(resp.status)
    except urllib.error.HTTPError as err:
        return int(err.code)


def test_wrong_token_is_refused() -> None:
    ctx = Context(clock="wall")
    port = _free_port()
    server = DashboardServer(ctx, "127.0.0.1", port, token="s3cret")
    ctx.spin_in_thread()
    server.start()
    try:
        base = f"http://127.0.0.1:{port}"
        assert _http_status(base + "/?token=wrong") == 403
        assert _http_status(base + "/") == 403
        assert _http_status(base + "/?token=s3cret") == 200
        assert _ws_handshake_status(port, "/ws?token=wrong") == 403
        assert _ws_handshake_status(port, "/ws?token=s3cret") == 101
    finally:
        server.stop()
        ctx.shutdown()


def test_non_loopback_host_gets_a_token() -> None:
    ctx = Context(clock="wall")
    server = DashboardServer(ctx, "0.0.0.0", 0)
    assert server.token and len(server.token) >= 16
    assert f"token={server.token}" in server.url
    ctx.shutdown()
