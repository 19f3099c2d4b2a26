"""The dashboard's server without a simulation or a browser: it refuses a wrong token (on
its pages, its config and its websocket), gives a token to a server open beyond loopback, and
serves its vendored three.js with the licence."""

from __future__ import annotations

import socket
import urllib.error
import urllib.request

from roverlab.core import Context
from roverlab.viz import DashboardServer
from tests.helpers.net import free_port


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
    port = free_port()
    server = DashboardServer(ctx, "127.0.0.1", port, token="s3cret")
    ctx.spin_in_thread()
    server.start()
    try:
        base = f"http://127.0.0.1:{port}"
        assert _http_status(base + "/?token=wrong") == 403
        assert _http_status(base + "/") == 403
        assert _http_status(base + "/?token=s3cret") == 200
        assert _http_status(base + "/config?token=wrong") == 403
        assert _http_status(base + "/config?token=s3cret") == 200
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


def test_vendored_three_js_is_served_with_its_licence() -> None:
    """three.js for the 3D view comes from the npm registry (pinned, scripts/vendor-three.sh)
    and the dashboard serves it itself, licence included: no CDN."""
    ctx = Context(clock="wall")
    port = free_port()
    server = DashboardServer(ctx, "127.0.0.1", port)
    ctx.spin_in_thread()
    server.start()
    try:
        base = f"http://127.0.0.1:{port}/static/vendor/three"
        with urllib.request.urlopen(f"{base}/three.module.min.js", timeout=5) as resp:
            head = resp.read(400).decode()
        assert "Copyright 2010-2024 Three.js Authors" in head and 'const t="170"' in head
        with urllib.request.urlopen(f"{base}/LICENSE", timeout=5) as resp:
            assert "The MIT License" in resp.read().decode()
        with urllib.request.urlopen(f"{base}/VERSION", timeout=5) as resp:
            assert resp.read().decode().startswith("three@0.170.0 (sha512-")
        assert _http_status(f"{base}/addons/controls/OrbitControls.js") == 200
    finally:
        server.stop()
        ctx.shutdown()
