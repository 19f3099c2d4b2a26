"""The dashboard in Debian's chromium (Playwright) against a live in-process simulation.

One simulation, one server and one browser page are shared by the module. Besides the
simulated robot (scan, odometry, TF, camera) a test node publishes a map (with a static
``map -> odom``), a path, a pose array, a point cloud, markers and a depth image, so every
display kind is drawn. Screenshots go to the tests' tmp dirs.
"""

from __future__ import annotations

import io
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from roverlab.core import Context, QoSProfile, Time
from roverlab.geometry import Transform3
from roverlab.localization.amcl.node import AmclNode
from roverlab.msgs import (
    Marker,
    MarkerArray,
    PoseArray,
    array_to_image,
    array_to_occupancy_grid,
    make,
    pose_from_xytheta,
    xytheta_from_pose,
    xyz_to_pointcloud2,
)
from roverlab.sim.app import Simulation
from roverlab.tf import StaticTransformBroadcaster
from roverlab.tf.convert import transform_to_msg
from roverlab.viz import DashboardServer
from roverlab.viz.config import DisplayConfig, default_config
from tests.helpers.browser import CHROMIUM
from tests.helpers.net import wait_until

RESOLUTION_M = 0.05
VIEWPORT = {"width": 1600, "height": 900}

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
    amcl: AmclNode
    grid: np.ndarray
    origin: tuple[float, float]
    robot: tuple[float, float]
    map_dir: Path
    got: dict[str, list[Any]] = field(default_factory=dict)


def _extra_displays() -> list[DisplayConfig]:
    return [
        DisplayConfig(
            "path", "Plan", True, "/test/plan", {"color": [255, 0, 255], "line_width": 0.1}
        ),
        DisplayConfig(
            "pose_array",
            "Particles",
            True,
            "/test/particles",
            {"color": [0, 255, 255], "length": 0.6},
        ),
        DisplayConfig("point_cloud2", "Cloud", True, "/test/cloud", {"size_px": 4.0}),
        DisplayConfig("marker_array", "Markers", True, "/test/markers", {}),
        DisplayConfig("pose_array", "Lost", True, "/test/lost", {}),
        DisplayConfig(
            "pose_with_covariance", "AMCL pose", True, "/test/amcl_pose", {"color": [255, 255, 0]}
        ),
        DisplayConfig("path", "Silent", True, "/test/silent", {}),
    ]


