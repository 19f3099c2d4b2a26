"""The dashboard for the bring-up seeds, in Debian's chromium (Playwright).

* seed 004 as typed: ``roverlab launch urdlee car_ee.launch`` and ``roverlab topic pub
  -r 10 /cmd_vel ...`` in two processes; the launch's rviz (the dashboard) shows the car
  driving a circle in the odom frame, and its Joints sliders (joint_state_publisher_gui)
  move the wheel joints on /joint_states;
* rqt_image_view in a launch file: the image panel shows face_detector's annotated image
  of a face picture fed through usb_cam.

Screenshots go to the tests' tmp dirs.
"""

from __future__ import annotations

import io
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pytest
import yaml
from PIL import Image

from roverlab.core import Context
from roverlab.launch import build_launch, load_launch
from roverlab.world import BUNDLED_WORLDS_DIR
from tests.helpers.browser import CHROMIUM
from tests.helpers.procs import twist_pub_args

ROVERLAB = str(Path(sys.executable).with_name("roverlab"))
FACE_PNG = BUNDLED_WORLDS_DIR / "models/poster_face/materials/textures/face.png"

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
pytestmark = [
    pytest.mark.skipif(not CHROMIUM.exists(), reason="/usr/bin/chromium is absent"),
    pytest.mark.timeout(240),
]


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _wait_http(url: str, timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        try:
            with urllib.request.urlopen(url, timeout=1.0):
                return
        except OSError:
            time.sleep(0.3)
    raise AssertionError(f"{url} never answered")


def _stop(p: subprocess.Popen[str]) -> None:
    if p.poll() is None:
        p.send_signal(signal.SIGINT)
        try:
            p.wait(timeout=15)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def _robot_centre(page: Any) -> tuple[float, float]:
    pts = page.evaluate("() => viz.data.state.robot.flatMap(r => r.points)")
    arr = np.asarray(pts, dtype=float)
    return float(arr[:, 0].mean()), float(arr[:, 1].mean())


def test_seed_004_car_drives_in_the_dashboard(daemon: str, browser: Any, tmp_path: Path) -> None:
    port = _free_port()
    env = {**os.environ, "ROVERLAB_DASHBOARD_PORT": str(port), "PYTHONUNBUFFERED": "1"}
    launch = subprocess.Popen(
        [ROVERLAB, "launch", "urdlee", "car_ee.launch"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    pub = None
    try:
        url = f"http://127.0.0.1:{port}/"
        _wait_http(url)
        pub = subprocess.Popen(
            [
                ROVERLAB,
                *twist_pub_args(0.2, 0.5),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        page = browser.new_page(viewport={"width": 1400, "height": 850})
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        page.wait_for_function(
            "() => window.viz && viz.data.state && viz.data.state.robot.length > 3"
            " && viz.data.state.frames.odom",
            timeout=30000,
        )
        # the seed's showmycar.rviz fixes base_link; to watch the car drive, pick odom
        # as the seed's tutorial says (使用 odom 运行小车)
        page.select_option("#fixed-frame", "odom")
        page.wait_for_function("() => viz.data.state.fixed_frame === 'odom'", timeout=10000)
        # as a person would: add an Odometry display (the arrows trail the car) and zoom in
        page.select_option("#add-kind", label="Odometry")
        page.click("#add-display")
        page.evaluate(  # its arrow length (an option of the display), from 1.3 m to 0.12 m
            "() => { const c = structuredClone(viz.data.config);"
            " c.displays.at(-1).options.length = 0.12; viz.send({type: 'config', config: c}); }"
        )
        # showmycar.rviz's view is rviz's Orbit (the 3D view); this test drives the 2D one
        page.evaluate("() => viz.setViewMode('2D')")
        box = page.locator("#view").bounding_box()
        assert box is not None
        page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        for _ in range(5):
            page.mouse.wheel(0, -300)
            page.wait_for_timeout(50)
        page.wait_for_timeout(500)
        first = _robot_centre(page)
        page.locator("#view").screenshot(path=str(tmp_path / "car_t0.png"))
        moved, second = 0.0, first
        for _ in range(60):  # about 3 s at 0.2 m/s; more on a loaded machine
            page.wait_for_timeout(250)
            second = _robot_centre(page)
            moved = float(np.hypot(second[0] - first[0], second[1] - first[1]))
            if moved > 0.3:
                break
        shot = page.screenshot(path=str(tmp_path / "car_t3.png"))
        assert moved > 0.3, (first, second)
        # a circle of radius v / w = 0.195 / 0.45 = 0.43 m around (0, 0.43)
        for cx, cy in (first, second):
            assert np.hypot(cx, cy - 0.433) == pytest.approx(0.433, abs=0.08)
        assert np.asarray(Image.open(io.BytesIO(shot))).std() > 5

        # joint_state_publisher_gui: the Joints panel has a slider per wheel joint
        sliders = page.locator("#joints input.joint")
        assert sliders.count() == 4
        page.evaluate(
            "() => { const s = document.querySelector("
            "'#joints input[data-joint=\"left_wheel2base_link\"]');"
            " s.value = 1.25; s.dispatchEvent(new Event('input')); }"
        )
        echo = subprocess.run(
            [ROVERLAB, "topic", "echo", "/joint_states", "-n", "30", "--timeout", "20"],
            capture_output=True,
            text=True,
            env=env,
            timeout=60,
            check=False,
        )
        docs = [yaml.safe_load(d) for d in echo.stdout.split("---") if d.strip()]
        moved_joint = [
            dict(zip(d["name"], d["position"], strict=True)).get("left_wheel2base_link")
            for d in docs
        ]
        assert any(v is not None and abs(v - 1.25) < 0.01 for v in moved_joint), moved_joint[:5]
        page.locator("#right").screenshot(path=str(tmp_path / "joints.png"))
        assert not errors, errors
        page.close()
    finally:
        if pub is not None:
            _stop(pub)
        _stop(launch)


def test_rqt_image_view_shows_face_detector_boxes(
    browser: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    picture = tmp_path / "operator.png"
    scene = np.full((480, 640, 3), 100, np.uint8)
    scene[140:340, 220:420] = cv2.imread(str(FACE_PNG))
    cv2.imwrite(str(picture), scene)
    launch_file = tmp_path / "faces.launch"
    launch_file.write_text(
        f"""<launch>
  <node name="usb_cam" pkg="usb_cam" type="usb_cam_node">
    <param name="video_device" value="{picture}"/><param name="framerate" value="5"/>
  </node>
  <node pkg="face_detector" type="face_detector" name="face_detector">
    <remap from="camera" to="usb_cam"/><remap from="image_topic" to="image_raw"/>
    <param name="do_publish_faces_of_unknown_size" value="true"/>
  </node>
  <node pkg="rqt_image_view" type="rqt_image_view" name="image_view"
        args="/face_detector/image"/>
</launch>"""
    )
    port = _free_port()
    monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", str(port))
    ctx = Context(clock="wall")
    launch = build_launch(load_launch(launch_file), context=ctx)
    assert launch.warnings == [] and "image_view" in {n.get_name() for n in launch.nodes}
    ctx.spin_in_thread()
    try:
        page = browser.new_page(viewport={"width": 1400, "height": 850})
        page.goto(f"http://127.0.0.1:{port}/")
        page.wait_for_function(
            "() => { const i = document.getElementById('camera');"
            " return i && i.naturalWidth > 0; }",
            timeout=30000,
        )
        assert page.locator("#image-topic").input_value() == "/face_detector/image"
        png = page.locator("#camera").screenshot(path=str(tmp_path / "faces.png"))
        pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
        blue = (pixels[:, :, 2] > 200) & (pixels[:, :, 0] < 60) & (pixels[:, :, 1] < 60)
        assert blue.sum() > 50  # the box of a face of unknown size
        page.close()
    finally:
        ctx.shutdown()
