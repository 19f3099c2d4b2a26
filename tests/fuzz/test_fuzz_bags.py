"""Fuzzing the ROS 1 bag reader: a real bag (index, chunks of every compression, connection
records) with random byte edits must give its messages or one clear line naming the file,
from ``bag info``, reading and decoding every message, and ``bag reindex`` (recover)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from roverlab.bag.files import bag_info, recover_bag
from roverlab.bag.reader import BagReader
from roverlab.bag.writers import open_writer
from roverlab.msgs import LaserScan, Odometry
from tests.fuzz.mutation import FUZZ, clean, in_folder


def _seed(compression: str) -> bytes:
    with tempfile.TemporaryDirectory(prefix="roverlab-fuzz-") as folder:
        out = open_writer(Path(folder) / "seed.bag", compression)
        scan = out.add_topic("/scan", "sensor_msgs/LaserScan", callerid="/laser")
        odom = out.add_topic("/odom", "nav_msgs/Odometry", latched=True)
        for i in range(3):
            ranges = np.full(16, float(i), np.float32)
            out.write(scan, 10**9 * (i + 1), LaserScan(header_frame_id="laser", ranges=ranges))
            out.write(odom, 10**9 * (i + 1), Odometry(child_frame_id="base"))
            out.flush()  # a chunk each
        out.finish()
        return out.path.read_bytes()


SEEDS = [_seed("none"), _seed("bz2"), _seed("lz4")]


@st.composite
def damaged(draw: Any) -> bytes:
    """A seed bag with 1..4 byte edits: overwrite, insert, delete, or truncate."""
    data = bytearray(SEEDS[draw(st.integers(0, len(SEEDS) - 1))])
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        kind = draw(st.sampled_from(["set", "set", "insert", "delete", "truncate"]))
        piece = draw(st.sampled_from([b"\x00", b"\xff", b"\xff\xff\xff\x7f", b"=", b"op="]))
        if kind == "set":
            data[at : at + len(piece)] = piece
        elif kind == "insert":
            data[at:at] = piece
        elif kind == "delete":
            del data[at : at + draw(st.integers(1, 64))]
        else:
            del data[at:]
    return bytes(data)


def _read_all(path: Path) -> int:
    with BagReader(path) as reader:
        n = 0
        for msg in reader.messages():
            if not msg.connection.problem:
                clean(msg.decode)  # a corrupted payload: a MessageError, one line
            n += 1
        return n


@FUZZ
@given(damaged())
def test_ros1_bag_reader(data: bytes) -> None:
    with in_folder("fuzz.bag", data) as path:
        clean(bag_info, path, name=str(path))
        clean(_read_all, path, name=str(path))
        before = path.read_bytes()
        got = clean(recover_bag, path, name=str(path))
        assert path.read_bytes() == before  # never in place
        if got is not None:
            clean(_read_all, got.path, name=str(got.path))
