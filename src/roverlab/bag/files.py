"""Whole-bag operations: ``ros2 bag info``, ``convert`` and ``rosbag reindex`` (recover).

Inputs are a ROS 1 ``.bag``, a ROS 2 bag (sqlite3 or MCAP folder) or a single ``.mcap`` file
(:class:`~roverlab.bag.reader.BagReader`); the output's extension decides its format
(:mod:`roverlab.bag.writers`). Outputs are written to a temporary name and renamed.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader

from roverlab.bag.errors import BagError
from roverlab.bag.reader import BagConnection, BagReader, input_path
from roverlab.bag.ros1scan import MAGIC as ROS1_MAGIC
from roverlab.bag.ros1scan import scan_bag
from roverlab.bag.writers import (
    BagWriter,
    McapBagWriter,
    check_output,
    open_writer,
    output_path,
)
from roverlab.msgs import MessageError

__all__ = [
    "BagInfo",
    "Converted",
    "Recovered",
    "TopicInfo",
    "bag_info",
    "convert_bag",
    "recover_bag",
]


@dataclass(frozen=True)
class TopicInfo:
    name: str
    typename: str
    count: int
    serialization: str


@dataclass(frozen=True)
class BagInfo:
    """What ``ros2 bag info`` prints."""

    path: Path
    storage: str
    size_bytes: int
    start_ns: int
    end_ns: int
    messages: int
    topics: list[TopicInfo] = field(default_factory=list)

    @property
    def duration_s(self) -> float:
        return (self.end_ns - self.start_ns) / 1e9 if self.messages else 0.0

    def lines(self) -> list[str]:
        """``ros2 bag info``'s layout."""

        def stamp(ns: int) -> str:
            t = dt.datetime.fromtimestamp(ns / 1e9, tz=dt.UTC)
            return f"{t:%b %d %Y %H:%M:%S}.{t.microsecond // 1000:03d} ({ns / 1e9:.9f})"

        out = [
            f"Files:             {self.path.name}",
            f"Bag size:          {_size(self.size_bytes)}",
            f"Storage id:        {self.storage}",
            f"Duration:          {self.duration_s:.9f}s",
            f"Start:             {stamp(self.start_ns)}",
            f"End:               {stamp(self.end_ns)}",
            f"Messages:          {self.messages}",
        ]
        width = max((len(t.name) for t in self.topics), default=0)
        tw = max((len(t.typename) for t in self.topics), default=0)
        for i, t in enumerate(self.topics):
            head = "Topic information: " if i == 0 else " " * 19
            out.append(
                f"{head}Topic: {t.name:<{width}} | Type: {t.typename:<{tw}} | "
                f"Count: {t.count} | Serialization Format: {t.serialization}"
            )
        if not self.topics:
            out.append("Topic information: ")
        return out


@dataclass(frozen=True)
class BagMessage:
    topic: str
    typename: str
    log_time_ns: int
    cdr: bytes


def _size(n: int) -> str:
    for unit in ("B", "KiB", "MiB", "GiB"):
        if n < 1024 or unit == "GiB":
            return f"{n:.1f} {unit}" if unit != "B" else f"{n} B"
        n /= 1024  # type: ignore[assignment]
    return f"{n} B"


def _storage(reader: BagReader) -> str:
    if reader.format == "ros2":
        return "sqlite3" if any(reader.path.glob("*.db3")) else "mcap"
    return {"ros1": "rosbag_v2", "mcap": "mcap"}[reader.format]


def _bytes(path: Path) -> int:
    if path.is_dir():
        return sum(f.stat().st_size for f in path.iterdir() if f.is_file())
    return path.stat().st_size


