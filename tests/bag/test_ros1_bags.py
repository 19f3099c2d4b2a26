"""ROS 1 bags for real: the extension decides the format, real rosbag bags read and convert,
and Debian's rosbag (module, ``rosbag info``, ``rosbag play`` into a real roscore) agrees
with what roverlab writes."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from roverlab.bag import BagError, BagRecorder
from roverlab.bag.files import bag_info, convert_bag
from roverlab.bag.player import Player, PlayOptions
from roverlab.bag.reader import BagReader
from roverlab.bag.writers import open_writer
from roverlab.core import Context, QoSProfile
from roverlab.msgs import (
    LaserScan,
    OccupancyGrid,
    String,
    TFMessage,
    TransformStamped,
    array_to_occupancy_grid,
    time_to_ns,
)
from roverlab.msgs.ros1 import ros1_definition
from roverlab.slam.data.bag_logs import read_bag
from tests.bag import ros1_tools
from tests.helpers.nodes import run_main
from tests.helpers.procs import Proc

RL = [sys.executable, "-m", "roverlab.cli"]
SHORT_RUN = ["--duration", "1", "--rate", "max"]


def _decoded(path: Path) -> list[tuple[str, int, Any]]:
    """(topic, log time, runtime message) of every message roverlab reads."""
    with BagReader(path) as reader:
        return [(m.topic, m.log_time_ns, m.decode()) for m in reader.messages()]


def _summary(items: list[tuple[str, int, Any]]) -> list[tuple[str, int, Any]]:
    """What must survive a conversion: topic, time, and each message's defining values."""
    out = []
    for topic, t, msg in items:
        if topic == "/scan":
            key: Any = (time_to_ns(msg.header.stamp), msg.header.frame_id, msg.ranges.tolist())
        elif topic == "/odom":
            key = (time_to_ns(msg.header.stamp), msg.child_frame_id, msg.pose.pose.position.x)
        elif topic in ("/tf", "/tf_static"):
            tr = msg.transforms[0]
            key = (time_to_ns(tr.header.stamp), tr.child_frame_id, tr.transform.translation.x)
        else:
            key = repr(msg)
        out.append((topic, t, key))
    return out


# ------------------------------------------------------------------ in one process
def _record(path: Path, compression: str | None = None) -> int:
    ctx = Context()
    rec = BagRecorder(path, compression=compression, topics=["/robot_description", "/scan"])
    ctx.add_transport(rec)
    node = ctx.create_node("robot")
    latched = node.create_publisher(
        String, "/robot_description", QoSProfile(depth=1, durability="transient_local")
    )
    scans = node.create_publisher(LaserScan, "/scan", 10)
    latched.publish(String(data="<robot name='r'/>"))
    for i in range(5):
        ctx.spin_for(0.1)
        scan = LaserScan(header_frame_id="laser", ranges=np.full(8, 1.0 + i, np.float32))
        scan.header.stamp = ctx.now().to_msg()
        scans.publish(scan)
        ctx.spin_once(0)
    ctx.shutdown()
    return rec.messages


def test_the_extension_decides_and_every_direction_converts(tmp_path: Path) -> None:
    bag = tmp_path / "rec.bag"
    assert _record(bag, "bz2") == 6
    with Ros1Reader(bag) as raw:
        conns = {c.topic: c for c in raw.connections}
        assert raw.chunk_infos and conns["/robot_description"].ext.latching == 1
        assert conns["/scan"].ext.latching is None
        assert conns["/scan"].digest == ros1_definition("sensor_msgs/LaserScan")[1]
        assert conns["/scan"].msgdef.data == ros1_definition("sensor_msgs/LaserScan")[0]
        assert conns["/scan"].ext.callerid == "/robot"
        # a message published before the clock ran is indexed at ROS 1's TIME_MIN, not 0
        assert [t for c, t, _ in raw.messages() if c.topic == "/robot_description"] == [1]
    first = _summary(_decoded(bag))
    chain = [tmp_path / "a.mcap", tmp_path / "folder", tmp_path / "b.db3", tmp_path / "c.bag"]
    src = bag
    for dst in chain:
        done = convert_bag(src, dst, compression="lz4" if dst.suffix == ".bag" else None)
        assert done.messages == 6 and not done.skipped
        src = done.path
    assert (tmp_path / "folder" / "metadata.yaml").is_file()
    assert (tmp_path / "b" / "b.db3").is_file()
    assert [info.storage for info in map(bag_info, [chain[0], chain[1], tmp_path / "b"])] == [
        "mcap",
        "sqlite3",
        "sqlite3",
    ]
    assert _summary(_decoded(tmp_path / "c.bag")) == first
    with Ros1Reader(tmp_path / "c.bag") as raw:  # latched again from the topic's name
        assert {c.topic: c.ext.latching for c in raw.connections}["/robot_description"] == 1


