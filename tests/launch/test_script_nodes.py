"""A user's own rospy script as a ``<node>``: run in a process of its own, with the
launch's arguments, remaps, name, namespace, private and global parameters, cwd and
env; stopped (its on_shutdown hooks run) with the launch; required/respawn watched."""

from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path

import pytest

from roverlab.core import Context
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport, daemon_endpoint
from roverlab.launch import LaunchError, build_launch

pytestmark = pytest.mark.zenoh

PACKAGE_XML = "<package format='2'><name>my_pkg</name><version>0.0.1</version></package>"
SCRIPT = """#!/usr/bin/env python3
import json, os
import rospy
from std_msgs.msg import String

out = os.environ["OUT"]  # the <env> of its <node>
rospy.init_node("talker")
rospy.on_shutdown(lambda: open(out + ".bye", "w").write("bye"))
report = {
    "name": rospy.get_name(),
    "rate": rospy.get_param("~rate"),
    "pid": rospy.get_param("~pid"),
    "global": rospy.get_param("/global_p"),
    "relative": rospy.get_param("in_ns"),
    "myargv": rospy.myargv()[1:],
    "cwd": os.getcwd(),
}
with open(out, "w") as f:
    json.dump(report, f)
pub = rospy.Publisher("chatter", String, queue_size=1)
while not rospy.is_shutdown():
    pub.publish(String("hi"))
    rospy.sleep(0.1)
"""


def _package(tmp_path: Path, launch: str) -> Path:
    pkg = tmp_path / "ws" / "my_pkg"
    for sub in ("launch", "scripts", "config"):
        (pkg / sub).mkdir(parents=True)
    (pkg / "package.xml").write_text(PACKAGE_XML)
    (pkg / "scripts" / "talker.py").write_text(SCRIPT)
    (pkg / "scripts" / "driver_node").write_bytes(b"\x7fELF compiled")
    (pkg / "config" / "pid.yaml").write_text("pid: {p: 1.0, i: 0.1}\n")
    path = pkg / "launch" / "talk.launch"
    path.write_text(launch)
    return path


def _context() -> Context:
    ctx = Context(clock="wall", publish_clock=False)
    ctx.add_transport(ZenohTransport(ZenohOptions(connect=(daemon_endpoint(),))))
    return ctx


TALK = """<launch>
  <param name="global_p" value="42"/>
  <group ns="robot">
    <param name="in_ns" value="yes"/>
    <node pkg="my_pkg" type="talker.py" name="talker1" args="foo bar" cwd="node" {extra}>
      <param name="rate" value="5"/>
      <rosparam file="$(find my_pkg)/config/pid.yaml" command="load"/>
      <remap from="chatter" to="/other"/>
      <env name="OUT" value="{out}"/>
    </node>
  </group>
</launch>"""


