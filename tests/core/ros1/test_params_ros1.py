"""A roverlab node's declared parameters on a real master's parameter server: the real
``rosparam get`` reads them under the node's name (``a.b`` as ``/node/a/b``), and a
``rosparam set`` reaches the running node (paramUpdate) through its set-parameters
callback, which may refuse it."""

from __future__ import annotations

import os
import subprocess
import sys
import time

from tests.core.ros1.conftest import SCRIPTS, run_ros, stop


def test_declared_parameters_are_on_the_master_and_rosparam_set_reaches_the_node(
    real_master: str,
) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    node = subprocess.Popen(
        [sys.executable, str(SCRIPTS / "param_node.py")],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert node.stdout is not None and node.stdout.readline().strip() == "READY"

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
