"""``roverlab roscore`` against Debian's real ROS 1: rospy talker/listener, rosparam,
rostopic and rosnode work against it unchanged; /rosout gathers on /rosout_agg; paramUpdate
reaches a subscribed node."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
from typing import Any

from roverlab.core.transport.ros1.master import Master
from roverlab.core.transport.ros1.xmlrpc import XmlRpcServer, call
from tests.core.ros1.conftest import SCRIPTS, needs_ros1, run_ros, start_ros, stop
from tests.helpers.net import free_port


@needs_ros1
def test_real_ros_tools_and_rospy_nodes_against_roverlab_roscore(roverlab_master: str) -> None:
    uri = roverlab_master
    assert run_ros(uri, "/usr/bin/rosparam", "set", "/robot/max_speed", "0.5").returncode == 0
    assert run_ros(uri, "/usr/bin/rosparam", "set", "/robot/name", "rover").returncode == 0
    got = run_ros(uri, "/usr/bin/rosparam", "get", "/robot")
    assert got.returncode == 0 and "max_speed: 0.5" in got.stdout and "name: rover" in got.stdout
    assert run_ros(uri, "/usr/bin/rosparam", "get", "/run_id").stdout.count("-") == 4
    talker = start_ros(uri, "/usr/bin/python3", str(SCRIPTS / "talker.py"))
    try:
        heard = run_ros(uri, "/usr/bin/python3", str(SCRIPTS / "listener.py"), "chatter", "3")
        assert heard.returncode == 0, heard.stderr
        assert heard.stdout.count("hello") == 3
        assert "/chatter" in run_ros(uri, "/usr/bin/rostopic", "list").stdout.split()
        echo = run_ros(uri, "/usr/bin/rostopic", "echo", "-n", "1", "/chatter")
        assert 'data: "hello' in echo.stdout
        assert any(
            n.startswith("/talker_")
            for n in run_ros(uri, "/usr/bin/rosnode", "list").stdout.split()
        )
        agg = run_ros(uri, "/usr/bin/rostopic", "echo", "-n", "1", "/rosout_agg")
        assert 'msg: "talker said hello' in agg.stdout  # roscore's /rosout node
    finally:
        stop(talker)


def test_roscore_port_in_use_is_one_line_exit_2(roverlab_master: str) -> None:
    port = roverlab_master.rstrip("/").rsplit(":", 1)[1]
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "master", "-p", port],
        capture_output=True,
        text=True,
        timeout=30,
    )
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == [
        f"error: cannot listen on 127.0.0.1:{port}: Address already in use "
        "(another roscore running? try -p PORT)"
    ]


def test_master_api_and_param_updates_one_per_node() -> None:
    master = Master(port=free_port())
    master.start()
    node = XmlRpcServer("127.0.0.1", 0)
    updates: list[tuple[str, Any]] = []
    heard = threading.Event()

    def param_update(caller: str, key: str, value: Any) -> list[Any]:
        updates.append((key, value))
        heard.set()
        return [1, "", 0]

    node.add("paramUpdate", param_update)
    told_to_stop = threading.Event()
    node.add("shutdown", lambda caller, msg="": (told_to_stop.set(), [1, "", 0])[1])
    threading.Thread(target=node.serve_forever, daemon=True).start()
    uri = master.uri
    try:
        assert call(uri, "subscribeParam", "/ns/node", node.uri, "~gain") == {}
        call(uri, "setParam", "/other", "/ns/node/gain", 2.5)
        assert heard.wait(5.0)
        assert updates == [("/ns/node/gain/", 2.5)]
        assert call(uri, "searchParam", "/ns/node", "gain") == "/ns/node/gain"
        assert call(uri, "getParam", "/ns/x", "node") == {"gain": 2.5}
        subs = call(uri, "registerPublisher", "/ns/node", "out", "std_msgs/String", node.uri)
        assert subs == []
        assert call(uri, "lookupNode", "/x", "/ns/node") == node.uri
        assert ["/ns/out", "std_msgs/String"] in call(uri, "getTopicTypes", "/x")
        pubs, _, _ = call(uri, "getSystemState", "/x")
        assert ["/ns/out", ["/ns/node"]] in pubs
        assert call(uri, "hasParam", "/x", "/nothing") is False
        # the same name registered from another URI: the old node is told to shut down
        call(uri, "registerSubscriber", "/ns/node", "/in", "std_msgs/String", "http://127.0.0.1:9/")
        assert told_to_stop.wait(5.0)
        assert call(uri, "lookupNode", "/x", "/ns/node") == "http://127.0.0.1:9/"
        pubs, _, _ = call(uri, "getSystemState", "/x")
        assert ["/ns/out", ["/ns/node"]] not in pubs  # the old node's registrations went
    finally:
        node.shutdown()
        node.server_close()
        master.stop()


@needs_ros1
def test_roverlab_param_and_real_rosparam_share_the_parameter_server(
    roverlab_master: str,
) -> None:
    uri = roverlab_master
    env = {**os.environ, "ROS_MASTER_URI": uri}
    param = [sys.executable, "-m", "roverlab.cli", "param"]
    assert (
        run_ros(uri, "/usr/bin/rosparam", "set", "/amcl", "{laser: {max_beams: 30}}").returncode
        == 0
    )
    got = subprocess.run(
        [*param, "get", "/amcl", "laser.max_beams"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert got.returncode == 0 and got.stdout.strip() == "30", got.stderr
    done = subprocess.run(
        [*param, "set", "/amcl", "min_particles", "200"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert run_ros(uri, "/usr/bin/rosparam", "get", "/amcl/min_particles").stdout.strip() == "200"