def test_unknown_extension_or_compression_is_refused_before_anything(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    for bad, match in [
        (tmp_path / "x.rosbag", r"x\.rosbag: unknown bag format '\.rosbag'"),
        (tmp_path / "x.txt", r"x\.txt: unknown bag format"),
    ]:
        with pytest.raises(BagError, match=match):
            BagRecorder(bad)
    with pytest.raises(BagError, match=r"x\.bag: a ROS 1 bag has no 'zstd' compression"):
        BagRecorder(tmp_path / "x.bag", compression="zstd")
    assert list(tmp_path.iterdir()) == []
    for argv in (
        ["sim", "--record", str(tmp_path / "x.rosbag"), "--duration", "1"],
        ["bag", "convert", str(tmp_path / "nothing.bag"), str(tmp_path / "out.txt")],
        ["bag", "record", "-a", "-O", str(tmp_path / "x.bag"), "--compression", "zstd"],
    ):
        assert run_main(argv) == 2
        err = capfd.readouterr().err
        assert err.count("\n") == 1 and str(tmp_path) in err, err
        assert "unknown bag format" in err or "no 'zstd' compression" in err, err
        assert "simulating" not in err and list(tmp_path.iterdir()) == []


def test_unknown_types_play_with_their_definition_else_are_skipped(tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS1_NOETIC)
    text = "Header header\nuint16 level\nstring[] tags\n"
    store.register(get_types_from_msg(text, "rl_test_msgs/msg/Status"))
    definition, md5 = store.generate_msgdef("rl_test_msgs/msg/Status")
    cls = store.types["rl_test_msgs/msg/Status"]
    hdr, stamp = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    bag = tmp_path / "custom.bag"
    with Ros1Writer(bag) as w:
        known = w.add_connection(
            "/status", "rl_test_msgs/msg/Status", msgdef=definition, md5sum=md5
        )
        unknown = w.add_connection(
            "/mystery", "rl_other_msgs/msg/Thing", msgdef="", md5sum="0" * 32
        )
        for i in range(3):
            data = store.serialize_ros1(
                cls(hdr(i, stamp(7, i), "base"), 3 + i, ["a", "b"]), "rl_test_msgs/msg/Status"
            )
            w.write(known, 1_000_000_000 + i, data)
            w.write(unknown, 1_000_000_000 + i, b"\x01\x02")
    ctx = Context(clock="wall")
    got: list[Any] = []
    ctx.create_node("listener").create_subscription(
        "rl_test_msgs/msg/Status", "/status", got.append, 10
    )
    warnings: list[str] = []
    player = Player(ctx, bag, PlayOptions(rate=100.0), warn=warnings.append)
    ctx.spin_in_thread()
    assert player.run(threading.Event()) == 3
    deadline = time.monotonic() + 5
    while len(got) < 3 and time.monotonic() < deadline:
        time.sleep(0.02)
    ctx.shutdown()
    assert [(m.level, m.tags, m.header.stamp.nanosec) for m in got] == [
        (3, ["a", "b"], 0),
        (4, ["a", "b"], 1),
        (5, ["a", "b"], 2),
    ]
    assert len(warnings) == 1 and "rl_other_msgs/msg/Thing" in warnings[0]
    assert "/mystery" in warnings[0] and "\n" not in warnings[0]
    # copied between ROS 1 bags as bytes; skipped (with its reason) into MCAP
    assert convert_bag(bag, tmp_path / "copy.bag").messages == 6
    done = convert_bag(bag, tmp_path / "custom.mcap")
    assert done.messages == 3 and [(c.topic, n) for c, n in done.skipped] == [("/mystery", 3)]


# ------------------------------------------------------------------ Debian's rosbag
@pytest.fixture(scope="module")
def real_bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    ros1_tools.need_ros1()
    return ros1_tools.write_real_bags(tmp_path_factory.mktemp("real"))


@pytest.fixture(scope="module")
def master(tmp_path_factory: pytest.TempPathFactory) -> Iterator[int]:
    ros1_tools.need_ros1()
    yield from ros1_tools.roscore(tmp_path_factory.mktemp("roshome"))


def test_real_rosbag_bags_convert_both_ways_and_lose_nothing(
    real_bags: dict[str, Path], tmp_path: Path
) -> None:
    backs = []
    for comp, bag in real_bags.items():
        info = bag_info(bag)
        assert {t.name: t.count for t in info.topics} == {
            "/odom": 20,
            "/scan": 20,
            "/tf": 20,
            "/tf_static": 1,
        }
        assert info.start_ns == 100_000_000_000 and info.end_ns == 101_900_000_000
        original = _summary(_decoded(bag))
        assert original[0][2] == (100_000_000_000, "laser", 0.1)  # /tf_static first
        mcap = convert_bag(bag, tmp_path / f"{comp}.mcap").path
        back = convert_bag(mcap, tmp_path / f"back_{comp}.bag", compression=comp).path
        copy = convert_bag(bag, tmp_path / f"copy_{comp}.bag").path
        assert _summary(_decoded(mcap)) == original
        assert _summary(_decoded(back)) == original
        for path in (bag, back):  # what `roverlab slam run` reads: every scan, its odometry
            poses = [r.odom_pose.x for r in read_bag(path)]
            assert poses == pytest.approx([0.05 * i for i in range(20)])
        backs += [back, copy]
    seen = ros1_tools.read_with_rosbag(*backs)
    for path, got in seen.items():
        assert got["info"] == 0, got["info_err"]
        topics = got["topics"]
        assert {t: d["count"] for t, d in topics.items()} == {
            "/tf_static": 1,
            "/scan": 20,
            "/odom": 20,
            "/tf": 20,
        }
        assert all(d["md5"] == [d["class_md5"]] for d in topics.values())
        assert topics["/tf_static"]["latching"] == "1"
        assert topics["/scan"]["stamps"] == [100_000_000_000 + i * 100_000_000 for i in range(20)]
        assert topics["/scan"]["times"] == topics["/scan"]["stamps"]
        # a ROS 1 -> ROS 1 copy keeps the bytes, Header.seq included
        expect_seq = list(range(20)) if "copy_" in path else [0] * 20
        assert topics["/odom"]["seqs"] == expect_seq


def test_roverlab_plays_a_real_bag_to_topic_echo(
    real_bags: dict[str, Path], daemon: str, cli: Callable[..., Any]
) -> None:
    echo = Proc([*RL, "topic", "echo", "/odom", "nav_msgs/Odometry", "--once"])
    try:
        time.sleep(2.0)  # the echo's subscription is declared
        played = cli("bag", "play", str(real_bags["lz4"]), "--rate", "4", timeout=60)
        assert played.returncode == 0, played.stderr
        assert "published 61 messages" in played.stderr
        out, err = echo.communicate(timeout=30)
        assert echo.popen.returncode == 0, err
    finally:
        echo.stop()
    assert "child_frame_id: base_footprint" in out and "frame_id: odom" in out
    assert "sec: 100" in out


def test_sim_record_bag_agrees_with_debian_rosbag(tmp_path: Path, master: int) -> None:
    rec = tmp_path / "rec.bag"
    sim = subprocess.run(
        [*RL, "sim", "--no-expose", "--record", str(rec), "--world", "empty", *SHORT_RUN],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert sim.returncode == 0, sim.stderr
    seen = ros1_tools.read_with_rosbag(rec)[str(rec)]
    assert seen["info"] == 0, seen["info_err"]
    topics = seen["topics"]
    assert {"/scan", "/odom", "/tf", "/tf_static", "/clock"} <= set(topics)
    assert all(d["md5"] == [d["class_md5"]] for d in topics.values())
    assert topics["/tf_static"]["latching"] == "1" and topics["/tf_static"]["count"] == 1
    assert all(t >= 1 for d in topics.values() for t in d["times"])
    assert sum(d["count"] for d in topics.values()) == bag_info(rec).messages

    env = ros1_tools.ros_env(master, tmp_path / "home")
    echo = subprocess.Popen(
        ["/usr/bin/rostopic", "echo", "-n", "1", "/tf_static"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        time.sleep(2.0)
        play = subprocess.run(
            ["/usr/bin/rosbag", "play", "--quiet", str(rec)],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert play.returncode == 0, play.stderr
        assert "invalid time" not in play.stdout + play.stderr
        out, err = echo.communicate(timeout=30)
    finally:
        if echo.poll() is None:
            echo.kill()
            echo.wait()
    assert "child_frame_id" in out, err


def test_a_late_subscriber_gets_the_newest_latched_map(tmp_path: Path) -> None:
    """rosbag play latches a topic's newest message per recorded publisher: a display that
    subscribes after the maps were played draws the last /map whole, never an early one."""
    bag = tmp_path / "maps.bag"
    out = open_writer(bag)
    maps = out.add_topic("/map", "nav_msgs/OccupancyGrid", latched=True, callerid="/slam")
    statics = [
        out.add_topic("/tf_static", "tf2_msgs/TFMessage", latched=True, callerid=f"/pub{i}")
        for i in range(2)
    ]
    for i in range(3):
        grid = array_to_occupancy_grid(np.full((4, 4 + i), i, np.int8), resolution=0.05)
        out.write(maps, 10**9 * (i + 1), grid)
    for i, handle in enumerate(statics):
        tf = TFMessage(transforms=[TransformStamped(child_frame_id=f"c{i}")])
        out.write(handle, 10**9, tf)
    out.finish()
    ctx = Context(clock="wall")
    ctx.spin_in_thread()
    assert Player(ctx, bag, PlayOptions(rate=50.0)).run(threading.Event()) == 5
    time.sleep(0.5)  # the executor has delivered what was played
    got: list[Any] = []
    tfs: list[Any] = []

    def late_display() -> None:  # subscribes on the executor's thread, as a node does
        node = ctx.create_node("late_display")
        node.create_subscription(OccupancyGrid, "/map", got.append, 10)
        node.create_subscription(TFMessage, "/tf_static", tfs.append, 10)

    ctx.executor.call_soon_threadsafe(late_display)
    deadline = time.monotonic() + 5
    while (not got or len(tfs) < 2) and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(0.1)
    ctx.shutdown()
    assert [m.info.width for m in got] == [6]
    assert sorted(t.transforms[0].child_frame_id for t in tfs) == ["c0", "c1"]
