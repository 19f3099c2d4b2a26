"""Bags in one process: the recorder's flushing, recover after a kill, info, convert."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.typesys import Stores, get_typestore

from roverlab.bag import BagError, BagRecorder
from roverlab.bag.files import bag_info, convert_bag, recover_bag
from roverlab.core import Context
from roverlab.msgs.factory import Image, String


def _read(path: Path) -> dict[str, list[int]]:
    """Per topic, the log times rosbags reads."""
    out: dict[str, list[int]] = {}
    with AnyReader([path]) as reader:
        for conn, t, raw in reader.messages():
            reader.deserialize(raw, conn.msgtype)
            out.setdefault(conn.topic, []).append(t)
    return out


def test_recorder_flushes_chunks_and_recover_keeps_all_but_the_last_second(
    tmp_path: Path,
) -> None:
    """Copy the .part file as a kill -9 would leave it, at a moment after >= 2 s of
    recording: recover gets every message older than one flush period back."""
    ctx = Context(clock="wall")
    out = tmp_path / "run.mcap"
    rec = BagRecorder(out, clock=time.time_ns, flush_period_s=1.0)
    ctx.add_transport(rec)
    pub = ctx.create_node("talker").create_publisher(String, "/chatter", 10)
    big = ctx.create_node("imager").create_publisher(Image, "/image", 10)
    image = Image(height=48, width=64, encoding="rgb8", step=192, data=np.zeros(9216, np.uint8))
    sent: list[int] = []
    n = [0]

    def tick() -> None:
        n[0] += 1
        sent.append(time.time_ns())
        pub.publish(String(data=f"hello {n[0]}"))
        big.publish(image)

    ctx.create_node("timer").create_timer(0.02, tick)
    ctx.spin_in_thread()
    time.sleep(2.6)
    kill_ns = time.time_ns()
    snapshot = tmp_path / "killed.mcap.part"
    shutil.copyfile(rec._part, snapshot)  # what the disk holds at a kill -9
    ctx.shutdown()
    assert not rec._part.exists() and out.is_file()
    with pytest.raises(BagError, match="unfinished recording"):
        bag_info(snapshot)

    got = recover_bag(snapshot)
    assert got.path == tmp_path / "killed.mcap" and got.chunks >= 2
    times = _read(got.path)
    before = [t for t in sent if t <= kill_ns - 1.2e9]  # all but ~1 s (+ scheduling slack)
    assert len(times["/chatter"]) >= len(before) > 50
    assert abs(len(times["/image"]) - len(times["/chatter"])) <= 1  # a flush between the two
    # the finished file has them all
    full = _read(out)
    assert len(full["/chatter"]) == len(sent)


def test_recover_a_cut_chunk_and_reject_garbage(tmp_path: Path) -> None:
    ctx = Context()
    out = tmp_path / "a.mcap"
    rec = BagRecorder(out, flush_period_s=0.0)  # a chunk per message
    ctx.add_transport(rec)
    pub = ctx.create_node("talker").create_publisher(String, "/chatter", 10)
    for i in range(20):
        pub.publish(String(data=str(i)))
        ctx.spin_once(0)
    part = rec._part.read_bytes()
    ctx.shutdown()
    cut = tmp_path / "cut.mcap.part"
    cut.write_bytes(part[:-20])  # only the last chunk's message index is cut: chunk whole
    got = recover_bag(cut)
    assert got.messages == 20 and got.chunks == 20 and got.dropped_bytes > 0
    cut.write_bytes(part[:-60])  # the last chunk is cut
    got = recover_bag(cut)
    assert got.messages == 19 and got.chunks == 19
    assert len(_read(got.path)["/chatter"]) == got.messages
    junk = tmp_path / "junk.mcap.part"
    junk.write_bytes(b"not an mcap file at all")
    with pytest.raises(BagError, match=r"junk\.mcap\.part: not an MCAP recording"):
        recover_bag(junk)


def test_info_layout_and_convert_ros1_bag(tmp_path: Path) -> None:
    store = get_typestore(Stores.ROS1_NOETIC)
    ros1 = tmp_path / "old.bag"
    Str = store.types["std_msgs/msg/String"]
    with Ros1Writer(ros1) as w:
        conn = w.add_connection("/chatter", "std_msgs/msg/String", typestore=store)
        for i in range(5):
            w.write(
                conn,
                1_000_000_000 + i * 100_000_000,
                store.serialize_ros1(Str(f"m{i}"), "std_msgs/msg/String"),
            )
    info = bag_info(ros1)
    assert info.messages == 5 and info.storage == "rosbag_v2"
    assert info.duration_s == pytest.approx(0.4)
    out = tmp_path / "new.mcap"
    assert convert_bag(ros1, out).messages == 5
    lines = bag_info(out).lines()
    assert lines[2].split() == ["Storage", "id:", "mcap"]
    assert lines[3] == "Duration:          0.400000000s"
    assert lines[6] == "Messages:          5"
    assert lines[7].startswith("Topic information: Topic: /chatter | Type: std_msgs/msg/String")
    assert lines[7].endswith("| Count: 5 | Serialization Format: cdr")
    with AnyReader([out]) as reader:
        texts = [reader.deserialize(raw, c.msgtype).data for c, _, raw in reader.messages()]
    assert texts == [f"m{i}" for i in range(5)]
    with pytest.raises(BagError, match=r"x\.txt: unknown bag format '\.txt'"):
        convert_bag(ros1, tmp_path / "x.txt")
    assert not (tmp_path / "x.txt").exists()
    with pytest.raises(BagError, match=r"nothere\.mcap: no such file"):
        bag_info(tmp_path / "nothere.mcap")
