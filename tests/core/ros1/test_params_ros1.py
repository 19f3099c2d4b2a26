"""A roverlab node's declared parameters on a real master's parameter server: the real
``rosparam get`` reads them under the node's name (``a.b`` as ``/node/a/b``), a
``rosparam set`` reaches the running node (paramUpdate) through its set-parameters
callback, which may refuse it, and one made before the node starts wins over its default;
the dashboard follows /robot_description on the master."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from roverlab.core import Context
from roverlab.core.transport.ros1.master import Master
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.viz.bridge import VizBridge
from roverlab.viz.config import DashboardConfig, DisplayConfig
from tests.core.ros1.conftest import SCRIPTS, run_ros, stop
from tests.helpers.net import free_port


def _param_node(master: str, *args: str) -> subprocess.Popen[str]:
    """scripts/param_node.py (a roverlab node) under ``master``."""
    env = {**os.environ, "ROS_MASTER_URI": master, "ROS_HOSTNAME": "127.0.0.1"}
    return subprocess.Popen(
        [sys.executable, str(SCRIPTS / "param_node.py"), *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_declared_parameters_are_on_the_master_and_rosparam_set_reaches_the_node(
    real_master: str,
) -> None:
    node = _param_node(real_master)
    try:
        assert node.stdout is not None
        assert node.stdout.readline().strip() == "READY 0.5 slow 12.0 odom"

        def get(name: str) -> str:
            deadline = time.monotonic() + 10
            while True:
                out = run_ros(real_master, "/usr/bin/rosparam", "get", name)
                if out.returncode == 0 or time.monotonic() > deadline:
                    return out.stdout.strip()
                time.sleep(0.2)

        assert get("/param_node/speed") == "0.5"
        assert get("/param_node/mode") == "slow"
        assert get("/param_node/limits/max_range") == "12.0"
        assert get("/param_node/frame") == "odom"
        unset = run_ros(real_master, "/usr/bin/rosparam", "get", "/param_node/unset")
        assert unset.returncode != 0 and "not set" in unset.stderr + unset.stdout
        assert (
            run_ros(real_master, "/usr/bin/rosparam", "set", "/param_node/speed", "0.8").returncode
            == 0
        )
        assert node.stdout.readline().strip() == "SET speed 0.8"
        # refused by the node's callback: the node keeps 0.8 and says why
        assert (
            run_ros(real_master, "/usr/bin/rosparam", "set", "/param_node/speed", "-1.0").returncode
            == 0
        )
        run_ros(real_master, "/usr/bin/rosparam", "set", "/param_node/limits/max_range", "6.0")
        assert node.stdout.readline().strip() == "SET limits.max_range 6.0"
    finally:
        node.send_signal(2)
        try:
            _, err = node.communicate(timeout=10)
        finally:
            stop(node)
    assert "speed must be >= 0" in err


def test_values_set_on_the_master_before_a_node_starts_win_over_its_defaults(
    real_master: str,
) -> None:
    """As a rospy node reads ``~speed`` at start: what ``rosparam set`` put there first
    wins over the default (an override from the launch over both; a value of the wrong
    type is one warning line and the default stays)."""
    for name, value in (
        ("/early_node/speed", "0.7"),
        ("/early_node/mode", "fast"),
        ("/early_node/limits/max_range", "far"),
        ("/early_node/frame", "map"),
    ):
        assert run_ros(real_master, "/usr/bin/rosparam", "set", name, value).returncode == 0
    node = _param_node(real_master, "early_node")
    try:
        assert node.stdout is not None
        assert node.stdout.readline().strip() == "READY 0.7 fast 12.0 odom"
    finally:
        node.send_signal(2)
        try:
            _, err = node.communicate(timeout=10)
        finally:
            stop(node)
    assert "/early_node/limits/max_range = 'far' not used" in err


def _urdf(link: str, size: float) -> str:
    return (
        f'<robot name="r"><link name="{link}"><visual><geometry><box size="{size} {size} 0.1"/>'
        "</geometry></visual></link></robot>"
    )


def test_dashboard_reads_robot_description_again_when_it_is_set() -> None:
    """The dashboard on a ROS 1 graph takes /robot_description from the master, and again
    each time it is set there (paramUpdate), as a changed robot does."""
    port = free_port()
    uri = f"http://127.0.0.1:{port}/"
    master = Master(host="127.0.0.1", port=port)
    master.start()
    ctx = Context(clock="wall", publish_clock=False)
    try:
        call(uri, "setParam", "/test", "/robot_description", _urdf("base_link", 0.4))
        ctx.add_transport(Ros1Transport(uri))
        bridge = VizBridge(
            context=ctx,
            config=DashboardConfig(
                fixed_frame="base_link",
                displays=[DisplayConfig("robot_model", "Robot", True, "/robot_description")],
            ),
        )
        ctx.spin_in_thread()
        assert [s["link"] for s in bridge.shapes] == ["base_link"]
        call(uri, "setParam", "/test", "/robot_description", _urdf("chassis", 0.6))
        end = time.monotonic() + 10
        while [s["link"] for s in bridge.shapes] != ["chassis"] and time.monotonic() < end:
            time.sleep(0.05)
        assert [s["link"] for s in bridge.shapes] == ["chassis"]
    finally:
        ctx.shutdown()
        master.stop()
