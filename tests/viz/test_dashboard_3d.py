"""The dashboard's 3D view (three.js) in Debian's chromium (Playwright), with screenshots.

* seed 001: mycar with its kinect in box_house, displays from its ``test.rviz`` (rviz/Orbit)
  plus the kinect's PointCloud2 in RGB8: the coloured cloud is drawn in 3D, above the
  ground, and the car's links are drawn in their URDF colours;
* seed 004: the xacro cylinder car of ``showmycar.rviz`` (fixture copied from the urdlee
  package): base, wheels, camera and laser support are drawn from the orbit view;
* the 2D Nav Goal dragged in the orbit view publishes ``/move_base_simple/goal`` at the
  point the mouse ray meets the ground.

Screenshots go to the tests' tmp dirs.
"""

from __future__ import annotations

import contextlib
import io
import math
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

import roverlab.packages
from roverlab.core import Context, Time
from roverlab.description.node import JointStatePublisher, RobotStatePublisher
from roverlab.geometry import Transform3, quat_from_rpy
from roverlab.msgs import yaw_from_quaternion
from roverlab.sim.app import Simulation, SpawnPose
from roverlab.tf import StaticTransformBroadcaster
from roverlab.tf.convert import transform_to_msg
from roverlab.viz import DashboardServer
from roverlab.viz.config import DisplayConfig, load_rviz
from tests.helpers.browser import CHROMIUM

VIEWPORT = {"width": 1400, "height": 860}
MYCAR = Path(roverlab.packages.__file__).parent / "mycar"
URDLEE = Path(__file__).parent / "fixtures" / "urdlee"

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
pytestmark = pytest.mark.skipif(not CHROMIUM.exists(), reason="/usr/bin/chromium is absent")


def _open(browser: Any, server: DashboardServer, ready: str, timeout_ms: int = 60000) -> Any:
    page = browser.new_page(viewport=VIEWPORT)
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(server.url)
    page.wait_for_function(
        "() => window.viz && viz.cam && viz.cam.frames > 0 && viz.data.state"
        " && viz.data.state.robot3d.length > 0 && (" + ready + ")",
        timeout=timeout_ms,
    )
    _next_frame(page)
    page.errors = errors
    return page


def _next_frame(page: Any) -> None:
    """The page draws only when something changed: one more frame, with all that arrived."""
    drawn = page.evaluate("() => { viz.requestDraw(); return viz.cam.frames; }")
    page.wait_for_function(f"() => viz.cam.frames > {drawn}")


def _shot(page: Any, path: Path) -> np.ndarray:
    png = page.locator("#view3d").screenshot(path=str(path))
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(np.int16)


def _screen(page: Any, x: float, y: float, z: float) -> tuple[float, float]:
    sx, sy = page.evaluate(f"() => viz.worldToScreen3({x}, {y}, {z})")
    return float(sx), float(sy)


@pytest.fixture(scope="module")
def mycar() -> Iterator[tuple[Context, DashboardServer, list[Any]]]:
    ctx = Context()
    # facing box_1 (2.0, 1.5) so the kinect sees a coloured box in front of the white walls
    Simulation(
        context=ctx,
        world=MYCAR / "worlds" / "box_house.world",
        robot="mycar",
        spawn=SpawnPose(0.0, 0.0, math.atan2(1.5, 2.0)),
    )
    # sensor.launch's static_transform_publisher 0 0 0 -1.57 0 -1.57 support support_depth
    node = ctx.create_node("goal_listener")
    optical = Transform3.from_arrays((0.0, 0.0, 0.0), quat_from_rpy(-1.57, 0.0, -1.57))
    StaticTransformBroadcaster(node).send_transform(
        transform_to_msg("support", "support_depth", Time(0), optical)
    )
    config = load_rviz(MYCAR / "config" / "test.rviz")
    assert config.view["mode"] == "Orbit"
    config.displays.append(
        DisplayConfig(
            "point_cloud2",
            "PointCloud2",
            True,
            "/camera/depth/points",
            {"color_transformer": "RGB8", "size_px": 3.0},
        )
    )
    for d in config.displays:
        if d.kind == "tf":
            d.enabled = True
    goals: list[Any] = []
    node.create_subscription(
        "geometry_msgs/msg/PoseStamped", "/move_base_simple/goal", goals.append, 10
    )
    server = DashboardServer(ctx, "127.0.0.1", 0, config=config)
    ctx.spin_in_thread()
    server.start()
    yield ctx, server, goals
    server.stop()
    ctx.shutdown()


