"""A launch's script node joins the graph the launch joined, however it joined: here a
launch connected to another machine's endpoint (127.0.0.1 standing for the robot) with a
user and password; the script's topics reach that side, and the password is never on a
command line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from roverlab.cli.common import NetworkOptions
from roverlab.core import Context
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.launch.process import child_network
from tests.helpers.net import free_port, wait_until

pytestmark = [pytest.mark.zenoh, pytest.mark.timeout(180)]

SCRIPT = """#!/usr/bin/env python3
import json, os
import rospy
from std_msgs.msg import String

rospy.init_node("talker")
with open(os.environ["OUT"], "w") as f:
    json.dump({"cmdline": open("/proc/self/cmdline").read().split("\\0")}, f)
pub = rospy.Publisher("chatter", String, queue_size=1)
while not rospy.is_shutdown():
    pub.publish(String("hi"))
    rospy.sleep(0.1)
"""
LAUNCH = """<launch>
  <node pkg="my_pkg" type="talker.py" name="talker" output="screen">
    <env name="OUT" value="{out}"/>
  </node>
</launch>"""


def test_a_script_joins_the_endpoint_the_launch_connected_to(tmp_path: Path, daemon: str) -> None:
    pkg = tmp_path / "ws" / "my_pkg"
    (pkg / "scripts").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>my_pkg</name></package>")
    (pkg / "scripts" / "talker.py").write_text(SCRIPT)
    out = tmp_path / "report.json"
    (pkg / "talk.launch").write_text(LAUNCH.format(out=out))
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    robot = Context(clock="wall", publish_clock=False)  # the other side: not on the daemon
    robot.add_transport(
        ZenohTransport(ZenohOptions(listen=(endpoint,), user="robot", password="s3cret"))
    )
    got: list[object] = []
    robot.create_node("far").create_subscription("std_msgs/msg/String", "/chatter", got.append, 1)
    robot.spin_in_thread()
    env = {
        **os.environ,
        "ROS_PACKAGE_PATH": str(tmp_path / "ws"),
        "ROS_HOME": str(tmp_path / "ros_home"),
        "ROVERLAB_PASSWORD": "s3cret",
    }
    argv = [sys.executable, "-m", "roverlab.cli", "--connect", endpoint, "--user", "robot"]
    argv += ["launch", str(pkg / "talk.launch"), "--clock", "wall"]
    proc = subprocess.Popen(argv, env=env, stderr=subprocess.PIPE, text=True)
    try:
        assert wait_until(lambda: bool(got) or proc.poll() is not None, timeout=90), "no /chatter"
        assert got, proc.communicate(timeout=30)[1]
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            proc.communicate(timeout=60)
        robot.shutdown()
    cmdline = json.loads(out.read_text())["cmdline"]
    assert "--client-of" in cmdline and "s3cret" not in " ".join(cmdline)


def test_a_launch_without_its_own_endpoint_gives_its_options_to_the_script() -> None:
    laptop = NetworkOptions(connect=("tcp/127.0.0.1:7500",), user="u", password="p")
    net = child_network(laptop.zenoh_options())
    assert net.args == ("--user", "u", "--connect", "tcp/127.0.0.1:7500")
    assert net.env["ROVERLAB_PASSWORD"] == "p" and net.env["ROVERLAB_CONNECT"] is None
    sock = ZenohOptions(listen=("tcp/127.0.0.1:0", "unixsock-stream//tmp/x/zenoh.sock"))
    assert child_network(sock).args == ("--client-of", "unixsock-stream//tmp/x/zenoh.sock")
    assert NetworkOptions(client_of="unixsock-stream//tmp/x").zenoh_options().mode == "client"
