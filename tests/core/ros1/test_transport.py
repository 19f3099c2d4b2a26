"""The ROS 1 transport: a roverlab context's nodes in a real ROS 1 graph (Debian's
rosmaster, rospy, rostopic), messages in ROS 1's bytes both ways, latched topics."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from typing import Any

from roverlab.core.context import Context
from roverlab.core.qos import QoSProfile
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.msgs import classes as mc
from roverlab.msgs import get_service_type
from tests.core.ros1.conftest import (
    DATA,
    SCRIPTS,
    needs_ros1,
    run_ros,
    start_ros,
    stop,
    wait_master,
)
from tests.helpers.net import free_port


def test_roverlab_nodes_are_ros1_nodes(real_master: str) -> None:
    ctx = Context(clock="wall")
    transport = Ros1Transport(real_master)
    ctx.add_transport(transport)
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/ros_in")
    try:
        node = ctx.create_node("rl_node")
        got: list[Any] = []
        node.create_subscription(mc.String, "/ros_in", got.append, 10)
        latched = QoSProfile(depth=1, durability="transient_local")
        node.create_publisher(mc.String, "/rl_latched", latched).publish(mc.String(data="kept"))
        pub = node.create_publisher(mc.String, "/rl_out", 10)
        thread = ctx.spin_in_thread()
        listener = start_ros(
            real_master, "/usr/bin/python3", str(SCRIPTS / "listener.py"), "/rl_out", "3"
        )
        end = time.monotonic() + 30
        while listener.poll() is None and time.monotonic() < end:
            pub.publish(mc.String(data="from roverlab"))
            time.sleep(0.05)
        assert listener.returncode == 0
        echo = run_ros(real_master, "/usr/bin/rostopic", "echo", "-n", "1", "/rl_latched")
        assert 'data: "kept"' in echo.stdout
        topics = run_ros(real_master, "/usr/bin/rostopic", "list").stdout.split()
        assert {"/rl_out", "/rl_latched", "/ros_in"} <= set(topics)
        assert len(got) >= 3 and got[-1].data.startswith("hello ")
        assert transport.received >= 3 and transport.sent >= 3
        ctx.shutdown()
        thread.join(5)
    finally:
        stop(talker)
        transport.close()


def test_roverlab_topic_echo_and_pub_with_rospy(real_master: str) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    cli = [sys.executable, "-m", "roverlab.cli", "topic"]
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/cli_in")
    listener = start_ros(
        real_master, "/usr/bin/python3", str(SCRIPTS / "listener.py"), "/cli_out", "2"
    )
    pub = subprocess.Popen(
        [*cli, "pub", "/cli_out", "std_msgs/String", "{data: from the cli}", "-r", "10"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        echo = subprocess.run(
            [*cli, "echo", "/cli_in", "-n", "2", "--timeout", "30"],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert echo.returncode == 0, echo.stderr
        assert echo.stdout.count('data: "hello') + echo.stdout.count("data: hello") == 2
        assert listener.wait(30) == 0
        assert listener.stdout is not None and "from the cli" in listener.stdout.read()
        stop(pub)  # SIGTERM: the command unregisters on its way out, as a rospy node
        nodes = run_ros(real_master, "/usr/bin/rosnode", "list").stdout.split()
        assert "/roverlab_topic_pub" not in nodes and "/roverlab_topic_echo" not in nodes
    finally:
        for proc in (pub, talker, listener):
            stop(proc)


def test_real_ros1_tools_see_roverlab_sim(real_master: str) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    sim = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "sim", "--world", "empty", "--duration", "60"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        lookup = run_ros(
            real_master, "/usr/bin/python3", str(SCRIPTS / "tf_lookup.py"), "odom", "base_link"
        )
        assert lookup.returncode == 0, lookup.stderr[-2000:]
        assert lookup.stdout.startswith("odom -> base_link: ")
        topics = set(run_ros(real_master, "/usr/bin/rostopic", "list").stdout.split())
        assert {"/scan", "/odom", "/tf", "/tf_static", "/clock", "/cmd_vel"} <= topics
        scan = run_ros(real_master, "/usr/bin/rostopic", "echo", "-n", "1", "--noarr", "/scan")
        assert "frame_id: " in scan.stdout and "range_max" in scan.stdout
        assert (
            run_ros(real_master, "/usr/bin/rosparam", "get", "/use_sim_time").stdout.strip()
            == "true"
        )
        # a second roverlab process reaches the simulator through the ROS 1 graph
        tf = subprocess.run(
            [sys.executable, "-m", "roverlab.cli", "tf", "echo", "odom", "base_link", "-n", "1"],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert tf.returncode == 0 and "- Translation: [" in tf.stdout, tf.stderr
        urdf = run_ros(real_master, "/usr/bin/rosparam", "get", "/robot_description")
        assert "<robot" in urdf.stdout  # a parameter in ROS 1, a latched topic in roverlab
    finally:
        stop(sim)
        run_ros(real_master, "/usr/bin/rosparam", "delete", "/use_sim_time")
        run_ros(real_master, "/usr/bin/rosparam", "delete", "/robot_description")


def test_services_both_ways_with_rospy_and_rosservice(real_master: str) -> None:
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    server = start_ros(
        real_master, "/usr/bin/python3", str(SCRIPTS / "set_bool_server.py"), "/rospy_set"
    )
    ctx = Context(clock="wall")
    transport = Ros1Transport(real_master)
    ctx.add_transport(transport)
    try:
        node = ctx.create_node("rl_server")

        def on_call(req: Any, resp: Any) -> Any:
            if not req.data:
                raise ValueError("roverlab refuses false")
            resp.success, resp.message = True, "roverlab got true"
            return resp

        node.create_service(get_service_type("std_srvs/srv/SetBool"), "/rl_set", on_call)
        thread = ctx.spin_in_thread()
        info = run_ros(real_master, "/usr/bin/rosservice", "info", "/rl_set")  # a probe
        assert "Node: /rl_server" in info.stdout and "Type: std_srvs/SetBool" in info.stdout
        ok = run_ros(real_master, "/usr/bin/rosservice", "call", "/rl_set", "data: true")
        assert ok.returncode == 0 and 'message: "roverlab got true"' in ok.stdout
        bad = run_ros(real_master, "/usr/bin/rosservice", "call", "/rl_set", "data: false")
        assert bad.returncode != 0 and "roverlab refuses false" in bad.stderr
        assert server.stdout is not None and server.stdout.readline().strip() == "ready"
        cli = [sys.executable, "-m", "roverlab.cli", "service", "call", "/rospy_set"]
        got = subprocess.run(
            [*cli, "{data: true}"], env=env, capture_output=True, text=True, timeout=60
        )
        assert got.returncode == 0, got.stderr
        assert "success: true" in got.stdout and "message: rospy got true" in got.stdout
        refused = subprocess.run(
            [*cli, "{data: false}"], env=env, capture_output=True, text=True, timeout=60
        )
        assert refused.returncode == 2
        assert refused.stderr.strip().endswith("refusing false")
        ctx.shutdown()
        thread.join(5)
    finally:
        stop(server)
        transport.close()


@needs_ros1
def test_launch_starts_a_master_and_puts_its_parameters_there() -> None:
    uri = f"http://127.0.0.1:{free_port()}/"  # nothing listens here: the launch starts a master
    env = {**os.environ, "ROS_MASTER_URI": uri, "ROS_HOSTNAME": "127.0.0.1"}
    launch_file = str(DATA / "map_server.launch")
    launch = subprocess.Popen(
        [sys.executable, "-m", "roverlab.cli", "launch", launch_file, "--clock", "wall"],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        wait_master(uri, 60.0)
        greeting = run_ros(uri, "/usr/bin/rosparam", "get", "/greeting")
        assert greeting.stdout.strip() == "hello from a launch"
        grid = run_ros(uri, "/usr/bin/rostopic", "echo", "-n", "1", "--noarr", "/map")
        assert "width: 216" in grid.stdout and "height: 176" in grid.stdout
    finally:
        stop(launch)
    assert launch.stderr is not None
    assert f"note: started a ROS master at {uri} (nothing answered there)" in launch.stderr.read()


def test_roverlab_run_rospy_script_joins_the_ros1_graph(real_master: str) -> None:
    """The issue's first complaint: `roverlab run listener.py` with ROS_MASTER_URI set
    heard nothing from a real talker; and rospy.get_param/set_param reach the master."""
    env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
    run = [sys.executable, "-m", "roverlab.cli", "run"]
    assert run_ros(real_master, "/usr/bin/rosparam", "set", "/greeting", "hi").returncode == 0
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/run_in")
    try:
        heard = subprocess.run(
            [*run, str(SCRIPTS / "listener.py"), "/run_in", "3"],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert heard.returncode == 0, heard.stderr
        assert heard.stdout.count("hello ") >= 3
        params = subprocess.run(
            [*run, str(SCRIPTS / "params_rw.py")],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert params.returncode == 0, params.stderr
        assert "greeting: hi" in params.stdout
        assert run_ros(real_master, "/usr/bin/rosparam", "get", "/answer").stdout.strip() == "42"
    finally:
        stop(talker)
