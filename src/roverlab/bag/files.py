"""Reading bags: ``ros2 bag info``, ``convert`` and ``rosbag reindex``'s role (recover).

Every reader goes through rosbags' :class:`~rosbags.highlevel.AnyReader`, so a ROS 1
``.bag``, a ROS 2 bag (sqlite3 or MCAP folder) and a single ``.mcap`` file are all inputs.
Output is always one MCAP file with ROS 2 CDR messages and ``ros2msg`` schemas, written to a
temporary name and renamed.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer
from rosbags.highlevel import AnyReader, AnyReaderError

from roverlab.bag.recorder import BagError
from roverlab.msgs import STORE

__all__ = [
    "BagInfo",
    "BagMessage",
    "TopicInfo",
    "bag_info",
    "convert_bag",
    "open_reader",
    "read_messages",
    "recover_bag",
]

_COMPRESSION = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}


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


def _check_input(path: Path) -> Path:
    if path.name.endswith(".part"):
        raise BagError(
            f"{path}: an unfinished recording (the recorder was killed); "
            f"run `roverlab bag recover {path}` first"
        )
    if not path.exists():
        raise BagError(f"{path}: no such file or directory")
    if path.is_file() and path.suffix.lower() == ".db3":  # a ROS 2 bag named by its database
        return path.parent
    return path


@contextlib.contextmanager
def open_reader(path: str | Path) -> Iterator[AnyReader]:
    """An opened rosbags AnyReader for a .bag, a ROS 2 bag folder or a .mcap file."""
    p = _check_input(Path(path))
    try:
        reader = AnyReader([p], default_typestore=STORE.typestore)
        reader.open()
    except (AnyReaderError, OSError, ValueError, KeyError) as err:
        raise BagError(f"{p}: cannot read as a ROS bag or MCAP file: {err}") from err
    try:
        yield reader
    finally:
        reader.close()


def _storage(path: Path) -> str:
    if path.is_dir():
        return "sqlite3" if any(path.glob("*.db3")) else "mcap"
    return {".bag": "rosbag_v2", ".mcap": "mcap"}.get(path.suffix.lower(), "unknown")


def _bytes(path: Path) -> int:
    if path.is_dir():
        return sum(f.stat().st_size for f in path.iterdir() if f.is_file())
    return path.stat().st_size


def bag_info(path: str | Path) -> BagInfo:
    """Duration, start, end, message count and per-topic type/count/format of a bag."""
    p = Path(path)
    with open_reader(p) as reader:
        ros1 = reader.is2 is False
        topics: dict[str, list[Any]] = {}
        for c in reader.connections:
            topics.setdefault(c.topic, []).append(c)
        infos = [
            TopicInfo(
                name=name,
                typename=conns[0].msgtype,
                count=sum(c.msgcount for c in conns),
                serialization="ros1" if ros1 else "cdr",
            )
            for name, conns in sorted(topics.items())
        ]
        return BagInfo(
            path=p,
            storage=_storage(_check_input(p)),
            size_bytes=_bytes(_check_input(p)),
            start_ns=reader.start_time if reader.message_count else 0,
            end_ns=reader.end_time - 1 if reader.message_count else 0,  # rosbags: last + 1
            messages=reader.message_count,
            topics=infos,
        )


def read_messages(
    reader: AnyReader, topics: list[str] | None = None, start_ns: int | None = None
) -> Iterator[BagMessage]:
    """The messages of an opened bag in time order, as ROS 2 CDR (ROS 1 data converted)."""
    conns = [c for c in reader.connections if topics is None or c.topic in topics]
    ts = reader.typestore
    for conn, t, raw in reader.messages(connections=conns, start=start_ns):
        data = raw if reader.is2 else ts.ros1_to_cdr(raw, conn.msgtype)
        yield BagMessage(conn.topic, conn.msgtype, t, bytes(data))


def _schema_text(reader: AnyReader, typename: str) -> str:
    text, _ = reader.typestore.generate_msgdef(typename, ros_version=2)
    return str(text)


class _McapOut:
    """An MCAP file written to ``OUT.tmp`` and renamed on :meth:`finish`."""

    def __init__(self, path: Path, compression: str) -> None:
        if compression not in _COMPRESSION:
            raise BagError(f"unknown compression {compression!r} (zstd, lz4 or none)")
        self.path = path
        self.tmp = path.with_name(path.name + ".tmp")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            self.fh: IO[bytes] = open(self.tmp, "wb")  # noqa: SIM115 - closed in finish()
        except OSError as err:
            raise BagError(f"{path}: cannot write: {err.strerror}") from err
        self.writer = Writer(self.fh, compression=_COMPRESSION[compression])
        self.writer.start(profile="ros2", library="roverlab")
        self.schemas: dict[str, int] = {}
        self.channels: dict[tuple[str, str], int] = {}
        self.count = 0

    def channel(self, topic: str, typename: str, schema_text: str) -> int:
        key = (topic, typename)
        if key not in self.channels:
            if typename not in self.schemas:
                self.schemas[typename] = self.writer.register_schema(
                    name=typename, encoding="ros2msg", data=schema_text.encode()
                )
            self.channels[key] = self.writer.register_channel(
                topic=topic, message_encoding="cdr", schema_id=self.schemas[typename]
            )
        return self.channels[key]

    def write(self, channel: int, log_ns: int, publish_ns: int, data: bytes) -> None:
        self.writer.add_message(
            channel_id=channel, log_time=log_ns, publish_time=publish_ns, data=data
        )
        self.count += 1

    def finish(self) -> None:
        self.writer.finish()
        self.fh.flush()
        os.fsync(self.fh.fileno())
        self.fh.close()
        os.replace(self.tmp, self.path)

    def abort(self) -> None:
        self.fh.close()
        with contextlib.suppress(OSError):
            self.tmp.unlink()


def convert_bag(src: str | Path, dst: str | Path, *, compression: str = "zstd") -> int:
    """Copy a ROS 1 .bag, ROS 2 bag or MCAP file into one MCAP file (ROS 2 CDR); returns the
    number of messages written."""
    out_path = Path(dst)
    if out_path.suffix.lower() != ".mcap":
        raise BagError(f"{out_path}: the output must be an .mcap file")
    with open_reader(src) as reader:
        out = _McapOut(out_path, compression)
        try:
            texts: dict[str, str] = {}
            for msg in read_messages(reader):
                if msg.typename not in texts:
                    texts[msg.typename] = _schema_text(reader, msg.typename)
                ch = out.channel(msg.topic, msg.typename, texts[msg.typename])
                out.write(ch, msg.log_time_ns, msg.log_time_ns, msg.cdr)
        except BaseException:
            out.abort()
            raise
        out.finish()
        return out.count


@dataclass(frozen=True)
class Recovered:
    path: Path
    messages: int
    chunks: int
    dropped_bytes: int


def recover_bag(part: str | Path, out: str | Path | None = None) -> Recovered:
    """Write a readable MCAP with every complete chunk of an unfinished recording.

    ``part`` is what a killed recorder left (``NAME.mcap.part``): a header, complete chunks
    and then at most one cut record. The output (default: ``NAME.mcap``) has the schemas,
    channels and messages of every complete record, in their order.
    """
    src = Path(part)
    if not src.is_file():
        raise BagError(f"{src}: no such file")
    if out is None:
        name = src.name[: -len(".part")] if src.name.endswith(".part") else src.name + ".recovered"
        dst = src.with_name(name if name.endswith(".mcap") else name + ".mcap")
    else:
        dst = Path(out)
    size = src.stat().st_size
    result = _McapOut(dst, "zstd")
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    chunks = 0
    try:
        with open(src, "rb") as fh:
            reader = StreamReader(fh, skip_magic=False, emit_chunks=False, validate_crcs=True)
            records = reader.records
            pending: list[Message] = []  # the messages of the chunk being read
            read_to = fh.tell()
            try:
                for rec in records:
                    if isinstance(rec, Schema):
                        schemas[rec.id] = rec
                    elif isinstance(rec, Channel):
                        channels[rec.id] = rec
                    elif isinstance(rec, Message):
                        pending.append(rec)
                    else:  # a record after a chunk's messages: the chunk was whole
                        if pending:
                            chunks += 1
                        _write_pending(result, pending, schemas, channels)
                        pending = []
                        read_to = fh.tell()  # the end of the last whole record
                if pending:  # the file ended cleanly after a chunk
                    chunks += 1
                    _write_pending(result, pending, schemas, channels)
            except Exception as err:  # a cut file ends in any of mcap's, struct's, zstd's errors
                if not pending and result.count == 0 and not schemas:
                    raise BagError(f"{src}: not an MCAP recording ({err})") from err
                # a chunk is decoded whole before its messages come out: `pending` is whole
                if pending:
                    chunks += 1
                    _write_pending(result, pending, schemas, channels)
            else:
                read_to = fh.tell()
    except BaseException:
        result.abort()
        raise
    result.finish()
    return Recovered(dst, result.count, chunks, max(0, size - read_to))


def _write_pending(
    out: _McapOut, pending: list[Message], schemas: dict[int, Schema], channels: dict[int, Channel]
) -> None:
    for m in pending:
        ch = channels.get(m.channel_id)
        if ch is None:
            continue
        schema = schemas.get(ch.schema_id)
        typename = schema.name if schema else ""
        text = schema.data.decode() if schema else ""
        cid = out.channel(ch.topic, typename, text)
        out.write(cid, m.log_time, m.publish_time, m.data)