def test_mycar_cloud_and_links_in_the_orbit_view(
    mycar: tuple[Context, DashboardServer, list[Any]], browser: Any, tmp_path: Path
) -> None:
    _, server, _ = mycar
    page = _open(browser, server, "viz.data.layers.some(l => l && l.points)", 120000)
    assert page.evaluate("() => viz.cam.mode") == "Orbit"  # from test.rviz's Views/Current
    # closer than test.rviz's 6.2 m, from behind the car, towards the box it faces
    page.evaluate(
        "() => { viz.cam.distance = 3.2; viz.cam.focal.set(0.9, 0.7, 0.2);"
        " viz.cam.yaw = Math.atan2(1.5, 2.0) + Math.PI; viz.cam.pitch = 0.45; }"
    )
    page.wait_for_timeout(800)
    _next_frame(page)  # drawn from the new camera (800 ms alone missed it once under load)
    img = _shot(page, tmp_path / "mycar_orbit.png")
    cloud = page.evaluate(
        "() => { const l = viz.data.layers.find(l => l && l.points); const s = l.points.at(-1);"
        " let zmax = -1e9, zmin = 1e9, grey = 0; for (let i = 0; i < s.n; i++) {"
        " const z = s.xyz[3 * i + 2]; zmax = Math.max(zmax, z); zmin = Math.min(zmin, z);"
        " const c = s.rgba.subarray(4 * i, 4 * i + 3);"
        " if (Math.max(...c) - Math.min(...c) < 60) grey++; }"
        " return {n: s.n, stride: s.stride, perPoint: s.perPoint, zmin, zmax, grey}; }"
    )
    assert cloud["n"] > 1000 and cloud["stride"] == 3 and cloud["perPoint"]
    assert cloud["zmax"] - cloud["zmin"] > 0.3  # height kept: a wall, not a floor line
    # RGB8 colours from the camera: the box's saturated colour, not one flat colour
    assert cloud["n"] - cloud["grey"] > 200
    # the car's links: mycar's base_link is a brown (0.5, 0.3, 0, 0.5) cylinder at its TF
    base = page.evaluate("() => viz.data.state.frames3.base_link")
    bx, by = _screen(page, base[0], base[1], base[2])
    patch = img[int(by) - 8 : int(by) + 9, int(bx) - 8 : int(bx) + 9].reshape(-1, 3)
    brown = int(((patch[:, 0] - patch[:, 2] > 25) & (patch[:, 1] - patch[:, 2] > 5)).sum())
    shapes = page.evaluate("() => viz.data.state.robot3d.map(s => s.link)")
    assert {"base_link", "camera", "laser"} <= set(shapes)
    # the point cloud's pixels: coloured dots far from the background grey
    bg = np.array([48, 48, 48])
    coloured = (np.abs(img - bg).max(axis=2) > 60).sum()
    assert coloured > 2000
    assert brown > 20, "the brown base_link cylinder is not drawn at its TF"
    # TF names: shown, none overlapping
    boxes = page.evaluate("() => viz.tfLabelBoxes")
    assert len(boxes) >= 4
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            overlap = a["x"] < b["x"] + b["w"] and b["x"] < a["x"] + a["w"]
            assert not (overlap and a["y"] < b["y"] + b["h"] and b["y"] < a["y"] + a["h"])
    assert not page.errors
    page.close()