def bag_info(path: str | Path) -> BagInfo:
    """Duration, start, end, message count and per-topic type/count/format of a bag."""
    with BagReader(path) as reader:
        topics: dict[str, list[BagConnection]] = {}
        for c in reader.connections:
            topics.setdefault(c.topic, []).append(c)
        infos = [
            TopicInfo(
                name=name,
                typename=conns[0].typename,
                count=sum(c.count for c in conns),
                serialization=conns[0].encoding,
            )
            for name, conns in sorted(topics.items())
        ]
        return BagInfo(
            path=Path(path),
            storage=_storage(reader),
            size_bytes=_bytes(reader.path),
            start_ns=reader.start_ns,
            end_ns=reader.end_ns,
            messages=reader.message_count,
            topics=infos,
        )


@dataclass(frozen=True)
class Converted:
    """What :func:`convert_bag` wrote, and the connections it could not convert."""

    path: Path
    messages: int
    skipped: list[tuple[BagConnection, int]]


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.resolve() == b.resolve()
    except OSError:
        return False


def convert_bag(src: str | Path, dst: str | Path, *, compression: str | None = None) -> Converted:
    """Copy a bag of any format into another; the output's extension decides its format
    (see :mod:`roverlab.bag.writers`). Messages keep their times; a ROS 1 -> ROS 1 copy
    keeps the bytes (``Header.seq`` included) and the connections' definitions.

    Connections whose type cannot be decoded (unknown and without a definition, or a
    definition other than roverlab's) are copied as bytes between ROS 1 bags, else skipped
    and returned in :attr:`Converted.skipped`.

    Raises:
        BagError: Unknown output extension or compression, unreadable input, output = input.
    """
    check_output(dst, compression)
    src_path = input_path(src)
    if _same_file(src_path, output_path(dst)):
        raise BagError(f"{dst}: is the input; convert writes a new bag, never in place")
    with BagReader(src_path) as reader:
        out = open_writer(dst, compression)
        handles: dict[int, int] = {}
        skipped: dict[int, list[Any]] = {}
        try:
            for msg in reader.messages():
                conn = msg.connection
                key = id(conn)
                handle = handles.get(key)
                if handle is None:
                    if key in skipped:
                        skipped[key][1] += 1
                        continue
                    if conn.problem and not (conn.encoding == out.encoding == "ros1"):
                        skipped[key] = [conn, 1]
                        continue
                    handle = handles[key] = _add_topic(out, conn)
                try:
                    out.write_raw(handle, msg.log_time_ns, msg.data, conn.encoding)
                except MessageError as err:
                    raise BagError(
                        f"{reader.path}: a {conn.typename} on {conn.topic} at "
                        f"{msg.log_time_ns / 1e9:.9f} s cannot be converted: {err}"
                    ) from err
        except BaseException:
            out.abort()
            raise
        out.finish()
        return Converted(out.path, out.count, [(c, int(n)) for c, n in skipped.values()])


def _add_topic(out: BagWriter, conn: BagConnection) -> int:
    ros1 = conn.ros1 if conn.encoding == "ros1" else None
    return out.add_topic(
        conn.topic,
        conn.typename,
        latched=conn.latched,
        callerid=conn.callerid or "/roverlab",
        ros1=ros1,
    )


@dataclass(frozen=True)
class Recovered:
    path: Path
    messages: int
    chunks: int
    dropped_bytes: int


def _recover_output(src: Path, out: str | Path | None, ext: str) -> Path:
    if out is not None:
        dst = Path(out)
    elif src.name.endswith(".part"):
        dst = src.with_name(src.name[: -len(".part")])
    else:  # a damaged finished bag: a new file beside it, never in place
        dst = src.with_name(f"{src.stem}.reindexed{ext}")
    if not dst.name.lower().endswith(ext):
        dst = dst.with_name(dst.name + ext)
    if _same_file(src, dst):
        raise BagError(f"{dst}: is the input; recover writes a new bag, never in place")
    return dst


