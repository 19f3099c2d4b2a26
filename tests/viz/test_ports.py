"""The one port rule of the pages: ``--port`` > ``$ROVERLAB_DASHBOARD_PORT`` > 8080; a port
the user chose that is taken is one error line naming it and its option; the default port,
taken, gives way to the next free one, said aloud."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from collections.abc import Iterator

import pytest

from roverlab.core import Context
from roverlab.viz import ports
from roverlab.viz.errors import DashboardError
from roverlab.viz.launcher import start_image_view, start_rviz
from roverlab.viz.ports import PORT_ENV, PortChoice, PortTakenError, choose_port, start_page
from roverlab.viz.server import DashboardServer


@pytest.fixture
def taken() -> Iterator[int]:
    """A loopback port something listens on."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield int(s.getsockname()[1])


def test_option_then_variable_then_8080(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(PORT_ENV, raising=False)
    assert choose_port(None) == PortChoice(8080, "")
    monkeypatch.setenv(PORT_ENV, "18090")
    assert choose_port(None) == PortChoice(18090, PORT_ENV)
    assert choose_port(18091) == PortChoice(18091, "--port")
    assert choose_port(0, option_name="--dashboard-port") == PortChoice(0, "--dashboard-port")
    monkeypatch.setenv(PORT_ENV, "eighty")
    with pytest.raises(DashboardError, match=f"{PORT_ENV} must be a port number, got 'eighty'"):
        choose_port(None)
    with pytest.raises(DashboardError, match=r"--port must be a port 0\.\.65535, got 70000"):
        choose_port(70000)


def test_a_taken_port_the_user_chose_is_an_error_naming_it(
    taken: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    ctx = Context()
    said: list[str] = []
    server = DashboardServer(ctx, "127.0.0.1", taken, node_name="rviz_a")
    with pytest.raises(PortTakenError, match=f"^port {taken} \\(--port\\) is taken: [^\n]*$"):
        start_page(server, choose_port(taken), say=said.append)
    # the default port taken: the next free one, said aloud
    monkeypatch.setattr(ports, "DEFAULT_PORT", taken)
    monkeypatch.delenv(PORT_ENV, raising=False)
    choice = choose_port(None)
    server = DashboardServer(ctx, "127.0.0.1", choice.port, node_name="rviz_b")
    start_page(server, choice, say=said.append)
    try:
        assert server.port != taken
        assert said == [
            f"port {taken} is taken; serving on {server.port} instead "
            f"(choose one with --port N or {PORT_ENV}=N)"
        ]
    finally:
        server.stop()
        ctx.shutdown()


def test_launch_pages_follow_the_rule(taken: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """A launch's rviz on the default port that is taken serves on the next free one and
    says so; rqt_image_view beside it does the same on ``$ROVERLAB_DASHBOARD_PORT``."""
    monkeypatch.setattr(ports, "DEFAULT_PORT", taken)
    monkeypatch.delenv(PORT_ENV, raising=False)
    ctx = Context()
    warnings: list[str] = []
    rviz = start_rviz(ctx, "", source="x.launch", warn=warnings.append)
    assert rviz is not None and rviz.server.port != taken
    assert warnings == [
        f"x.launch: rviz: port {taken} is taken; serving on {rviz.server.port} instead "
        f"(choose one with --port N or {PORT_ENV}=N)"
    ]
    monkeypatch.setenv(PORT_ENV, str(rviz.server.port))
    view = start_image_view(ctx, "/image", remaps={}, warn=warnings.append)
    assert view is not None and view.server.port not in (taken, rviz.server.port)
    ctx.shutdown()


def test_image_view_on_a_taken_port_is_one_line(taken: int) -> None:
    run = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "image", "view", "/image_raw"],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, PORT_ENV: str(taken)},
    )
    assert run.returncode == 2
    assert run.stderr.strip().splitlines() == [
        f"error: port {taken} ({PORT_ENV}) is taken: another dashboard or program serves "
        f"there; choose another with --port N or {PORT_ENV}=N (0: any free port)"
    ]