def test_nav_goal_in_the_orbit_view_casts_onto_the_ground(
    mycar: tuple[Context, DashboardServer, list[Any]], browser: Any
) -> None:
    _, server, goals = mycar
    page = _open(browser, server, "true")
    page.evaluate("() => { viz.cam.distance = 6; viz.cam.focal.set(0, 0, 0); }")
    page.wait_for_timeout(300)
    box = page.locator("#view3d").bounding_box()
    gx, gy = 1.0, -0.5
    sx, sy = _screen(page, gx, gy, 0.0)
    ex, ey = _screen(page, gx, gy + 1.0, 0.0)  # drag towards +y: yaw pi/2
    page.click("button[data-tool=goal]")
    page.mouse.move(box["x"] + sx, box["y"] + sy)
    page.mouse.down()
    page.mouse.move(box["x"] + ex, box["y"] + ey, steps=5)
    page.mouse.up()
    deadline = time.monotonic() + 10
    while not goals and time.monotonic() < deadline:
        time.sleep(0.05)
    assert goals, "no /move_base_simple/goal from the orbit view"
    p = goals[-1].pose
    assert p.position.x == pytest.approx(gx, abs=0.05)
    assert p.position.y == pytest.approx(gy, abs=0.05)
    assert yaw_from_quaternion(p.orientation) == pytest.approx(math.pi / 2, abs=0.1)
    assert page.evaluate("() => viz.getTool()") == "move"  # back to the camera tool
    page.close()


def test_seed_004_cylinder_car_from_showmycar_rviz(browser: Any, tmp_path: Path) -> None:
    ctx = Context()
    xacro = URDLEE / "urdf" / "xacro" / "car.urdf.xacro"
    RobotStatePublisher(ctx, robot_description=str(xacro))
    JointStatePublisher(ctx, robot_description=str(xacro))
    config = load_rviz(URDLEE / "config" / "showmycar.rviz")
    assert config.view["mode"] == "Orbit" and config.fixed_frame == "base_link"
    server = DashboardServer(ctx, "127.0.0.1", 0, config=config)
    ctx.spin_in_thread()
    server.start()
    try:
        page = _open(browser, server, "Object.keys(viz.data.state.frames3).length >= 5")
        page.evaluate("() => { viz.cam.distance = 1.2; viz.cam.focal.set(0, 0, 0.05); }")
        page.wait_for_timeout(800)
        img = _shot(page, tmp_path / "showmycar_orbit.png")
        links = set(page.evaluate("() => viz.data.state.robot3d.map(s => s.link)"))
        frames = page.evaluate("() => viz.data.state.frames3")
        for group in (("base_link",), ("camera",), ("support",), ("laser",)):
            assert any(g in links for g in group), f"{group} missing from {sorted(links)}"
        wheels = [name for name in links if "wheel" in name]
        assert len(wheels) >= 2
        # every link with a shape is drawn where TF puts it: some non-background pixels
        bg = np.array([48, 48, 48])
        for name in ["base_link", "camera", "laser", *wheels]:
            sx, sy = _screen(page, *frames[name][:3])
            x, y = int(sx), int(sy)
            patch = img[max(0, y - 6) : y + 7, max(0, x - 6) : x + 7]
            drawn = int((np.abs(patch - bg).max(axis=2) > 25).sum())
            assert drawn > 10, f"link {name} not drawn at its TF ({x}, {y})"
        assert not page.errors
        page.close()
    finally:
        server.stop()
        ctx.shutdown()


def _box_stl(path: Path, size: float) -> None:
    """An ASCII STL of a cube of side ``size`` centred on its origin."""
    h = size / 2
    corners = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1)]
    faces += [(2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    lines = ["solid box"]
    for a, b, c in faces:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {p[0]} {p[1]} {p[2]}" for p in corners[[a, b, c]]]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid box"]) + "\n")


