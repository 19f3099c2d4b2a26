"""One port rule for every command that serves a page (dashboard, image view, demo, sim
``--dashboard``, a launch's rviz and rqt_image_view).

The port is ``--port`` when given, else ``$ROVERLAB_DASHBOARD_PORT``, else 8080
(:func:`choose_port`). A port the user chose (the option or the variable) that is taken is
one clear error naming the port and where it came from; the default port, when taken, gives
way to the next free one, and the caller says so (:func:`start_page`). 0 picks any free port.
"""

from __future__ import annotations

import errno
import os
import socket
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final, Protocol

from roverlab.viz.errors import DashboardError

__all__ = [
    "DEFAULT_PORT",
    "PORT_ENV",
    "PortChoice",
    "PortTakenError",
    "check_port",
    "choose_port",
    "start_page",
]

DEFAULT_PORT: Final = 8080
PORT_ENV: Final = "ROVERLAB_DASHBOARD_PORT"
NEXT_FREE_TRIES: Final = 50
"""How many ports after a taken default one are tried before any free port is taken."""


class PortTakenError(DashboardError):
    """The port to serve on is in use (another dashboard, or another program)."""

    def __init__(self, message: str, port: int) -> None:
        super().__init__(message)
        self.port = port


@dataclass(frozen=True)
class PortChoice:
    """The port to serve a page on and where it came from.

    Attributes:
        port: 0..65535 (0: any free port).
        source: the option's name (``--port``), :data:`PORT_ENV`, or ``""`` for the default.
    """

    port: int
    source: str = ""

    @property
    def chosen(self) -> bool:
        """The user named this port (a taken one is an error, not a detour)."""
        return bool(self.source)


def choose_port(option: int | None, *, option_name: str = "--port") -> PortChoice:
    """``option`` (the command's ``--port``) > ``$ROVERLAB_DASHBOARD_PORT`` > 8080.

    Raises:
        DashboardError: a port out of 0..65535, or a variable that is not a number.
    """
    if option is not None:
        choice = PortChoice(option, option_name)
    else:
        text = os.environ.get(PORT_ENV, "").strip()
        if not text:
            return PortChoice(DEFAULT_PORT)
        try:
            choice = PortChoice(int(text), PORT_ENV)
        except ValueError:
            raise DashboardError(f"{PORT_ENV} must be a port number, got {text!r}") from None
    if not 0 <= choice.port <= 65535:
        raise DashboardError(f"{choice.source} must be a port 0..65535, got {choice.port}")
    return choice


def _taken(choice: PortChoice) -> PortTakenError:
    return PortTakenError(
        f"port {choice.port} ({choice.source}) is taken: another dashboard or program "
        f"serves there; choose another with --port N or {PORT_ENV}=N (0: any free port)",
        choice.port,
    )


def check_port(host: str, choice: PortChoice) -> None:
    """Fail at once, before a command connects to the network, when the user's port is
    taken (:func:`start_page` checks again when it binds).

    Raises:
        PortTakenError: ``choice`` is the user's and something listens there.
    """
    if not choice.chosen or choice.port == 0:
        return
    try:
        infos = socket.getaddrinfo(host, choice.port, type=socket.SOCK_STREAM)
    except OSError:
        return  # a bad host is the server's to report
    family, _, _, _, address = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind(address)
        except OSError as err:
            if err.errno == errno.EADDRINUSE:
                raise _taken(choice) from err


class _Page(Protocol):
    port: int

    def start(self, *, next_free: bool = False) -> None: ...


def start_page(page: _Page, choice: PortChoice, *, say: Callable[[str], None]) -> None:
    """Start ``page`` (a :class:`~roverlab.viz.server.DashboardServer`) on ``choice``; when
    the default port is taken it serves on the next free one and ``say`` tells which.

    Raises:
        PortTakenError: the user's port is taken (the message names it and its option).
        DashboardError: the page could not be served for another reason.
    """
    try:
        page.start(next_free=not choice.chosen)
    except PortTakenError as err:
        if choice.chosen:
            raise _taken(choice) from err
        raise
    if page.port != choice.port and choice.port != 0:
        say(
            f"port {choice.port} is taken; serving on {page.port} instead "
            f"(choose one with --port N or {PORT_ENV}=N)"
        )
