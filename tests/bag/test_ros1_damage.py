"""Damaged ROS 1 bags: one line naming the file and the byte offset; reindex (recover) writes
what can be read to a new bag and never touches the input."""

from __future__ import annotations

import hashlib
import struct
from pathlib import Path

import numpy as np
import pytest

from roverlab.bag.errors import BagError
from roverlab.bag.files import bag_info, recover_bag
from roverlab.bag.reader import BagReader
from roverlab.bag.ros1scan import scan_bag
from roverlab.bag.writers import open_writer
from roverlab.msgs import LaserScan

CHUNKS = 6


def _bag(path: Path, *, finish: bool = True) -> bytes:
    """A ROS 1 bag of CHUNKS chunks, one LaserScan each (the writer flushed after each)."""
    out = open_writer(path, "lz4")
    handle = out.add_topic("/scan", "sensor_msgs/LaserScan", callerid="/laser")
    for i in range(CHUNKS):
        scan = LaserScan(header_frame_id="laser", ranges=np.full(90, float(i), np.float32))
        out.write(handle, 1_000_000_000 * (i + 1), scan)
        out.flush()
    if finish:
        out.finish()
        return path.read_bytes()
    data = out.part.read_bytes()  # what a kill -9 leaves: chunks, no index
    out.abort()
    return data


def _chunk_offsets(data: bytes) -> list[int]:
    """Byte offsets of the chunk records (op 0x05)."""
    out, at = [], 0
    while (at := data.find(b"op=\x05", at + 1)) > 0:
        # the record starts at its header length: the op field sits after a 4-byte field length
        start = data.rfind(struct.pack("<I", 4), 0, at) - 4
        while struct.unpack_from("<I", data, start)[0] > len(data):
            start -= 1
        out.append(start)
    return out


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _one_line(err: BagError, path: Path) -> str:
    text = str(err)
    assert "\n" not in text and str(path) in text, text
    return text


def test_a_bag_cut_mid_chunk(tmp_path: Path) -> None:
    data = _bag(tmp_path / "whole.bag")
    cut = tmp_path / "cut.bag"
    offsets = scan_bag(tmp_path / "whole.bag")
    assert offsets.chunks == CHUNKS and offsets.damage is None
    chunks = _chunk_offsets(data)
    cut.write_bytes(data[: chunks[4] + 40])  # four whole chunks, the fifth cut
    before = _digest(cut)
    with pytest.raises(BagError) as err:
        bag_info(cut)
    text = _one_line(err.value, cut)
    assert f"at byte {chunks[4]} (of {len(data[: chunks[4] + 40])})" in text, text
    got = recover_bag(cut)
    assert got.path == tmp_path / "cut.reindexed.bag" and got.messages == 4 and got.chunks == 4
    assert got.dropped_bytes == 40 and _digest(cut) == before
    with BagReader(got.path) as reader:
        ranges = [float(m.decode().ranges[0]) for m in reader.messages()]
    assert ranges == [0.0, 1.0, 2.0, 3.0]


def test_wrong_op_code_and_a_chunk_claiming_4_gb(tmp_path: Path) -> None:
    data = _bag(tmp_path / "whole.bag")
    chunks = _chunk_offsets(data)
    at = data.index(b"op=\x05", chunks[2])
    wrong = tmp_path / "wrong.bag"
    wrong.write_bytes(data[: at + 3] + b"\x42" + data[at + 4 :])
    got = recover_bag(wrong)
    assert got.messages == 2
    with pytest.raises(BagError) as err, BagReader(wrong) as reader:
        list(reader.messages())
    text = _one_line(err.value, wrong)
    assert f"unknown op code 42 at byte {chunks[2]}" in text, text

    huge = tmp_path / "huge.bag"
    hlen = struct.unpack_from("<I", data, chunks[1])[0]
    data_len_at = chunks[1] + 4 + hlen
    huge.write_bytes(data[:data_len_at] + struct.pack("<I", 0xFFFFFFF0) + data[data_len_at + 4 :])
    with pytest.raises(BagError) as err, BagReader(huge) as reader:
        list(reader.messages())
    text = _one_line(err.value, huge)
    assert f"claims 4294967280 data bytes; the rest is shorter at byte {chunks[1]}" in text
    assert recover_bag(huge, tmp_path / "fixed.bag").messages == 1


def test_an_unindexed_bag_from_a_killed_recorder(tmp_path: Path) -> None:
    part = tmp_path / "rec.bag.part"
    part.write_bytes(_bag(tmp_path / "rec.bag", finish=False))
    with pytest.raises(BagError, match=r"rec\.bag\.part: an unfinished recording"):
        bag_info(part)
    renamed = tmp_path / "renamed.bag"
    renamed.write_bytes(part.read_bytes())
    with pytest.raises(BagError) as err:
        bag_info(renamed)
    assert "not indexed" in _one_line(err.value, renamed)
    got = recover_bag(part)
    assert got.path == tmp_path / "rec.bag" and got.messages == CHUNKS and part.is_file()
    assert bag_info(got.path).messages == CHUNKS
    with pytest.raises(BagError, match="never in place"):
        recover_bag(got.path, got.path)
    with pytest.raises(BagError, match=r"junk\.bag: not a ROS 1 bag"):
        junk = tmp_path / "junk.bag"
        junk.write_bytes(b"#ROSBAG V1.2\nold")
        recover_bag(junk)
