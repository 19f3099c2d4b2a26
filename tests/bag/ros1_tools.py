"""Debian's real ROS 1 (python3-rosbag 1.15, roscore, rostopic) beside the bag tests.

Every helper runs the system's ``/usr/bin/python3`` (never the venv's), with a clean
environment and a master on a private loopback port.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.helpers.net import free_port

SYSTEM_PYTHON = "/usr/bin/python3"
ROSCORE = "/usr/bin/roscore"


def have_ros1() -> bool:
    return Path(ROSCORE).exists() and Path(SYSTEM_PYTHON).exists()


def need_ros1() -> None:
    if not have_ros1():
        pytest.skip("Debian's ROS 1 (scripts/install-system-deps.sh) is not installed")


def ros_env(master_port: int | None = None, home: Path | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env["PATH"] = "/usr/bin:/bin"
    env["ROS_HOSTNAME"] = "127.0.0.1"
    if master_port is not None:
        env["ROS_MASTER_URI"] = f"http://127.0.0.1:{master_port}"
    if home is not None:
        env["ROS_HOME"] = str(home)
    return env


def system_python(script: str, job: Any, timeout: float = 120.0) -> Any:
    """Run ``script`` with the system python, ``job`` as JSON on stdin; its JSON stdout."""
    done = subprocess.run(
        [SYSTEM_PYTHON, "-c", script],
        input=json.dumps(job),
        capture_output=True,
        text=True,
        timeout=timeout,
        env=ros_env(),
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


#: Writes bags with the real rosbag module: stamped LaserScan, Odometry, /tf and a latched
#: /tf_static (as robot_state_publisher's), 20 of each at 10 Hz from t = 100 s.
WRITE_BAGS = r"""
import json, sys
import rosbag, rospy
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage
job = json.load(sys.stdin)
for path, comp in job:
    with rosbag.Bag(path, "w", compression=comp) as bag:
        st = TransformStamped()
        st.header.stamp = rospy.Time(100, 0)
        st.header.frame_id = "base_link"
        st.child_frame_id = "laser"
        st.transform.translation.x = 0.1
        st.transform.rotation.w = 1.0
        bag.write("/tf_static", TFMessage(transforms=[st]), rospy.Time(100, 0),
                  connection_header={"latching": "1", "callerid": "/robot_state_publisher",
                                     "topic": "/tf_static", "type": "tf2_msgs/TFMessage",
                                     "md5sum": TFMessage._md5sum,
                                     "message_definition": TFMessage._full_text})
        for i in range(20):
            t = rospy.Time(100, i * 100000000)
            scan = LaserScan()
            scan.header.seq = i
            scan.header.stamp = t
            scan.header.frame_id = "laser"
            scan.angle_min, scan.angle_max = -1.5, 1.5
            scan.angle_increment = 3.0 / 359
            scan.range_min, scan.range_max = 0.1, 10.0
            scan.ranges = [1.0 + 0.01 * i] * 360
            bag.write("/scan", scan, t)
            odom = Odometry()
            odom.header.seq = i
            odom.header.stamp = t
            odom.header.frame_id = "odom"
            odom.child_frame_id = "base_footprint"
            odom.pose.pose.position.x = 0.05 * i
            odom.pose.pose.orientation.w = 1.0
            bag.write("/odom", odom, t)
            tf = TransformStamped()
            tf.header.stamp = t
            tf.header.frame_id = "odom"
            tf.child_frame_id = "base_footprint"
            tf.transform.translation.x = 0.05 * i
            tf.transform.rotation.w = 1.0
            bag.write("/tf", TFMessage(transforms=[tf]), t)
print(json.dumps("ok"))
"""

#: Reads bags with the real rosbag module: per topic the count, md5sums (the connection's and
#: the message class's), latching, first seq/stamp; and `rosbag info`'s exit code.
READ_BAGS = r"""
import json, subprocess, sys
import rosbag
job = json.load(sys.stdin)
out = {}
def text(v):
    return v.decode() if isinstance(v, bytes) else v
for path in job:
    topics = {}
    with rosbag.Bag(path) as bag:
        for topic, msg, t, hdr in bag.read_messages(return_connection_header=True):
            d = topics.setdefault(topic, {"count": 0, "md5": [], "class_md5": msg._md5sum,
                                          "latching": text(hdr.get("latching", "0")), "stamps": [],
                                          "seqs": [], "times": []})
            d["count"] += 1
            if text(hdr["md5sum"]) not in d["md5"]:
                d["md5"].append(text(hdr["md5sum"]))
            d["times"].append(t.to_nsec())
            if hasattr(msg, "header"):
                d["stamps"].append(msg.header.stamp.to_nsec())
                d["seqs"].append(msg.header.seq)
    info = subprocess.run(["rosbag", "info", path], capture_output=True, text=True)
    out[path] = {"topics": topics, "info": info.returncode, "info_err": info.stderr[-500:]}
print(json.dumps(out))
"""


def write_real_bags(folder: Path) -> dict[str, Path]:
    """plain / bz2 / lz4 bags written by the real rosbag module."""
    bags = {comp: folder / f"real_{comp}.bag" for comp in ("none", "bz2", "lz4")}
    system_python(WRITE_BAGS, [[str(p), comp] for comp, p in bags.items()])
    return bags


def read_with_rosbag(*paths: Path) -> dict[str, Any]:
    return dict(system_python(READ_BAGS, [str(p) for p in paths]))


def roscore(home: Path) -> Iterator[int]:
    """A real roscore on a private loopback port (a generator for a fixture)."""
    port = free_port()
    proc = subprocess.Popen(
        [SYSTEM_PYTHON, ROSCORE, "-p", str(port)],
        env=ros_env(port, home),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 60
        while True:
            probe = subprocess.run(
                ["/usr/bin/rosparam", "get", "/rosversion"],
                env=ros_env(port, home),
                capture_output=True,
                check=False,
            )
            if probe.returncode == 0:
                break
            assert proc.poll() is None and time.monotonic() < deadline, "roscore did not start"
            time.sleep(0.5)
        yield port
    finally:
        os.killpg(proc.pid, 2)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, 9)
            proc.wait()
        shutil.rmtree(home, ignore_errors=True)
