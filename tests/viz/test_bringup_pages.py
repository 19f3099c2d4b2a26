"""The dashboard for the bring-up seeds, in Debian's chromium (Playwright).

* seed 004 as typed: ``roverlab launch urdlee car_ee.launch`` and ``roverlab topic pub
  -r 10 /cmd_vel ...`` in two processes; the launch's rviz (the dashboard) shows the car
  driving in the odom frame where /odom puts it, /odom moving as commanded (checks that
  do not depend on the machine's load), and its Joints sliders
  (joint_state_publisher_gui) move the wheel joints on /joint_states;
* rqt_image_view in a launch file: the image panel shows face_detector's annotated image
  of a face picture fed through usb_cam.

Screenshots go to the tests' tmp dirs.
"""

from __future__ import annotations

import io
import itertools
import math
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

from roverlab.core import Context, QoSProfile
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport, daemon_endpoint
from roverlab.drivers.odometry import PID_RATE_HZ, wheel_setpoints
from roverlab.geometry import wrap_angle
from roverlab.launch import build_launch, load_launch
from roverlab.msgs import time_to_ns
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


def _drawn_robot(page: Any) -> tuple[np.ndarray, np.ndarray]:
    """The centre of the robot the dashboard draws, and the pose (x, y, yaw) of its
    base_footprint frame, in the fixed frame, from one state message."""
    got = page.evaluate(
        "() => ({points: viz.data.state.robot.flatMap(r => r.points),"
        " base: viz.data.state.frames.base_footprint})"
    )
    return np.asarray(got["points"], dtype=float).mean(axis=0), np.asarray(got["base"][:3])


def _odom_listener() -> tuple[Context, list[Any]]:
    """A node of this process on the launch's daemon, keeping every /odom message."""
    ctx = Context(clock="wall", publish_clock=False)
    ctx.add_transport(ZenohTransport(ZenohOptions(connect=(daemon_endpoint(),))))
    got: list[Any] = []
    node = ctx.create_node("odom_listener")
    node.create_subscription("nav_msgs/msg/Odometry", "/odom", got.append, QoSProfile(depth=1000))
    ctx.spin_in_thread()
    return ctx, got


def _check_odom_follows_the_command(odom: list[Any], linear_x: float, angular_z: float) -> int:
    """arbotix's /odom (car_ee's control.yaml: base_width 0.2, ticks_meter 2000, an
    acceleration limit far above one frame's change): each message's twist is either at
    rest (no command for the 1 s timeout: a starved publisher) or the commanded twist as
    the integer wheel set-points give it, and the pose moved by that twist over the time
    since the message before. However long an update took under load. Returns the number
    of moving messages."""
    left, right = wheel_setpoints(linear_x, angular_z, wheel_track_m=0.2, ticks_per_meter=2000)
    k = PID_RATE_HZ / 2000  # ticks per frame -> m/s
    v, w = 0.5 * (left + right) * k, (right - left) * k / 0.2
    moving = 0
    for before, msg in itertools.pairwise(odom):
        tw = msg.twist.twist
        dt = (time_to_ns(msg.header.stamp) - time_to_ns(before.header.stamp)) / 1e9
        if (tw.linear.x, tw.angular.z) == (0.0, 0.0):
            continue
        moving += 1
        # the encoders' counts are whole ticks: 1 tick per wheel over the update
        assert tw.linear.x == pytest.approx(v, abs=1e-3 / dt), (tw, dt)
        assert tw.angular.z == pytest.approx(w, abs=1e-2 / dt), (tw, dt)
        p0, p1 = before.pose.pose, msg.pose.pose
        step = np.hypot(p1.position.x - p0.position.x, p1.position.y - p0.position.y)
        turn = wrap_angle(_yaw(p1) - _yaw(p0))
        assert step == pytest.approx(tw.linear.x * dt, abs=1e-3), (step, tw, dt)
        assert turn == pytest.approx(tw.angular.z * dt, abs=1e-3), (turn, tw, dt)
    return moving


def _in_base(point: np.ndarray, base: np.ndarray) -> np.ndarray:
    """``point`` (fixed frame) in the frame whose pose is ``base`` (x, y, yaw)."""
    c, s = math.cos(base[2]), math.sin(base[2])
    return np.array([[c, s], [-s, c]]) @ (point - base[:2])


def _yaw(pose: Any) -> float:
    return 2.0 * math.atan2(pose.orientation.z, pose.orientation.w)


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
    odom_ctx: Context | None = None
    try:
        url = f"http://127.0.0.1:{port}/"
        _wait_http(url)
        odom_ctx, odom_got = _odom_listener()
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
        drawn = [_drawn_robot(page)]
        page.locator("#view").screenshot(path=str(tmp_path / "car_t0.png"))
        moved = 0.0
        for _ in range(60):  # about 3 s at 0.2 m/s; more on a loaded machine
            page.wait_for_timeout(250)
            drawn.append(_drawn_robot(page))
            moved = float(np.hypot(*(drawn[-1][0] - drawn[0][0])))
            if moved > 0.3:
                break
        shot = page.screenshot(path=str(tmp_path / "car_t3.png"))
        assert moved > 0.3, drawn
        assert np.asarray(Image.open(io.BytesIO(shot))).std() > 5
        # What is drawn is the car on /odom, and /odom is the commanded motion: checks
        # that hold however the machine's load delays the 10 Hz publisher (arbotix stops
        # the car after 1 s without a command) or arbotix's updates (its odometry takes
        # one long step, off the v/w circle an ideal car would drive).
        seen = len(odom_got)  # the messages the page drew may still be on their way here
        assert odom_ctx.wait_for(lambda: len(odom_got) >= seen + 5, timeout_sec=30)
        odom = list(odom_got)
        poses = np.array([(m.pose.pose.position.x, m.pose.pose.position.y, _yaw(m.pose.pose))
                          for m in odom])  # fmt: skip
        for centre, base in drawn:
            # the drawing rides on base_footprint (the same place on the car each time)
            assert _in_base(centre, base) == pytest.approx(_in_base(*drawn[0]), abs=0.01)
            # ... and base_footprint is where one of the /odom messages put it
            near = np.argmin(np.hypot(*(poses[:, :2] - base[:2]).T))
            assert np.hypot(*(poses[near, :2] - base[:2])) < 0.01, (base, poses[near])
            assert abs(wrap_angle(poses[near, 2] - base[2])) < 0.01, (base, poses[near])
        assert _check_odom_follows_the_command(odom, 0.2, 0.5) >= 3  # not only at rest

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
        if odom_ctx is not None:
            odom_ctx.shutdown()
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