def recover_bag(part: str | Path, out: str | Path | None = None) -> Recovered:
    """Write a readable bag with every whole chunk of an unfinished or damaged recording
    (``rosbag reindex``'s role, into a new file: the input is never changed).

    ``part`` is what a killed recorder left (``NAME.mcap.part``, ``NAME.bag.part``: a header,
    whole chunks, then at most one cut record) or a damaged ``.bag``. The output (default
    ``NAME.mcap`` / ``NAME.bag``, or ``NAME.reindexed.bag`` beside a damaged bag) has the
    connections and messages of every whole chunk, in their order.

    Raises:
        BagError: No such file, or nothing in it is a bag.
    """
    src = Path(part)
    if not src.is_file():
        raise BagError(f"{src}: no such file")
    with open(src, "rb") as fh:
        magic = fh.read(len(ROS1_MAGIC))
    if magic == ROS1_MAGIC or src.name.lower().endswith((".bag", ".bag.part")):
        return _reindex_ros1(src, _recover_output(src, out, ".bag"))
    return _recover_mcap(src, _recover_output(src, out, ".mcap"))


def _reindex_ros1(src: Path, dst: Path) -> Recovered:
    scan = scan_bag(src)
    if scan.damage is not None and scan.damage.offset == 0:
        raise BagError(f"{src}: {scan.damage}")
    result = open_writer(dst, part_suffix=".recovering")  # NAME.part may be the input
    try:
        handles: dict[int, int] = {}
        for conn_id, conn in scan.connections.items():
            handles[conn_id] = result.add_topic(
                conn.topic,
                conn.typename,
                latched=conn.latching,
                callerid=conn.callerid or "/roverlab",
                ros1=(conn.definition, conn.md5sum),
            )
        for conn_id, t, data in scan.messages:
            handle = handles.get(conn_id)
            if handle is not None:
                result.write_raw(handle, t, data, "ros1")
    except BaseException:
        result.abort()
        raise
    result.finish()
    return Recovered(dst, result.count, scan.chunks, max(0, scan.size - scan.read_to))


def _recover_mcap(src: Path, dst: Path) -> Recovered:
    size = src.stat().st_size
    result = open_writer(dst, "zstd", part_suffix=".recovering")  # NAME.part may be the input
    assert isinstance(result, McapBagWriter)
    copier = _McapCopier(result)
    chunks = 0
    try:
        with open(src, "rb") as fh:
            reader = StreamReader(fh, skip_magic=False, emit_chunks=False, validate_crcs=True)
            pending: list[Message] = []  # the messages of the chunk being read
            read_to = fh.tell()
            try:
                for rec in reader.records:
                    if isinstance(rec, Schema):
                        copier.schemas[rec.id] = rec
                    elif isinstance(rec, Channel):
                        copier.channels[rec.id] = rec
                    elif isinstance(rec, Message):
                        pending.append(rec)
                    else:  # a record after a chunk's messages: the chunk was whole
                        if pending:
                            chunks += 1
                        copier.write(pending)
                        pending = []
                        read_to = fh.tell()  # the end of the last whole record
                if pending:  # the file ended cleanly after a chunk
                    chunks += 1
                    copier.write(pending)
            except Exception as err:  # a cut file ends in any of mcap's, struct's, zstd's errors
                if not pending and result.count == 0 and not copier.schemas:
                    raise BagError(f"{src}: not an MCAP recording ({err})") from err
                # a chunk is decoded whole before its messages come out: `pending` is whole
                if pending:
                    chunks += 1
                    copier.write(pending)
            else:
                read_to = fh.tell()
    except BaseException:
        result.abort()
        raise
    result.finish()
    return Recovered(dst, result.count, chunks, max(0, size - read_to))


class _McapCopier:
    """Copies MCAP message records, with their schemas and channels, into a new file."""

    def __init__(self, out: McapBagWriter) -> None:
        self.out = out
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.handles: dict[tuple[str, str], int] = {}

    def write(self, pending: list[Message]) -> None:
        for m in pending:
            ch = self.channels.get(m.channel_id)
            if ch is None:
                continue
            schema = self.schemas.get(ch.schema_id)
            typename = schema.name if schema else ""
            key = (ch.topic, typename)
            handle = self.handles.get(key)
            if handle is None:
                text = schema.data.decode() if schema else ""
                handle = self.handles[key] = self.out.add_channel(ch.topic, typename, text)
            self.out.write_record(handle, m.log_time, m.publish_time, m.data)
