"""Seed 003's flow in the browser: mybot in the maze, map_server + amcl + move_base from
robot_navigation's navigation_stack.launch, the dashboard on its navigation.rviz; a 2D Nav
Goal dragged on the map drives the robot there and the action reports SUCCEEDED. The file's
view is rviz/TopDownOrtho, so the page shows the 3D view's orthographic top camera and the
tool casts the mouse onto the ground plane."""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import build_launch
from roverlab.navigation.move_base.node import MoveBase
from roverlab.sim.node import SimulatorNode
from roverlab.viz import DashboardServer
from roverlab.viz.config import load_rviz
from tests.helpers.browser import CHROMIUM, CHROMIUM_ARGS
from tests.helpers.net import wait_until
from tests.viz.test_dashboard import VIEWPORT

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")


@dataclass
class Nav:
    ctx: Context
    sim: SimulatorNode
    move_base: MoveBase
    server: DashboardServer
    results: list[Any]


@pytest.fixture
def nav(monkeypatch: pytest.MonkeyPatch) -> Iterator[Nav]:
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (run scripts/install-system-deps.sh)")
    monkeypatch.setenv("BASE_TYPE", "NanoRobot")
    ctx = Context(clock="paced", rate=4.0)
    sim = build_launch(
        find_package("bingda_tutorials") / "launch" / "simulation_robot.launch", context=ctx
    )
    stack = build_launch(
        find_package("robot_navigation") / "launch" / "navigation_stack.launch",
        {"simulation": "true"},
        context=ctx,
    )
    (mb,) = [n for n in stack.nodes if isinstance(n, MoveBase)]
    assert sim.simulator is not None
    results: list[Any] = []
    ctx.create_node("result_spy").create_subscription(
        "move_base_msgs/msg/MoveBaseActionResult", "/move_base/result", results.append, 10
    )
    config = load_rviz(find_package("robot_navigation") / "rviz" / "navigation.rviz")
    server = DashboardServer(ctx, "127.0.0.1", 0, config=config)
    ctx.spin_in_thread()
    server.start()
    yield Nav(ctx, sim.simulator, mb, server, results)
    server.stop()
    ctx.shutdown()


def test_2d_nav_goal_in_the_dashboard_drives_the_robot(nav: Nav, tmp_path: Path) -> None:
    pw = playwright_sync.sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    try:
        page = browser.new_page(viewport=VIEWPORT)
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(nav.server.url)
        page.wait_for_function(
            "() => window.viz && viz.data.map && viz.data.scan && viz.data.state"
            " && viz.data.state.robot.length > 0 && viz.view.placed",
            timeout=30000,
        )
        assert wait_until(lambda: nav.move_base.global_costmap.ready, 20.0)
        # the Footprint (rviz/PolygonStamped) display draws the local costmap's footprint
        assert not nav.server.bridge.config.unsupported
        page.wait_for_function(
            "() => viz.data.config.displays.some((d, i) => d.kind === 'polygon'"
            " && viz.data.layers[i] && (viz.data.layers[i].markers || []).length === 1)",
            timeout=20000,
        )
        assert page.evaluate("() => viz.cam.mode") == "TopDownOrtho"  # navigation.rviz's view
        assert page.evaluate("() => viz.cam.scale") == 110
        gx, gy = -0.5, 0.4  # a free place of the maze
        px, py = page.evaluate(f"() => viz.worldToScreen3({gx}, {gy}, 0)")
        box = page.locator("#view3d").bounding_box()
        page.click("#toolbar button[data-tool='goal']")
        page.mouse.move(box["x"] + px, box["y"] + py)
        page.mouse.down()
        page.mouse.move(box["x"] + px + 60, box["y"] + py, steps=6)  # facing +x on screen
        page.mouse.up()
        page.wait_for_timeout(1500)
        page.locator("#view3d").screenshot(path=str(tmp_path / "nav_goal_underway.png"))
        assert wait_until(lambda: bool(nav.results), 120.0), "no result on /move_base/result"
        status = nav.results[-1].status
        assert (status.status, status.text) == (3, "Goal reached.")  # SUCCEEDED
        assert math.hypot(nav.sim.x - gx, nav.sim.y - gy) < 0.2
        page.wait_for_timeout(500)
        page.locator("#view3d").screenshot(path=str(tmp_path / "nav_goal_reached.png"))
        assert not errors, errors
    finally:
        browser.close()
        pw.stop()
