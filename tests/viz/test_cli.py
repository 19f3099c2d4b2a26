"""``roverlab sim --dashboard``, ``roverlab dashboard --rviz``, and rviz in launch files."""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from roverlab.core import Context
from roverlab.viz.errors import DashboardError
from roverlab.viz.launcher import parse_rviz_args, start_rviz

FIXTURES = Path(__file__).parent / "fixtures"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _get(url: str) -> tuple[int, bytes]:
    with urllib.request.urlopen(url, timeout=5) as resp:
        return int(resp.status), resp.read()


def test_sim_dashboard_serves_from_the_same_process() -> None:
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "sim", "--no-expose", "--duration", "5",
         "--dashboard", "--dashboard-port", str(port)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        status = 0
        body = b""
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                status, body = _get(f"http://127.0.0.1:{port}/config")
                break
            except OSError:
                time.sleep(0.2)
        assert status == 200, "the dashboard did not come up"
        assert json.loads(body)["format"] == "roverlab-dashboard"
        _, stderr = proc.communicate(timeout=120)
        assert proc.returncode == 0, stderr
        assert f"dashboard: http://127.0.0.1:{port}/" in stderr
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def test_dashboard_with_a_missing_rviz_file_is_one_line_exit_2(tmp_path: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "dashboard", "--rviz", str(tmp_path / "x.rviz")],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert r.returncode == 2
    assert "x.rviz" in r.stderr and "Traceback" not in r.stderr


def test_rviz_args() -> None:
    a = parse_rviz_args("-d /a/b.rviz --fixed-frame=/odom --splash-screen s.png -q")
    assert a.display_config == "/a/b.rviz" and a.fixed_frame == "odom"
    assert a.ignored == ["--splash-screen", "s.png", "-q"]
    with pytest.raises(DashboardError, match="needs a value"):
        parse_rviz_args("-d")


def test_launch_rviz_node_loads_its_display_config(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", "0")
    ctx = Context()
    warnings: list[str] = []
    node = start_rviz(ctx, f"-d {FIXTURES / 'test.rviz'}", source="x.launch", warn=warnings.append)
    assert node is not None and warnings == []
    assert node.get_name() == "rviz"
    server = node.server  # type: ignore[attr-defined]
    assert server.bridge.config.fixed_frame == "odom"  # test.rviz's Fixed Frame
    assert "/odom" in ctx.graph.topics and "/scan" not in ctx.graph.topics
    status, _ = _get(
        server.url.replace("/?", "/config?") if "?" in server.url else server.url + "config"
    )
    assert status == 200
    missing = start_rviz(
        ctx, "-d /nowhere.rviz -f base_link", node_name="rviz2", warn=warnings.append
    )
    assert missing is not None and any("nowhere.rviz" in w for w in warnings)
    ctx.shutdown()  # stops both web servers


def test_launch_rviz_on_a_taken_port_is_a_warning(monkeypatch: pytest.MonkeyPatch) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", str(s.getsockname()[1]))
        ctx = Context()
        warnings: list[str] = []
        assert start_rviz(ctx, "", source="y.launch", warn=warnings.append) is None
        assert warnings and "not started" in warnings[0]
        assert "/rviz" not in ctx.nodes
        ctx.shutdown()


def test_image_view_serves_the_image_panel_on_its_topic(daemon: str) -> None:
    """``roverlab image view TOPIC`` (rqt_image_view): the dashboard with its image panel
    enabled on TOPIC."""
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "image", "view", "/usb_cam/image_raw",
         "--port", str(port)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        body = b""
        while time.monotonic() < deadline and proc.poll() is None and not body:
            try:
                _, body = _get(f"http://127.0.0.1:{port}/config")
            except OSError:
                time.sleep(0.2)
        assert body, "the image view did not come up"
        images = [d for d in json.loads(body)["displays"] if d["kind"] == "image"]
        assert [(d["topic"], d["enabled"]) for d in images] == [("/usb_cam/image_raw", True)]
    finally:
        proc.terminate()
        proc.communicate(timeout=30)
