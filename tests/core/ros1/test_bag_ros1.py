"""``roverlab bag record`` on a ROS 1 graph: it records a real rospy talker's topic over
TCPROS into a ROS 1 bag that Debian's real ``rosbag info`` and ``rosbag play`` read, the
messages in order with ROS 1's md5sum."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from tests.core.ros1.conftest import SCRIPTS, run_ros, start_ros, stop


def test_bag_record_hears_a_real_talker(real_master: str, tmp_path: Path) -> None:
    talker = start_ros(real_master, "/usr/bin/python3", str(SCRIPTS / "talker.py"), "/bag_in")
    bag = tmp_path / "talk.bag"
    try:
        env = {**os.environ, "ROS_MASTER_URI": real_master, "ROS_HOSTNAME": "127.0.0.1"}
        rec = subprocess.run(
            [
                sys.executable,
                "-m",
                "roverlab.cli",
                "bag",
                "record",
                "-O",
                str(bag),
                "--duration",
                "3",
                "/bag_in",
            ],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
    finally:
        stop(talker)
    assert rec.returncode == 0, rec.stderr[-2000:]
    info = run_ros(real_master, "/usr/bin/rosbag", "info", "--yaml", str(bag))
    assert info.returncode == 0, info.stderr
    assert "topic: /bag_in" in info.stdout and "type: std_msgs/String" in info.stdout
    assert "md5: 992ce8a1687cec8c8bd883ec73ca41d1" in info.stdout  # Noetic's std_msgs/String
    count = int(info.stdout.split("\nmessages: ")[1].split()[0])
    assert count >= 20, info.stdout  # 20 Hz for 3 s, less the time to connect
    # the real rosbag's Python API reads the messages back: consecutive greetings
    read = run_ros(
        real_master,
        "/usr/bin/python3",
        "-c",
        "import rosbag, sys\nfor _, m, _ in rosbag.Bag(sys.argv[1]).read_messages(): print(m.data)",
        str(bag),
    )
    lines = read.stdout.split("\n")[:-1]
    assert len(lines) == count, read.stderr
    numbers = [int(x.removeprefix("hello ")) for x in lines]
    assert numbers == list(range(numbers[0], numbers[0] + count))