def test_a_script_node_runs_as_roslaunch_runs_it(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "report.json"
    path = _package(tmp_path, TALK.format(extra="", out=out))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    ctx = _context()
    got: list[object] = []
    ctx.create_node("listener").create_subscription("std_msgs/msg/String", "/other", got.append, 1)
    try:
        launch = build_launch(path, context=ctx)
        (name, (_, proc)), *_ = launch.processes.items()
        assert name == "/robot/talker1" and proc.script.name == "talker.py"
        launch.supervise(0.1)
        ctx.spin_in_thread()
        assert ctx.wait_for(lambda: out.exists() and bool(got), timeout_sec=60)
    finally:
        ctx.shutdown()
    assert json.loads(out.read_text()) == {
        "name": "/robot/talker1",
        "rate": 5,
        "pid": {"p": 1.0, "i": 0.1},
        "global": 42,
        "relative": "yes",
        "myargv": ["foo", "bar"],
        "cwd": str(path.parents[1] / "scripts"),
    }
    assert proc.poll() is not None  # stopped with the launch, after its shutdown hook
    assert (tmp_path / "report.json.bye").read_text() == "bye"
    assert launch.deaths == []


def test_a_required_script_that_ends_ends_the_launch(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _package(tmp_path, TALK.format(extra='required="true"', out=tmp_path / "r.json"))
    (path.parents[1] / "scripts" / "talker.py").write_text("import sys\nsys.exit(3)\n")
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    ctx = _context()
    try:
        launch = build_launch(path, context=ctx)
        launch.supervise(0.1)
        ctx.spin_in_thread()
        deadline = time.monotonic() + 60
        while not ctx.is_shutdown() and time.monotonic() < deadline:
            time.sleep(0.1)
    finally:
        ctx.shutdown()
    assert len(launch.deaths) == 1
    assert launch.deaths[0].startswith("REQUIRED process [/robot/talker1] has died: pid ")
    assert "exit code 3" in launch.deaths[0]


def test_scripts_that_cannot_run_are_named(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _package(tmp_path, """<launch>
  <node pkg="my_pkg" type="driver_node" name="driver"/>
  <node pkg="my_pkg" type="nothing.py" name="nothing"/>
  <node pkg="other_pkg" type="x.py" name="x"/>
  <node pkg="my_pkg" type="../my_pkg/scripts/talker.py" name="up"/>
</launch>""")  # fmt: skip
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    ctx = _context()
    try:
        launch = build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    assert launch.processes == {}
    driver, nothing, other, up = launch.warnings
    assert str(path) in driver and "driver_node is not a Python script" in driver
    assert "my_pkg/nothing.py is not part of roverlab, and no file 'nothing.py' in " in nothing
    assert nothing.endswith(f"package my_pkg ({path.parents[1]}); skipped")
    # the package itself missing: said so, with where it was looked for
    assert "other_pkg/x.py is not part of roverlab, and package 'other_pkg' not found " in other
    assert f"(searched: {path.parents[2]}" in other
    assert "'../my_pkg/scripts/talker.py' is outside package my_pkg" in up
    private = Context(clock="wall", publish_clock=False)  # no transport: the script is alone
    try:
        path.write_text(TALK.format(extra="", out=tmp_path / "x.json"))
        with pytest.raises(LaunchError, match=r"talk.launch: <node name=\"talker1\">.*--expose"):
            build_launch(path, context=private)
    finally:
        private.shutdown()


def test_an_ambiguous_script_is_refused_and_a_non_executable_one_noted(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _package(tmp_path, """<launch>
  <node pkg="my_pkg" type="talker.py" name="talker"/>
  <node pkg="my_pkg" type="once.py" name="once"/>
  <node pkg="my_pkg" type="nodes/talker.py" name="by_path"/>
</launch>""")  # fmt: skip
    scripts = path.parents[1] / "scripts"
    (path.parents[1] / "nodes").mkdir()
    (path.parents[1] / "nodes" / "talker.py").write_text(SCRIPT)  # a second talker.py
    (path.parents[1] / "nodes" / "talker.py").chmod(0o755)
    (scripts / "once.py").write_text("print('once')\n")  # mode 0644: forgot chmod +x
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    ctx = _context()
    try:
        launch = build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    (ambiguous,) = launch.warnings
    assert ambiguous.startswith(f'{path}: <node name="talker">: node my_pkg/talker.py: ')
    assert "multiple files named [talker.py] in package [my_pkg]" in ambiguous
    assert "(name one by its path in the package: nodes/talker.py)" in ambiguous
    # a path inside the package names one file, as rosrun takes it
    assert list(launch.processes) == ["/once", "/by_path"]
    assert launch.processes["/by_path"][1].script == path.parents[1] / "nodes" / "talker.py"
    (note,) = launch.notes
    assert f"{scripts / 'once.py'} is not executable (roslaunch refuses it" in note
    assert note.startswith(f"{path}: ") and note.endswith("run anyway")


SLOW_HOOK = """import os, signal, time
import rospy

out = os.environ["OUT"]
seen = []
rospy.init_node("slow")
previous = signal.getsignal(signal.SIGINT)
def count(sig, frame):  # then rospy's own handler
    seen.append(sig)
    previous(sig, frame)
signal.signal(signal.SIGINT, count)
def hook():
    time.sleep(1.0)  # a hook that takes its time (stopping a motor, saving a file)
    open(out, "w").write(f"signals {len(seen)}")
rospy.on_shutdown(hook)
open(out + ".ready", "w").write("ready")
rospy.spin()
"""


def test_a_script_gets_one_sigint_and_its_slow_hook_finishes(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "hook.txt"
    path = _package(tmp_path, TALK.format(extra="", out=out))
    (path.parents[1] / "scripts" / "talker.py").write_text(SLOW_HOOK)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    monkeypatch.setenv("ROS_HOME", str(tmp_path / "ros_home"))
    ctx = _context()
    try:
        launch = build_launch(path, context=ctx)
        ctx.spin_in_thread()
        assert ctx.wait_for(lambda: Path(f"{out}.ready").exists(), timeout_sec=60)
        (_, proc), *_ = launch.processes.values()
        launch.stop_processes()  # as `roverlab launch` does before its network closes
    finally:
        ctx.shutdown()
    assert out.read_text() == "signals 1"  # a second SIGINT cut the hook short before
    assert proc.poll() == 0


def test_an_unmatched_quote_in_args_is_one_launch_error(
    tmp_path: Path, daemon: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _package(tmp_path, TALK.format(extra="", out=tmp_path / "q.json"))
    path.write_text(path.read_text().replace('args="foo bar"', 'args="foo \'bar"'))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(path.parents[2]))
    temp = tmp_path / "temp"
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))  # where a params file would go
    ctx = _context()
    try:
        quote = r"talk\.launch: <node name=.talker1.>: No closing quotation"
        with pytest.raises(LaunchError, match=quote):
            build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    assert not list(temp.iterdir())  # no params file left behind