@contextlib.contextmanager
def _one_mesh_page(browser: Any, urdf: str, token: str | None = None) -> Iterator[Any]:
    """A dashboard (showmycar.rviz: Orbit, fixed frame base_link) on a robot_state_publisher
    of ``urdf`` and a page open on it once its one mesh has loaded (``/mesh/0`` asks for
    ``token`` when one is given: the page adds its own)."""
    ctx = Context()
    RobotStatePublisher(ctx, robot_description=urdf)
    config = load_rviz(URDLEE / "config" / "showmycar.rviz")
    server = DashboardServer(ctx, "127.0.0.1", 0, config=config, token=token)
    ctx.spin_in_thread()
    server.start()
    try:
        page = _open(browser, server, "viz.meshes.loaded + viz.meshes.failed > 0")
        assert page.evaluate("() => viz.meshes") == {"loaded": 1, "failed": 0}
        yield page
    finally:
        server.stop()
        ctx.shutdown()


def test_stl_mesh_visual_is_loaded_and_drawn(browser: Any, tmp_path: Path) -> None:
    stl = tmp_path / "body.stl"
    _box_stl(stl, 0.4)
    urdf = f"""<robot name="meshbot">
      <link name="base_link"><visual><geometry><mesh filename="file://{stl}"/></geometry>
        <material name="red"><color rgba="1 0 0 1"/></material></visual></link>
    </robot>"""
    with _one_mesh_page(browser, urdf, token="mesh-token") as page:
        page.evaluate("() => { viz.cam.distance = 2.0; viz.cam.focal.set(0, 0, 0); }")
        page.wait_for_timeout(500)
        img = _shot(page, tmp_path / "stl_mesh.png")
        sx, sy = _screen(page, 0.0, 0.0, 0.0)
        patch = img[int(sy) - 10 : int(sy) + 11, int(sx) - 10 : int(sx) + 11].reshape(-1, 3)
        red = int(((patch[:, 0] > 120) & (patch[:, 1] < 60) & (patch[:, 2] < 60)).sum())
        assert red > 100, "the red STL box is not drawn at base_link"
        assert not page.errors
        page.close()


def test_collada_mesh_visual_keeps_its_colour_and_z_up(browser: Any, tmp_path: Path) -> None:
    """The book's kinect.dae (a Z_UP box 0.07 x 0.28 x 0.07 m, red in its own material,
    no URDF material): drawn red, long along y, seen from above."""
    dae = Path(__file__).parents[1] / "ros1_packages/book_robot_description/meshes/kinect.dae"
    urdf = f"""<robot name="daebot">
      <link name="base_link"><visual><geometry><mesh filename="file://{dae}" scale="3 3 3"/>
      </geometry></visual></link>
    </robot>"""
    with _one_mesh_page(browser, urdf) as page:
        page.evaluate(
            "() => { viz.cam.distance = 2.5; viz.cam.focal.set(0, 0, 0);"
            " viz.cam.pitch = 1.45; viz.cam.yaw = 0; }"
        )
        page.wait_for_timeout(500)
        img = _shot(page, tmp_path / "dae_mesh.png")

        def red_at(x: float, y: float) -> bool:
            sx, sy = _screen(page, x, y, 0.1)
            px = img[int(sy) - 2 : int(sy) + 3, int(sx) - 2 : int(sx) + 3].reshape(-1, 3)
            return bool(((px[:, 0] > 120) & (px[:, 1] < 70) & (px[:, 2] < 70)).sum() > 12)

        # scaled 3x: 0.84 m along y, 0.21 m across x and z (the file's Z_UP kept as ROS z)
        assert red_at(0.0, 0.0) and red_at(0.0, 0.35) and red_at(0.0, -0.35)
        assert not red_at(0.3, 0.0) and not red_at(-0.3, 0.0)
        assert not page.errors
        page.close()
