"""Fixtures for the ROS 1 wire tests: Debian's real ROS 1 beside roverlab's.

Every process listens on loopback only, on a port free when its fixture starts (two test
workers, or anything else on the machine, may hold a fixed one), and is stopped at the end of
its module. Tests that need real ROS 1 skip with one line when /usr/bin/roscore is missing.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.xmlrpc import call
from tests.helpers.net import free_port

SCRIPTS = Path(__file__).parent / "scripts"
DATA = Path(__file__).parent / "data"
HAVE_ROS1 = Path("/usr/bin/roscore").exists()
needs_ros1 = pytest.mark.skipif(
    not HAVE_ROS1, reason="Debian's ROS 1 (/usr/bin/roscore) is not installed"
)


def ros_env(master_uri: str) -> dict[str, str]:
    """The environment for a real ROS 1 process (Debian's python, not the venv)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env.update(
        ROS_MASTER_URI=master_uri, ROS_HOSTNAME="127.0.0.1", ROS_LOG_DIR="/tmp/roverlab-ros-log"
    )
    env["PATH"] = "/usr/bin:/bin"
    return env


def wait_master(uri: str, timeout_s: float = 20.0) -> None:
    end = time.monotonic() + timeout_s
    while True:
        try:
            call(uri, "getUri", "/test", timeout_s=1.0)
            return
        except MasterError:
            if time.monotonic() > end:
                raise
            time.sleep(0.1)


def stop(proc: subprocess.Popen[bytes] | subprocess.Popen[str]) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def run_ros(
    master_uri: str, *args: str, timeout_s: float = 30.0
) -> subprocess.CompletedProcess[str]:
    """Run a real ROS 1 command line tool or script to completion."""
    return subprocess.run(
        list(args), env=ros_env(master_uri), capture_output=True, text=True, timeout=timeout_s
    )


def start_ros(master_uri: str, *args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        list(args),
        env=ros_env(master_uri),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.fixture(scope="module")
def real_master() -> Iterator[str]:
    """Debian's real rosmaster (the master roscore starts) on a free loopback port."""
    if not HAVE_ROS1:
        pytest.skip("Debian's ROS 1 (/usr/bin/roscore) is not installed")
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    proc = subprocess.Popen(
        ["/usr/bin/rosmaster", "--core", "-p", str(port), "-w", "2"],
        env=ros_env(uri),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_master(uri)
        yield uri
    finally:
        stop(proc)


@pytest.fixture(scope="module")
def roverlab_master() -> Iterator[str]:
    """``roverlab roscore -p PORT`` as its own process, on a free loopback port."""
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    proc = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "roscore", "-p", str(port)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    try:
        wait_master(uri)
        yield uri
    finally:
        stop(proc)
