"""An unreachable ROS master: a node waits for it (as rospy and roscpp nodes do), saying so
in one line naming the URI; a one-shot tool fails at once (as rostopic does)."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import pytest

from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.master import Master
from roverlab.core.transport.ros1.xmlrpc import call, wait_for_master
from tests.core.ros1.conftest import SCRIPTS, stop
from tests.helpers.net import free_port


def test_one_shot_tools_fail_at_once_naming_the_master() -> None:
    uri = f"http://127.0.0.1:{free_port()}/"
    with pytest.raises(MasterError, match=f"no ROS master at {uri}"):
        wait_for_master(uri, None)
    env = {**os.environ, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "127.0.0.1"}
    t0 = time.monotonic()
    out = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "topic", "list"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and uri in lines[0], out.stderr
    assert "Traceback" not in out.stderr
    assert time.monotonic() - t0 < 20


def test_wait_for_master_retries_and_reports_until_it_answers() -> None:
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    lines: list[str] = []
    masters: list[Master] = []

    def start() -> None:
        masters.append(Master(host="127.0.0.1", port=port))
        masters[0].start()

    timer = threading.Timer(1.0, start)
    timer.start()
    try:
        wait_for_master(uri, lines.append, retry_s=0.1, remind_s=0.4)
    finally:
        timer.join()
        for m in masters:
            m.stop()
    assert lines[0].startswith(f"unable to register with the ROS master at {uri}")
    assert any(line.startswith(f"still no ROS master at {uri}") for line in lines[1:-1])
    assert lines[-1] == f"reached the ROS master at {uri}"
    assert all("\n" not in line for line in lines)


def test_a_node_started_before_the_master_registers_once_it_comes() -> None:
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    env = {**os.environ, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "127.0.0.1"}
    node = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "run", str(SCRIPTS / "talker.py"), "/early"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    master = None
    try:
        assert node.stderr is not None
        first = node.stderr.readline()
        assert f"unable to register with the ROS master at {uri}" in first, first
        assert node.poll() is None  # still waiting, not failed
        master = Master(host="127.0.0.1", port=port)
        master.start()
        end = time.monotonic() + 30
        pubs: list[list[str]] = []
        while time.monotonic() < end:
            pubs = call(uri, "getSystemState", "/test")[0]
            if any(topic == "/early" for topic, _ in pubs):
                break
            time.sleep(0.2)
        assert any(topic == "/early" for topic, _ in pubs), pubs
        assert node.stderr.readline().strip() == f"warning: reached the ROS master at {uri}"
    finally:
        stop(node)
        if master is not None:
            master.stop()