def _publishers(live_node: Any, robot: tuple[float, float]) -> None:
    rx, ry = robot
    plan_pub = live_node.create_publisher("nav_msgs/msg/Path", "/test/plan", 1)
    parts_pub = live_node.create_publisher("geometry_msgs/msg/PoseArray", "/test/particles", 1)
    lost_pub = live_node.create_publisher("geometry_msgs/msg/PoseArray", "/test/lost", 1)
    amcl_pub = live_node.create_publisher(
        "geometry_msgs/msg/PoseWithCovarianceStamped", "/test/amcl_pose", 1
    )
    live_node.create_publisher("nav_msgs/msg/Path", "/test/silent", 1)  # never publishes
    cloud_pub = live_node.create_publisher("sensor_msgs/msg/PointCloud2", "/test/cloud", 1)
    marker_pub = live_node.create_publisher(
        "visualization_msgs/msg/MarkerArray", "/test/markers", 1
    )
    depth_pub = live_node.create_publisher("sensor_msgs/msg/Image", "/test/depth", 1)
    header = {"frame_id": "map"}
    plan = make(
        "nav_msgs/msg/Path",
        header=header,
        poses=[
            {"header": header, "pose": pose_from_xytheta(rx - 2.0 + 0.5 * i, ry + 2.0, 0.0)}
            for i in range(9)
        ],
    )
    parts = PoseArray(
        header=header,
        poses=[pose_from_xytheta(rx - 2.5 + 0.5 * i, ry - 2.0, math.pi / 2) for i in range(3)],
    )
    lost = PoseArray(header={"frame_id": "nowhere"}, poses=[pose_from_xytheta(0, 0, 0)])
    cov = np.zeros(36)
    cov[0], cov[7], cov[35] = 0.4**2, 0.15**2, 0.2**2  # 1-sigma ellipse 0.8 m x 0.3 m
    amcl_pose = make(
        "geometry_msgs/msg/PoseWithCovarianceStamped",
        header=header,
        pose={"pose": pose_from_xytheta(rx + 1.0, ry - 1.0, 0.0), "covariance": cov},
    )
    gx, gy = np.meshgrid(np.linspace(0, 0.8, 12), np.linspace(0, 0.8, 12))
    zs = np.linspace(0.0, 1.0, gx.size)
    cloud_pts = np.column_stack((gx.ravel() + rx + 2.0, gy.ravel() + ry - 2.4, zs))
    cloud = xyz_to_pointcloud2(cloud_pts.astype(np.float32), "map")
    cube = Marker(
        header=header,
        ns="t",
        id=1,
        type=1,
        pose=pose_from_xytheta(rx - 2.5, ry + 0.0, 0.3),
        scale={"x": 0.6, "y": 0.6, "z": 0.6},
        color={"r": 1.0, "g": 0.5, "b": 0.0, "a": 1.0},
    )
    text = Marker(
        header=header,
        ns="t",
        id=2,
        type=9,
        pose=pose_from_xytheta(rx + 2.5, ry + 0.5, 0.0),
        scale={"z": 0.4},
        color={"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0},
        text="goal",
    )
    depth = np.tile(np.linspace(0.5, 4.0, 64, dtype=np.float32), (48, 1))
    depth[:, :4] = np.nan
    depth_msg = array_to_image(depth, "32FC1", frame_id="camera")

    def tick() -> None:
        plan_pub.publish(plan)
        parts_pub.publish(parts)
        lost_pub.publish(lost)
        amcl_pub.publish(amcl_pose)
        cloud_pub.publish(cloud)
        marker_pub.publish(MarkerArray(markers=[cube, text]))
        depth_pub.publish(depth_msg)

    live_node.create_timer(0.25, tick)


@pytest.fixture(scope="module")
def live(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Live]:
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
    StaticTransformBroadcaster(node).send_transform(
        transform_to_msg("map", "odom", Time(0), Transform3())
    )
    robot = (0.0, 0.0)
    _publishers(node, robot)
    got: dict[str, list[Any]] = {"goal": [], "initialpose": [], "odom": [], "point": []}
    node.create_subscription(
        "geometry_msgs/msg/PoseStamped", "/move_base_simple/goal", got["goal"].append, 10
    )
    node.create_subscription(
        "geometry_msgs/msg/PoseWithCovarianceStamped", "/initialpose", got["initialpose"].append, 10
    )
    node.create_subscription(
        "geometry_msgs/msg/PointStamped", "/clicked_point", got["point"].append, 10
    )
    node.create_subscription("nav_msgs/msg/Odometry", "/odom", got["odom"].append, 10)
    # amcl on the published map, re-initialised by 2D Pose Estimate (the test node's
    # static map -> odom stays the only one)
    amcl = AmclNode(ctx, parameter_overrides={"use_map_topic": True, "tf_broadcast": False})
    config = default_config("map")
    config.displays += _extra_displays()
    map_dir = tmp_path_factory.mktemp("maps")
    server = DashboardServer(
        ctx, "127.0.0.1", 0, config=config, map_dir=map_dir, config_path=map_dir / "dash.json"
    )
    server.bridge.quiet_after_s = 2.0  # a silent topic warns after 2 s (5 s by default)
    ctx.spin_in_thread()
    server.start()
    yield Live(
        ctx, sim, server, amcl, grid, (float(origin[0]), float(origin[1])), robot, map_dir, got
    )
    server.stop()
    ctx.shutdown()


@pytest.fixture(scope="module")
def page(live: Live, browser: Any) -> Iterator[Any]:
    pg = browser.new_page(viewport=VIEWPORT)
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(live.server.url)
    # drawn: the map, a scan, the robot outline and the test displays have all arrived
    pg.wait_for_function(
        "() => window.viz && viz.data.map && viz.data.scan && viz.data.state"
        " && viz.data.state.robot.length > 0 && viz.view.placed && viz.data.frames > 5"
        " && viz.data.layers.some(l => l && l.markers && l.markers.length)"
        " && viz.data.layers.some(l => l && l.path)",
        timeout=20000,
    )
    pg.wait_for_timeout(400)
    yield pg
    assert not errors, f"JavaScript errors on the page: {errors}"
    pg.close()


def _canvas_shot(page: Any, path: Path) -> np.ndarray:
    png = page.locator("#view").screenshot(path=str(path))
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.int16)


