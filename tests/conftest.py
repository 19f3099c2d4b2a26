"""Shared fixtures: an isolated roverlab daemon per test session, child processes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.helpers.net import free_port
from tests.helpers.procs import Proc

HELPERS = Path(__file__).parent / "helpers"
REPO = Path(__file__).resolve().parents[1]


# A shell without job control starts background commands with SIGINT ignored (POSIX), and
# an ignored signal stays ignored in every child: `make test &` would make every Ctrl-C
# test fail (the commands under test would never see their SIGINT). The tests' children
# get SIGINT's default back (a caught signal is reset to the default at exec).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session", autouse=True)
def _mesh_cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """Processed meshes go to a per-session folder, not the user's ~/.cache."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROVERLAB_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="session", autouse=True)
def _private_daemon_endpoint(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """ROVERLAB_DAEMON points every process of the session at a free loopback port of its
    own, so no test can join (or start) the machine's default daemon, which a user's live
    system may be using; a daemon something started there is stopped at the end."""
    from roverlab.core.transport.daemon import stop_daemon

    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("ROVERLAB_DAEMON", endpoint)
        mp.setenv("ROVERLAB_LOG_DIR", str(tmp_path_factory.mktemp("log")))
        yield endpoint
        stop_daemon(endpoint)


@pytest.fixture(scope="session")
def daemon(_private_daemon_endpoint: str) -> str:
    """The session's daemon, started on its private port (see above)."""
    from roverlab.core.transport.daemon import ensure_daemon

    ensure_daemon(_private_daemon_endpoint)
    return _private_daemon_endpoint


@pytest.fixture
def node_proc(daemon: str) -> Iterator[object]:
    """Start ``tests/helpers/node_proc.py MODE`` processes; stopped at teardown."""
    procs: list[Proc] = []

    def start(mode: str) -> Proc:
        p = Proc([sys.executable, str(HELPERS / "node_proc.py"), mode])
        procs.append(p)
        assert p.wait_line(lambda line: line.startswith("READY")) == "READY"
        return p

    yield start
    for p in procs:
        p.stop()


@pytest.fixture
def cli(daemon: str) -> object:
    """Run ``roverlab ARGS`` in a subprocess; returns CompletedProcess."""

    def run(*args: str, timeout: float = 30.0) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "roverlab.cli", *args],
            capture_output=True,
            text=True,
            timeout=timeout,
            env=dict(os.environ),
        )

    return run
