"""The dashboard page itself in Debian's chromium (Playwright): it loads with nothing
missing (its icon included: no 404 in the console), hands its token to the requests it
makes of the server (``viz.withToken``) and reconnects when the server comes back."""

from __future__ import annotations

import urllib.request
from collections.abc import Iterator
from typing import Any

import pytest

from roverlab.core import Context
from roverlab.viz import DashboardServer
from tests.helpers.browser import CHROMIUM
from tests.helpers.net import free_port
from tests.viz.test_dashboard import VIEWPORT

playwright_sync = pytest.importorskip("playwright.sync_api", reason="playwright not installed")
pytestmark = pytest.mark.skipif(not CHROMIUM.exists(), reason="/usr/bin/chromium is absent")

TOKEN = "page-token"


@pytest.fixture(scope="module")
def server() -> Iterator[DashboardServer]:
    """A dashboard with nothing to show, asking for a token."""
    ctx = Context(clock="wall")
    dash = DashboardServer(ctx, "127.0.0.1", 0, token=TOKEN)
    ctx.spin_in_thread()
    dash.start()
    yield dash
    dash.stop()
    ctx.shutdown()


def test_page_loads_with_no_console_error_and_its_icon(
    server: DashboardServer, browser: Any
) -> None:
    page = browser.new_page()
    console: list[str] = []
    failed: list[str] = []
    page.on("console", lambda m: console.append(f"{m.type}: {m.text}"))
    page.on("pageerror", lambda e: console.append(f"pageerror: {e}"))
    page.on("requestfailed", lambda r: failed.append(r.url))
    page.on("response", lambda r: failed.append(f"{r.status} {r.url}") if r.status >= 400 else None)
    try:
        page.goto(server.url)
        page.wait_for_function("() => window.viz && viz.conn.connected && viz.cam", timeout=20000)
        page.wait_for_timeout(800)  # the browser asks for the icon after the page loaded
        errors = [line for line in console if line.startswith(("error", "pageerror"))]
        assert errors == [] and failed == [], (errors, failed)
        icon = page.evaluate("() => document.querySelector('link[rel=icon]').href")
        assert icon.endswith("/static/favicon.svg")
    finally:
        page.close()
    base = server.url.split("/?")[0]
    for path in ("/static/favicon.svg", "/favicon.ico"):  # the icon needs no token
        with urllib.request.urlopen(base + path, timeout=10) as reply:
            assert reply.headers["Content-Type"].startswith("image/svg+xml")
            assert reply.read().lstrip().startswith(b"<svg")


def test_page_requests_carry_its_token(server: DashboardServer, browser: Any) -> None:
    page = browser.new_page()
    try:
        page.goto(server.url)
        page.wait_for_function("() => window.viz && viz.conn.connected", timeout=20000)
        assert page.evaluate("() => viz.withToken('mesh/3')") == f"mesh/3?token={TOKEN}"
        href = page.evaluate("() => document.getElementById('download-config').href")
        assert href.endswith(f"/config?token={TOKEN}")
        status = page.evaluate("async () => (await fetch(viz.withToken('config'))).status")
        assert status == 200
    finally:
        page.close()


def test_page_reconnects_after_the_server_restarts(browser: Any) -> None:
    port = free_port()
    ctx1 = Context(clock="wall")
    first = DashboardServer(ctx1, "127.0.0.1", port)
    ctx1.spin_in_thread()
    first.start()
    pg = browser.new_page(viewport=VIEWPORT)
    ctx2 = Context(clock="wall")
    second = None
    try:
        pg.goto(first.url)
        pg.wait_for_function("() => viz.conn.connected", timeout=10000)
        first.stop()
        pg.wait_for_function(
            "() => document.getElementById('conn').textContent.includes('reconnecting')",
            timeout=10000,
        )
        second = DashboardServer(ctx2, "127.0.0.1", port)
        ctx2.spin_in_thread()
        second.start()
        pg.wait_for_function("() => viz.conn.connected", timeout=15000)
        assert pg.evaluate("() => viz.conn.attempts") >= 2
        assert pg.locator("#conn").inner_text() == "connected"
    finally:
        pg.close()
        if second is not None:
            second.stop()
        ctx1.shutdown()
        ctx2.shutdown()