def _view(page: Any) -> dict[str, float]:
    v: dict[str, float] = page.evaluate(
        "() => ({cx: viz.view.cx, cy: viz.view.cy, scale: viz.view.scale, angle: viz.view.angle,"
        " w: document.getElementById('view').width, h: document.getElementById('view').height})"
    )
    return v


def _to_screen(v: dict[str, float], x: Any, y: Any) -> tuple[Any, Any]:
    c, s = math.cos(v["angle"]), math.sin(v["angle"])
    dx, dy = x - v["cx"], y - v["cy"]
    return (
        v["w"] / 2 + (c * dx + s * dy) * v["scale"],
        v["h"] / 2 - (-s * dx + c * dy) * v["scale"],
    )


def _to_world(v: dict[str, float], px: float, py: float) -> tuple[float, float]:
    rx, ry = (px - v["w"] / 2) / v["scale"], -(py - v["h"] / 2) / v["scale"]
    c, s = math.cos(v["angle"]), math.sin(v["angle"])
    return v["cx"] + c * rx - s * ry, v["cy"] + s * rx + c * ry


def _near(img: np.ndarray, v: dict[str, float], x: float, y: float, r: int) -> np.ndarray:
    px, py = _to_screen(v, x, y)
    px, py = int(round(px)), int(round(py))
    return img[max(0, py - r) : py + r + 1, max(0, px - r) : px + r + 1]


def _count(patch: np.ndarray, rgb: tuple[int, int, int], tol: int = 40) -> int:
    return int((np.abs(patch - np.array(rgb)).max(axis=2) <= tol).sum())


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
    assert np.mean(free_px > 150) > 0.6, "free cells are not light"
    red = (img[..., 0] > 240) & (img[..., 1] < 30) & (img[..., 2] < 30)
    assert red.sum() > 30, "no scan points in the scan colour"
    cy, cx = h // 2, w // 2
    centre = img[cy - 30 : cy + 30, cx - 30 : cx + 30]
    blue = (centre[..., 2] > 170) & (centre[..., 0] < 40) & (centre[..., 1] < 40)
    assert blue.sum() > 20, "the robot's blue base is not drawn near the centre"


