"""What a newcomer sees with the data in another process, in Debian's chromium (Playwright).

Seed 001 as typed: its launch files (mycar in box_house, robot_state_publisher, the launch's
rviz) in one process, ``roverlab dashboard`` in another. Every display that has data is
green, the topics panel shows a rate for every flowing topic (counted where they are
published: the old panel showed ``- Hz`` for other processes' topics and greyed them out),
the camera's image_transport ``compressed`` topic is drawn in the image panel, and an image
display on a camera that does not exist says so in the panel instead of a broken icon.

Screenshots go to the test's tmp dir.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from roverlab.viz.config import DisplayConfig, load_rviz, save_config
from roverlab.viz.ports import PORT_ENV
from tests.helpers.browser import CHROMIUM
from tests.helpers.net import free_port
from tests.viz.test_bringup_pages import _stop, _wait_http

pytestmark = [
    pytest.mark.skipif(not CHROMIUM.exists(), reason="/usr/bin/chromium is absent"),
    pytest.mark.timeout(240),
]

MYCAR = Path(__file__).resolve().parents[2] / "src" / "roverlab" / "packages" / "mycar"
SEED_001 = """<launch>
  <include file="$(find mycar)/launch/environment.launch"/>
  <include file="$(find mycar)/launch/sensor.launch"/>
</launch>
"""
# flowing: read by someone (the dashboard, the launch's nodes); /clock pauses while nobody
# follows it and the cameras render only for their readers, as they should
FLOWING = ("/scan", "/odom", "/tf", "/joint_states", "/camera/image_raw/compressed")


@pytest.fixture(scope="module")
def seed001(daemon: str, tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The seed's launch in one process, ``roverlab dashboard`` in another; the page's URL."""
    tmp = tmp_path_factory.mktemp("seed001")
    launch = tmp / "seed001.launch"
    launch.write_text(SEED_001)
    config = load_rviz(MYCAR / "config" / "test.rviz")  # Grid, RobotModel, TF, Odometry
    config.displays += [
        DisplayConfig("laser_scan", "LaserScan", True, "/scan"),
        DisplayConfig("image", "Camera", True, "/camera/image_raw/compressed"),
        DisplayConfig("image", "No camera", True, "/usb_cam/image_raw"),
    ]
    save_config(config, tmp / "seed001.json")
    env = {**os.environ, PORT_ENV: str(free_port())}  # the launch's own rviz
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "roverlab.cli", "launch", str(launch)],
            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, text=True,
        ),
    ]  # fmt: skip
    port = free_port()
    procs.append(
        subprocess.Popen(
            [
                sys.executable,
                "-m",
                "roverlab.cli",
                "dashboard",
                "-d",
                str(tmp / "seed001.json"),
                "--port",
                str(port),
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            text=True,
        )
    )
    try:
        _wait_http(f"http://127.0.0.1:{port}/config", timeout_s=90.0)
        yield f"http://127.0.0.1:{port}/"
    finally:
        for p in procs:  # both stop at once, then each is waited for
            p.send_signal(signal.SIGINT)
        for p in procs:
            _stop(p)


def _displays(page: Any) -> dict[str, tuple[str, str]]:
    rows = page.evaluate(
        "() => Array.from(document.querySelectorAll('#displays .display')).map(e =>"
        " [e.querySelector('.dname').textContent, e.dataset.status,"
        "  e.querySelector('.status').textContent])"
    )
    return {r[0].split("(")[0].strip(): (r[1], r[2]) for r in rows}


def _topics(page: Any) -> dict[str, tuple[str, bool]]:
    rows = page.evaluate(
        "() => Array.from(document.querySelectorAll('#topics tr')).map(e =>"
        " [e.cells[0].textContent, e.cells[1].textContent, e.className === 'none'])"
    )
    return {r[0]: (r[1], r[2]) for r in rows}


def _hz(text: str) -> float:
    """``"4.5 Hz"`` -> 4.5; ``"- Hz"`` (not measured) -> 0."""
    value = text.split()[0]
    return 0.0 if value == "-" else float(value)


def test_seed_001_from_another_process_is_green_with_rates(
    seed001: str, browser: Any, tmp_path: Path
) -> None:
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    page.goto(seed001)
    want = {"Grid", "RobotModel", "Odometry", "LaserScan", "Camera"}
    deadline = time.monotonic() + 90
    displays: dict[str, tuple[str, str]] = {}
    topics: dict[str, tuple[str, bool]] = {}
    while time.monotonic() < deadline:
        displays, topics = _displays(page), _topics(page)
        green = all(displays.get(n, ("",))[0] == "ok" for n in want)
        rated = all(_hz(topics.get(t, ("- Hz", True))[0]) > 0 for t in FLOWING)
        shown = page.evaluate("() => document.querySelector('#camera').naturalWidth")
        if green and rated and shown:
            break
        time.sleep(1.0)
    page.screenshot(path=str(tmp_path / "seed001_dashboard.png"))
    for name in want:
        assert displays[name][0] == "ok", f"{name}: {displays[name]}"
    assert "messages received" in displays["LaserScan"][1]
    for topic in FLOWING:
        hz, greyed = topics[topic]
        assert not greyed and _hz(hz) > 0, f"{topic}: {hz}"
    # the compressed camera topic: a JPEG of box_house in the panel, no message over it
    box = page.locator("#camera").bounding_box()
    assert box is not None and box["width"] > 100
    assert page.locator("#camera-message").inner_text() == ""
    img = np.asarray(Image.open(tmp_path / "seed001_dashboard.png").convert("RGB"))
    x, y, w, h = (int(box[k]) for k in ("x", "y", "width", "height"))
    assert img[y : y + h, x : x + w].std() > 10, "the camera image is flat"
    # the camera that does not exist: a message, not a broken-image icon
    other = page.locator('.imgmsg[data-slot="6"]')
    deadline = time.monotonic() + 20
    while "No publisher" not in other.inner_text() and time.monotonic() < deadline:
        time.sleep(0.5)
    assert other.inner_text() == "No publisher on /usb_cam/image_raw"
    assert not page.locator('img[data-slot="6"]').is_visible()
    # the dropdown offers every image topic on the network, compressed ones too (it is
    # refilled with each topic list: under load the raw topic may come a refresh later)
    wanted = {"/camera/image_raw", "/camera/image_raw/compressed"}
    options: list[str] = []
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        options = page.evaluate(
            "() => Array.from(document.querySelectorAll('#image-topic option')).map(o => o.value)"
        )
        if wanted <= set(options):
            break
        time.sleep(0.5)
    assert wanted <= set(options)
    page.close()
