"""``roverlab demo``, the main job: every stage of the seeds' story, its files, Ctrl-C, and
the dashboard in a real browser while the robot explores."""

from __future__ import annotations

import json
import signal
import sys
import time
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from rosbags.highlevel import AnyReader

from roverlab.bag.reader import BagReader
from roverlab.cli.demo import _pause
from roverlab.core import Context
from roverlab.core.transport.daemon import daemon_running
from roverlab.maps import load_map
from roverlab.sim.app import Simulation
from roverlab.viz.server import DashboardServer
from tests.helpers.browser import CHROMIUM, CHROMIUM_ARGS
from tests.helpers.net import free_port
from tests.helpers.procs import Proc
from tests.viz.test_dashboard import VIEWPORT

DEMO = [sys.executable, "-m", "roverlab.cli", "demo", "--no-expose"]


def _report(out: Path) -> dict:
    return json.loads((out / "report.json").read_text())


def _wait_exit(proc: Proc, timeout: float) -> int:
    try:
        return proc.popen.wait(timeout=timeout)
    except Exception:
        proc.stop()
        raise


@dataclass(frozen=True)
class Headless:
    """One headless demo run, shared by the module's tests (its recording is played back)."""

    out: Path
    code: int
    stdout: str
    stderr: str


@pytest.fixture(scope="module")
def headless(tmp_path_factory: pytest.TempPathFactory) -> Headless:
    out = tmp_path_factory.mktemp("headless") / "demo"
    proc = Proc([*DEMO, "--no-dashboard", "--rate", "max", "--places", "2", "--out", str(out)])
    code = _wait_exit(proc, 600)
    stdout = proc.rest()
    return Headless(out, code, stdout, proc.stop())


