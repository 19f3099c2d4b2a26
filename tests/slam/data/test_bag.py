"""Reading laser logs from ROS 1 bags, ROS 2 bags and MCAP files (written here with rosbags)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin

from roverlab.bag import BagRecorder
from roverlab.core import Context, Node
from roverlab.geometry import SE2
from roverlab.msgs import Twist
from roverlab.sim.app import Simulation
from roverlab.slam.data import LogError, ScanRecord, iter_log, load_log, read_bag
from tests.slam.data import bags


def check_records(records: list[ScanRecord], *, offset: SE2 = bags.LASER_OFFSET) -> None:
    assert len(records) == len(bags.SCAN_TIMES_S)
    for k, (rec, t) in enumerate(zip(records, bags.SCAN_TIMES_S, strict=True)):
        ns = int(round(t * 1e9))
        assert rec.timestamp_text == f"{ns // 10**9}.{ns % 10**9:09d}"
        assert rec.timestamp == pytest.approx(t, abs=1e-9)
        np.testing.assert_array_equal(rec.ranges, bags.scan_ranges(k))
        assert rec.angle_min == pytest.approx(-1.5)
        assert rec.angle_increment == pytest.approx(math.radians(2.0))
        assert (rec.range_min, rec.range_max) == (pytest.approx(0.05), pytest.approx(12.0))
        # odometry is linear in time, so interpolation between samples is exact,
        # including where theta wraps past pi
        truth = bags.true_pose(t)
        assert rec.odom_pose.x == pytest.approx(truth.x, abs=1e-9)
        assert rec.odom_pose.y == pytest.approx(truth.y, abs=1e-9)
        assert math.remainder(rec.odom_pose.theta - truth.theta, 2 * math.pi) == pytest.approx(
            0.0, abs=1e-9
        )
        assert rec.laser_offset.x == pytest.approx(offset.x, abs=1e-9)
        assert rec.laser_offset.y == pytest.approx(offset.y, abs=1e-9)
        assert rec.laser_offset.theta == pytest.approx(offset.theta, abs=1e-9)
    thetas = [r.odom_pose.theta for r in records]
    assert max(thetas) > 2.5 and min(thetas) < -2.5  # the wrap was crossed


@pytest.mark.parametrize("odometry", ["odom", "tf"])
def test_ros1_bag(tmp_path: Path, odometry: str) -> None:
    path = bags.write_ros1_bag(tmp_path / "run.bag", odometry=odometry)  # type: ignore[arg-type]
    check_records(list(load_log(path)))


@pytest.mark.parametrize("storage", [StoragePlugin.SQLITE3, StoragePlugin.MCAP])
def test_ros2_bag_folder(tmp_path: Path, storage: StoragePlugin) -> None:
    path = bags.write_ros2_bag(tmp_path / "run", storage=storage)
    assert path.is_dir()
    check_records(list(load_log(path)))
    if storage is StoragePlugin.SQLITE3:  # a ROS 2 bag named by its database file
        (db3,) = path.glob("*.db3")
        check_records(list(load_log(db3)))


def test_bare_mcap_with_tf_odometry(tmp_path: Path) -> None:
    path = bags.write_mcap(tmp_path / "run.mcap", odometry="tf")
    assert path.is_file()
    stream = iter_log(path)
    first = next(stream)  # a generator: the first scan comes before the rest is read
    check_records([first, *stream])


def test_explicit_frames_and_missing_static_tf(tmp_path: Path) -> None:
    path = bags.write_ros2_bag(tmp_path / "run")
    # from base_link the laser is only the second static transform
    check_records(list(read_bag(path, base_frame="base_link")), offset=bags.LASER)
    # a laser frame the static tree does not reach: zero offset
    check_records(list(read_bag(path, laser_frame="camera")), offset=SE2())
    bare = bags.write_ros2_bag(tmp_path / "nostatic", static=False)
    check_records(list(load_log(bare)), offset=SE2())


def test_bag_errors(tmp_path: Path) -> None:
    path = bags.write_ros2_bag(tmp_path / "run")
    with pytest.raises(
        LogError, match=r"no topic /front_scan \(topics: /odom, /scan, /tf_static\)"
    ):
        load_log(path, scan_topic="/front_scan")
    with pytest.raises(LogError, match="no odometry"):
        load_log(path, odom_topic="/wheel_odom", tf_topic="/tf")
    with pytest.raises(LogError, match=r"unknown option.*range_max_m"):
        load_log(path, range_max_m=3.0)
    # without odometry on request: identity poses
    recs = list(load_log(path, odom_topic=None, tf_topic=None))
    assert len(recs) == len(bags.SCAN_TIMES_S)
    assert all(r.odom_pose == SE2() for r in recs)
    broken = tmp_path / "broken.bag"
    broken.write_bytes(b"#ROSBAG V2.0\nthis is not a bag")
    with pytest.raises(LogError, match=r"broken\.bag"):
        load_log(broken)


def test_tf_without_odom_transforms_is_an_error(tmp_path: Path) -> None:
    path = bags.write_ros1_bag(tmp_path / "run.bag", odometry="tf")
    with pytest.raises(LogError, match="no odometry: no map -> base transforms on /tf"):
        load_log(path, odom_frame="map")


def test_simulator_recording(tmp_path: Path) -> None:
    """An MCAP recorded from the simulator reads back with the /odom poses at the scans."""
    path = tmp_path / "sim.mcap"
    context = Context(clock="sim")
    context.add_transport(BagRecorder(path))
    Simulation(context=context, cameras=False)
    driver = Node("driver", context=context)
    pub = driver.create_publisher("geometry_msgs/msg/Twist", "/cmd_vel", 10)
    driver.create_timer(0.1, lambda: pub.publish(Twist(linear_x=0.3, angular_z=0.5)))
    context.spin_for(2.0)
    context.shutdown()

    log = load_log(path)
    assert len(log) >= 5
    odom: list[tuple[float, float]] = []
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == "/odom"]
        for con, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, con.msgtype)
            odom.append(
                (msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9, msg.pose.pose.position.x)
            )
    times, xs = np.array(odom).T
    np.testing.assert_allclose(
        log.odom_poses[:, 0], np.interp(log.timestamps, times, xs), atol=1e-9
    )
    assert log.odom_poses[-1, 0] > 0.1  # the robot moved
    assert np.all(np.diff(log.timestamps) > 0)