@browser_only
def test_path_poses_cloud_and_markers_are_drawn(live: Live, page: Any, tmp_path: Path) -> None:
    img = _canvas_shot(page, tmp_path / "displays.png")
    v = _view(page)
    rx, ry = live.robot
    # the plan: a magenta line 2 m above the robot
    assert _count(_near(img, v, rx + 1.0, ry + 2.0, 6), (255, 0, 255)) > 10, "no path"
    # three particles: cyan arrows pointing up
    assert _count(_near(img, v, rx - 2.0, ry - 1.8, 8), (0, 255, 255)) > 5, "no pose array"
    # the cloud: a square coloured by height, several rainbow hues
    patch = _near(img, v, rx + 2.4, ry - 2.0, 18).reshape(-1, 3)
    vivid = patch[(patch.max(axis=1) - patch.min(axis=1)) > 120]
    hues = {tuple(c) for c in (vivid // 100).tolist()}
    assert len(hues) >= 3, f"the cloud is not rainbow-coloured by height: {hues}"
    # the cube marker: orange
    assert _count(_near(img, v, rx - 2.5, ry, 10), (255, 128, 0), tol=30) > 100, "no cube"
    # the text marker: white pixels around its anchor
    assert _count(_near(img, v, rx + 2.5, ry + 0.5, 14), (255, 255, 255), tol=30) > 10
    # the amcl pose: a yellow arrow, its 1-sigma ellipse outlined 0.4 m to either side
    # along x and 0.15 m along y, filled faintly inside
    assert _count(_near(img, v, rx + 1.5, ry - 1.0, 3), (255, 255, 0)) > 3, "no arrow"
    for dx, dy in ((-0.4, 0.0), (0.0, 0.15), (0.0, -0.15)):
        edge = _near(img, v, rx + 1.0 + dx, ry - 1.0 + dy, 2)
        assert _count(edge, (255, 255, 0), tol=60) > 0, f"no ellipse at {dx}, {dy}"
    outside = _near(img, v, rx + 1.0, ry - 1.0 + 0.3, 2)
    assert _count(outside, (255, 255, 0), tol=60) == 0


@browser_only
def test_status_tree_reports_silent_topics_and_tf_failures(page: Any) -> None:
    page.wait_for_function(
        "() => document.querySelector('.display[data-slot] .status') !== null", timeout=5000
    )
    page.wait_for_function(  # the silent topic's grace time is over
        "() => Array.from(document.querySelectorAll('#displays .display')).some(e =>"
        " e.querySelector('.dname').textContent.startsWith('Silent')"
        " && e.dataset.status === 'warn')",
        timeout=10000,
    )
    rows = page.evaluate(
        "() => Array.from(document.querySelectorAll('#displays .display')).map(e =>"
        " [e.querySelector('.dname').textContent, e.dataset.status,"
        "  e.querySelector('.status').textContent])"
    )
    by_name = {r[0].split("  (")[0]: r for r in rows}
    assert by_name["Lost"][1] == "error" and "nowhere" in by_name["Lost"][2]
    assert by_name["Silent"][1] == "warn" and "No messages received" in by_name["Silent"][2]
    assert by_name["Costmap"][1] == "disabled"
    assert by_name["LaserScan"][1] == "ok"
    assert by_name["Plan"][1] == "ok"
    assert page.locator("#conn").inner_text() == "connected"


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
    assert wait_until(lambda: len(live.got["goal"]) > 0), "no /move_base_simple/goal"
    msg = live.got["goal"][-1]
    x, y, yaw = xytheta_from_pose(msg.pose)
    assert msg.header.frame_id == "map"
    assert math.hypot(x - wx, y - wy) < 0.04
    assert abs(yaw - math.pi / 4) < 0.05  # dragged up and to the right on screen


@browser_only
def test_pose_estimate_tool_publishes_initialpose(
    live: Live, page: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    v = _view(page)
    start = (int(v["w"] / 2 - 120), int(v["h"] / 2 + 80))
    assert live.amcl.amcl is not None
    before = live.amcl.amcl.pf.poses[:, :2].mean(axis=0)
    # what amcl sets, and where its particles are right after (the next scans may move
    # them: the robot is elsewhere, and polling could miss the moment in between)
    applied: list[tuple[float, float, float, float]] = []
    apply_initial = live.amcl._apply_initial

    def spy(pose: Any, cov: Any) -> None:
        apply_initial(pose, cov)
        assert live.amcl.amcl is not None
        mean = live.amcl.amcl.pf.poses[:, :2].mean(axis=0)
        applied.append((pose.x, pose.y, float(mean[0]), float(mean[1])))

    monkeypatch.setattr(live.amcl, "_apply_initial", spy)
    wx, wy = _drag_tool(page, "initialpose", start, (-80, 40))
    assert wait_until(lambda: len(live.got["initialpose"]) > 0), "no /initialpose"
    msg = live.got["initialpose"][-1]
    x, y, yaw = xytheta_from_pose(msg.pose.pose)
    assert math.hypot(x - wx, y - wy) < 0.04
    assert abs(yaw - math.atan2(-40, -80)) < 0.05
    cov = np.asarray(msg.pose.covariance)
    assert cov[0] == 0.25 and cov[7] == 0.25 and cov[35] == 0.06853891945200942

    # amcl takes it: the pose as clicked (the robot stands still), its particles re-drawn
    # around it (0.5 m spread)
    assert math.hypot(before[0] - wx, before[1] - wy) > 1.0
    assert wait_until(lambda: bool(applied)), "amcl did not re-initialise at the 2D Pose Estimate"
    px, py, mx, my = applied[-1]
    assert math.hypot(px - wx, py - wy) < 0.04
    assert math.hypot(mx - wx, my - wy) < 0.15


@browser_only
def test_tools_follow_a_rotated_view(live: Live, page: Any) -> None:
    page.click("#rot-right")  # the view turns by 15 degrees
    try:
        v = _view(page)
        assert abs(v["angle"] - math.pi / 12) < 1e-9
        start = (int(v["w"] / 2 + 100), int(v["h"] / 2 + 50))
        wx, wy = _drag_tool(page, "point", start, (0, 0))
        assert wait_until(lambda: len(live.got["point"]) > 0), "no /clicked_point"
        p = live.got["point"][-1].point
        assert math.hypot(p.x - wx, p.y - wy) < 0.04
        n = len(live.got["goal"])
        _drag_tool(page, "goal", start, (60, 0))  # right on screen
        assert wait_until(lambda: len(live.got["goal"]) > n)
        _, _, yaw = xytheta_from_pose(live.got["goal"][-1].pose)
        assert abs(yaw - math.pi / 12) < 0.05  # screen right is 15 degrees in the world
    finally:
        page.click("#rot-reset")


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
def test_depth_image_is_shown_with_a_colour_map(live: Live, page: Any, tmp_path: Path) -> None:
    page.wait_for_function(
        "() => Array.from(document.querySelectorAll('#image-topic option'))"
        ".some(o => o.value === '/test/depth')",
        timeout=10000,
    )
    page.select_option("#image-topic", "/test/depth")
    try:
        assert wait_until(
            lambda: any(
                d.kind == "image" and d.topic == "/test/depth"
                for d in live.server.bridge.config.displays
            )
        )
        page.wait_for_function(
            "() => { const i = document.getElementById('camera');"
            " return i.naturalWidth === 64 && i.naturalHeight === 48; }",
            timeout=10000,
        )
        png = page.locator("#camera").screenshot(path=str(tmp_path / "depth.png"))
        rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
        row = rgb[rgb.shape[0] // 2]
        w = len(row)
        near, far = row[int(w * 0.15)], row[int(w * 0.95)]
        assert near[2] > 150 and near[0] < 100, f"near depth is not blue in jet: {near}"
        assert far[0] > 150 and far[2] < 100, f"far depth is not red in jet: {far}"
        assert row[1].max() < 40, "no-data pixels are not black"
    finally:
        page.select_option("#image-topic", "/image_raw")


@browser_only
def test_key_i_drives_the_robot_forward(live: Live, page: Any) -> None:
    assert wait_until(lambda: len(live.got["odom"]) > 0)
    x0, y0, yaw0 = xytheta_from_pose(live.got["odom"][-1].pose.pose)
    page.locator("#view").click(position={"x": 5, "y": 5})  # focus; Move Camera tool is active
    page.keyboard.down("i")
    time.sleep(2.0)
    page.keyboard.up("i")
    time.sleep(0.5)
    x1, y1, _ = xytheta_from_pose(live.got["odom"][-1].pose.pose)
    forward = (x1 - x0) * math.cos(yaw0) + (y1 - y0) * math.sin(yaw0)
    assert forward > 0.1, f"robot moved {forward:.3f} m forward on 'i'"


@browser_only
def test_follow_robot_keeps_it_centred(live: Live, page: Any) -> None:
    page.select_option("#follow", "base_footprint")
    page.check("#rotate-follow")
    try:
        page.wait_for_timeout(300)
        state = page.evaluate("() => viz.data.state.frames.base_footprint")
        v = _view(page)
        assert math.hypot(v["cx"] - state[0], v["cy"] - state[1]) < 0.05
        assert abs(math.remainder(v["angle"] - (state[2] - math.pi / 2), 2 * math.pi)) < 0.05
    finally:
        page.uncheck("#rotate-follow")
        page.select_option("#follow", "")
        page.click("#rot-reset")


@browser_only
def test_side_panel_toggles_and_configures_displays(live: Live, page: Any) -> None:
    bridge = live.server.bridge
    slot = next(i for i, d in enumerate(bridge.config.displays) if d.name == "LaserScan")
    box = page.locator(f"#displays .display[data-slot='{slot}']")
    box.locator(".enabled").uncheck()
    try:
        assert wait_until(lambda: not bridge.config.displays[slot].enabled)
        assert wait_until(lambda: bridge.displays[slot].sub is None), "still subscribed to /scan"
    finally:
        box.locator(".enabled").check()
    assert wait_until(lambda: bridge.displays[slot].sub is not None)
    box.locator(".dhead").click()  # expand, then set the decay time
    box.locator("input[data-option='decay_s']").fill("2")
    box.locator("input[data-option='decay_s']").press("Enter")
    assert wait_until(lambda: bridge.config.displays[slot].option("decay_s") == 2.0)
    # scans accumulate for the decay time
    page.wait_for_function(f"() => viz.data.layers[{slot}].points.length > 2", timeout=10000)
    box.locator("input[data-option='decay_s']").fill("0")
    box.locator("input[data-option='decay_s']").press("Enter")
    assert wait_until(lambda: bridge.config.displays[slot].option("decay_s") == 0.0)
    mslot = next(i for i, d in enumerate(bridge.config.displays) if d.name == "Map")
    mbox = page.locator(f"#displays .display[data-slot='{mslot}']")
    mbox.locator(".dhead").click()
    mbox.locator("select[data-option='color_scheme']").select_option("costmap")
    assert wait_until(lambda: bridge.config.displays[mslot].option("color_scheme") == "costmap")
    assert page.evaluate(f"() => viz.data.layers[{mslot}].map.scheme") == "costmap"
    mbox.locator("select[data-option='color_scheme']").select_option("map")
    assert wait_until(lambda: bridge.config.displays[mslot].option("color_scheme") == "map")
    # the fixed frame selector
    page.select_option("#fixed-frame", "odom")
    assert wait_until(lambda: bridge.config.fixed_frame == "odom")
    page.select_option("#fixed-frame", "map")
    assert wait_until(lambda: bridge.config.fixed_frame == "map")


@browser_only
def test_topic_list_save_map_and_save_config(live: Live, page: Any) -> None:
    page.wait_for_function(
        "() => viz.data.topics.some(t => t.name === '/scan' && t.hz > 1)", timeout=10000
    )
    assert "/scan" in page.locator("#topics").inner_text()
    page.fill("#map-name", "live_map")
    page.click("#save-map")
    page.wait_for_function(
        "() => document.getElementById('notice').textContent.includes('live_map')", timeout=10000
    )
    assert (live.map_dir / "live_map.yaml").is_file() and (live.map_dir / "live_map.pgm").is_file()
    page.click("#save-config")
    page.wait_for_function(
        "() => document.getElementById('notice').textContent.includes('dash.json')", timeout=10000
    )
    assert '"roverlab-dashboard"' in (live.map_dir / "dash.json").read_text()