def test_headless_demo_runs_every_stage_and_leaves_its_files(headless: Headless) -> None:
    out, code, stdout = headless.out, headless.code, headless.stdout
    assert code == 0, (stdout, headless.stderr)
    report = _report(out)
    assert report["ok"] and report["stages"] == {
        "explore": "ok", "save_map": "ok", "restart": "ok", "patrol": "ok"
    }  # fmt: skip
    assert report["coverage"] >= 0.95 and report["map_accuracy"] >= 0.95
    assert report["patrol_goals"] == report["patrol_successes"] == 2
    assert report["distance_m"] > 10.0
    assert "patrol: 2/2 goals succeeded" in stdout and "Going to:" in stdout
    # the map as map_saver writes it, loadable by map_server
    saved = load_map(out / "map.yaml")
    assert saved.info.resolution == pytest.approx(0.05)
    for png in ("map.png", "coverage.png"):
        with Image.open(out / png) as im:
            assert im.size[0] >= 400
    assert json.loads((out / "patrol.json").read_text())["successes"] == 2
    # the recording has the whole story: the SLAM map, amcl and the move_base goals
    with AnyReader([out / "run.mcap"]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    for topic in ("/map", "/scan", "/tf", "/amcl_pose", "/move_base/goal", "/explore/frontiers"):
        assert counts.get(topic, 0) > 0, (topic, sorted(counts))
    assert not list(out.glob("*.part"))


def test_ctrl_c_ends_the_demo_with_its_report_and_a_complete_recording(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Exposed on a daemon of its own that was not running: the demo starts it and, as
    roslaunch stops the roscore it started, stops it when it ends."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    monkeypatch.setenv("ROVERLAB_DAEMON", endpoint)
    out = tmp_path / "demo"
    proc = Proc([sys.executable, "-m", "roverlab.cli", "demo", "--expose", "--no-dashboard",
                 "--rate", "2", "--out", str(out)])  # fmt: skip
    proc.wait_line(lambda s: s.startswith("[explore] ..."), timeout=120)
    assert daemon_running(endpoint)
    time.sleep(3.0)
    proc.popen.send_signal(signal.SIGINT)
    code = _wait_exit(proc, 60)
    assert code == 1
    assert not daemon_running(endpoint)
    report = _report(out)
    assert report["stages"]["explore"] == "interrupted"
    assert report["stages"]["patrol"] == "skipped" and not report["ok"]
    with AnyReader([out / "run.mcap"]) as reader:  # finished, not truncated
        assert any(c.topic == "/scan" and c.msgcount > 0 for c in reader.connections)
    assert not list(out.glob("*.part"))


def test_bad_arguments_are_one_line() -> None:
    proc = Proc([*DEMO, "--no-dashboard", "--places", "0"])
    code = _wait_exit(proc, 60)
    err = proc.stop()
    assert code == 2 and err.strip().splitlines() == ["error: --places must be >= 1, got 0"]
    proc = Proc([*DEMO, "--no-dashboard", "--stay"])
    code = _wait_exit(proc, 60)
    assert code == 2 and proc.stop().strip().splitlines() == [
        "error: --stay keeps the dashboard up: it cannot go with --no-dashboard"
    ]


def test_staying_pauses_everything_but_the_web_server() -> None:
    """What --stay does after the report: the simulator, every node's timers and the
    network stop; the dashboard still serves its last state; the process takes no CPU."""
    ctx = Context(clock="paced", rate=3.0)
    server = DashboardServer(ctx, "127.0.0.1", 0)
    Simulation(context=ctx, world="maze", robot="mybot")
    server.start()
    try:
        spinner = ctx.spin_in_thread()
        time.sleep(1.0)
        assert ctx.now().nanoseconds > 0  # the simulation runs
        _pause(ctx, spinner, own_daemon=False)
        assert not spinner.is_alive()
        used = time.process_time()
        time.sleep(3.0)
        assert time.process_time() - used < 0.1  # nothing runs
        with urllib.request.urlopen(server.url, timeout=10) as page:  # still served
            assert page.status == 200
    finally:
        ctx.shutdown()


playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")

# The dashboard draws only when something changed, but the demo's robot always moves: at
# rviz's Frame Rate (30) chromium would take much of a core from the demo it watches. Five
# frames a second (the page's own cap, viz.redraw.maxFps) still draw every layer; the checks
# below read the page's data, and the screenshots are whole frames.
FIVE_FPS = "() => { viz.redraw.maxFps = 5; }"


def test_the_dashboard_shows_the_demo(tmp_path: Path) -> None:
    """The dashboard's URL comes first; the page shows the map being built, the robot and
    move_base's plan while it explores, the particle cloud while it patrols; the demo
    reaches its report with every stage succeeding and ends by itself (as `make run`)."""
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (run scripts/install-system-deps.sh)")
    out = tmp_path / "demo"
    shots = tmp_path / "screenshots"
    shots.mkdir()
    proc = Proc([*DEMO, "--port", "0", "--rate", "5", "--places", "2", "--out", str(out)])
    pw = playwright_sync.sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    try:
        first = proc.wait_line(timeout=120)
        assert first.startswith("dashboard: http://127.0.0.1:"), first
        url = first.split()[1]
        page = browser.new_page(viewport=VIEWPORT)
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        page.evaluate(FIVE_FPS)
        page.wait_for_function(
            "() => window.viz && viz.data.map && viz.data.scan && viz.data.state"
            " && viz.data.state.robot.length > 0 && viz.view.placed"
            " && viz.data.layers.some(l => l && l.path && l.path.length > 1)"
            " && viz.data.layers.some(l => l && l.markers && l.markers.length)",
            polling=250,
            timeout=120000,
        )
        page.wait_for_timeout(500)
        page.screenshot(path=str(shots / "demo_exploring.png"))
        seen: list[str] = []

        def line(prefix: str | tuple[str, ...]) -> Callable[[str], bool]:
            return lambda s: bool(seen.append(s)) or s.startswith(prefix)

        # a stage failing before the patrol ends the story: say so, not a timeout
        patrolling = proc.wait_line(line(("[patrol] Going to:", "report:")), timeout=300)
        assert patrolling.startswith("[patrol]"), "".join(seen)
        page.wait_for_function(
            "() => viz.data.layers.some(l => l && l.poses && l.poses.length > 10)",
            polling=250,
            timeout=60000,
        )  # amcl's particle cloud
        page.wait_for_timeout(1500)
        page.screenshot(path=str(shots / "demo_patrolling.png"))
        try:
            proc.wait_line(line("  files: "), timeout=300)
        except AssertionError as err:
            raise AssertionError(f"{err}; stdout: {''.join(seen)}") from None
        assert not errors, errors
        code = _wait_exit(proc, 60)  # by itself: no Ctrl-C
    finally:
        browser.close()
        pw.stop()
        if proc.popen.poll() is None:
            proc.stop()
    report = _report(out)
    assert report["ok"], report["stages"]
    assert code == 0
    for shot in ("demo_exploring.png", "demo_patrolling.png"):
        with Image.open(shots / shot) as im:
            assert im.size == (VIEWPORT["width"], VIEWPORT["height"])


# the newest map the page holds, the Map display's status and the play's progress
PAGE_MAP = """() => {
  const m = viz.data.map, st = viz.data.state, cfg = viz.data.config;
  if (!m || !st || !cfg) return null;
  const slot = cfg.displays.findIndex((d) => d.kind === "map" && d.topic === "/map");
  let known = 0;
  for (const c of m.cells) if (c !== -1) known++;
  return { w: m.w, h: m.h, res: m.res, ox: m.ox, oy: m.oy, known,
           status: st.status.displays[slot].map((r) => r[0]) };
}"""


def test_the_demo_recording_played_into_the_dashboard_shows_the_last_map(
    headless: Headless,
) -> None:
    """``roverlab bag play`` of the demo's recording into a running dashboard (another
    process): the page ends with the last /map of the recording, every cell as recorded
    (the map grows over the play: full maps and patches), and the Map display is OK."""
    if not CHROMIUM.exists():
        pytest.skip("/usr/bin/chromium is absent (run scripts/install-system-deps.sh)")
    assert headless.code == 0, headless.stderr
    bag = headless.out / "run.mcap"
    last: Any = None
    with BagReader(bag) as reader:
        for msg in reader.messages(["/map"]):
            last = msg.decode()
    assert last is not None
    want = np.asarray(last.data, dtype=np.int8)
    dashboard = Proc([sys.executable, "-m", "roverlab.cli", "dashboard", "--port", "0"])
    pw = playwright_sync.sync_playwright().start()
    browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
    try:
        url = dashboard.wait_line(lambda s: s.startswith("dashboard: "), timeout=60).split()[1]
        page = browser.new_page(viewport=VIEWPORT)
        errors: list[str] = []
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(url)
        page.evaluate(FIVE_FPS)
        page.wait_for_function("() => window.viz && viz.data.config && viz.data.state")
        play = Proc([sys.executable, "-m", "roverlab.cli", "bag", "play", str(bag),
                     "-r", "50", "--topics", "/map", "/tf", "/tf_static"])  # fmt: skip
        assert _wait_exit(play, 60) == 0, play.stop()
        page.wait_for_function(
            f"() => {{ const s = ({PAGE_MAP})(); return s && s.known === {int((want != -1).sum())}"
            " && s.status.every((l) => l === 'ok'); }",
            polling=250,
            timeout=20000,
        )
        shown = page.evaluate(PAGE_MAP)
        cells = np.asarray(page.evaluate("() => Array.from(viz.data.map.cells)"), dtype=np.int8)
        assert not errors, errors
    finally:
        browser.close()
        pw.stop()
        dashboard.stop()
    info = last.info
    assert (shown["w"], shown["h"]) == (info.width, info.height)
    assert shown["res"] == pytest.approx(info.resolution)
    assert (shown["ox"], shown["oy"]) == pytest.approx(
        (info.origin.position.x, info.origin.position.y)
    )
    assert np.array_equal(cells, want)  # every cell, known or not, as the last /map has it
