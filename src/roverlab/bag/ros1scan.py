"""A record-by-record walk of a ROS 1 bag (format 2.0), for damaged files.

rosbags' reader trusts the index at the end of the file; when a bag is cut, unindexed or
corrupted it stops with a message that names no place. :func:`scan_bag` walks the records
from the start instead, as ``rosbag reindex`` does, and keeps every whole chunk: what
:func:`describe_damage` reports (the first problem and its byte offset) and what ``bag
recover`` / ``bag reindex`` copy into a new bag.

Format (http://wiki.ros.org/Bags/Format/2.0): ``#ROSBAG V2.0\\n``, then records of
``<header_len><header><data_len><data>``; a header is ``<len>name=value`` fields with an
``op`` byte: 0x03 bag header, 0x05 chunk (its data holds 0x07 connection and 0x02 message
records, compressed ``none``, ``bz2`` or ``lz4``), 0x04 index data, 0x06 chunk info.
"""

from __future__ import annotations

import bz2
import struct
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

import lz4.frame

__all__ = ["BagDamageError", "Ros1Scan", "ScannedConnection", "describe_damage", "scan_bag"]

MAGIC: Final = b"#ROSBAG V2.0\n"
OP_MSG, OP_BAG, OP_INDEX, OP_CHUNK, OP_CHUNK_INFO, OP_CONN = 2, 3, 4, 5, 6, 7
_OPS: Final = {OP_MSG, OP_BAG, OP_INDEX, OP_CHUNK, OP_CHUNK_INFO, OP_CONN}
#: A chunk larger than this (uncompressed) is damage, not data (rosbag's chunks are ~768 KB).
MAX_CHUNK_BYTES: Final = 1 << 30
_U32: Final = struct.Struct("<I")


class BagDamageError(Exception):
    """A record that cannot be read, at ``offset`` bytes into the file."""

    def __init__(self, problem: str, offset: int) -> None:
        super().__init__(f"{problem} at byte {offset}")
        self.problem = problem
        self.offset = offset


@dataclass(frozen=True)
class ScannedConnection:
    conn: int
    topic: str
    typename: str
    md5sum: str
    definition: str
    callerid: str
    latching: bool


@dataclass
class Ros1Scan:
    """What a walk of the file found.

    Attributes:
        connections: By connection id.
        messages: ``(conn, time_ns, data)`` of every whole chunk, in file order.
        chunks: Whole chunks read.
        indexed: The bag header points at an index.
        read_to: Offset after the last whole record.
        size: File size.
        damage: The first problem, or None when the whole file was read.
    """

    connections: dict[int, ScannedConnection] = field(default_factory=dict)
    messages: list[tuple[int, int, bytes]] = field(default_factory=list)
    chunks: int = 0
    indexed: bool = False
    read_to: int = 0
    size: int = 0
    damage: BagDamageError | None = None


def _fields(header: bytes, offset: int) -> dict[str, bytes]:
    out: dict[str, bytes] = {}
    pos = 0
    while pos < len(header):
        if pos + 4 > len(header):
            raise BagDamageError("a record header field is cut", offset + pos)
        (n,) = _U32.unpack_from(header, pos)
        item = header[pos + 4 : pos + 4 + n]
        if n > len(header) - pos - 4 or b"=" not in item:
            raise BagDamageError("a record header field is malformed", offset + pos)
        name, _, value = item.partition(b"=")
        out[name.decode("latin-1")] = value
        pos += 4 + n
    return out


def _records(buf: bytes, base: int) -> Iterator[tuple[int, dict[str, bytes], bytes, int, int]]:
    """``(op, fields, data, offset, end)`` of the records in ``buf``; offsets are
    ``base + pos``."""
    pos = 0
    while pos < len(buf):
        offset = base + pos
        if pos + 4 > len(buf):
            raise BagDamageError("the file ends inside a record", offset)
        (hlen,) = _U32.unpack_from(buf, pos)
        if hlen > len(buf) - pos - 8:
            raise BagDamageError(
                f"a record header claims {hlen} bytes; the rest is shorter", offset
            )
        fields = _fields(buf[pos + 4 : pos + 4 + hlen], offset + 4)
        (dlen,) = _U32.unpack_from(buf, pos + 4 + hlen)
        start = pos + 8 + hlen
        if dlen > len(buf) - start:
            raise BagDamageError(f"a record claims {dlen} data bytes; the rest is shorter", offset)
        op = fields.get("op", b"")
        if len(op) != 1 or op[0] not in _OPS:
            raise BagDamageError(f"unknown op code {op.hex() or 'missing'}", offset)
        yield op[0], fields, buf[start : start + dlen], offset, base + start + dlen
        pos = start + dlen


def _uint(fields: dict[str, bytes], name: str, size: int, offset: int) -> int:
    value = fields.get(name)
    if value is None or len(value) != size:
        raise BagDamageError(f"a record lacks a valid {name!r}", offset)
    return int.from_bytes(value, "little")


def _time(value: bytes | None, offset: int) -> int:
    if value is None or len(value) != 8:
        raise BagDamageError("a message record lacks a valid time", offset)
    secs, nsecs = struct.unpack("<II", value)
    return secs * 1_000_000_000 + nsecs


def _text(fields: dict[str, bytes], name: str) -> str:
    return fields.get(name, b"").decode("utf-8", errors="replace")


def _connection(fields: dict[str, bytes], data: bytes, offset: int) -> ScannedConnection:
    conn = _uint(fields, "conn", 4, offset)
    inner = _fields(data, offset)
    return ScannedConnection(
        conn=conn,
        topic=_text(fields, "topic") or _text(inner, "topic"),
        typename=_text(inner, "type"),
        md5sum=_text(inner, "md5sum"),
        definition=_text(inner, "message_definition"),
        callerid=_text(inner, "callerid"),
        latching=_text(inner, "latching") == "1",
    )


def _chunk_data(fields: dict[str, bytes], data: bytes, offset: int) -> bytes:
    comp = _text(fields, "compression")
    size = _uint(fields, "size", 4, offset)
    if size > MAX_CHUNK_BYTES:
        raise BagDamageError(f"a chunk claims {size} bytes uncompressed", offset)
    try:
        if comp == "none":
            out = data
        elif comp == "bz2":
            out = bz2.decompress(data)
        elif comp == "lz4":
            out = lz4.frame.decompress(data)
        else:
            raise BagDamageError(f"a chunk has unknown compression {comp!r}", offset)
    except (OSError, ValueError, RuntimeError, EOFError) as err:
        raise BagDamageError(f"a {comp} chunk does not decompress ({err})", offset) from err
    if len(out) != size:
        raise BagDamageError(f"a chunk claims {size} bytes but holds {len(out)}", offset)
    return out


def scan_bag(path: str | Path) -> Ros1Scan:
    """Walk a ROS 1 bag's records; never raises for damage (see :attr:`Ros1Scan.damage`).

    Raises:
        OSError: The file cannot be read.
    """
    with open(path, "rb") as fh:
        buf = fh.read()
    scan = Ros1Scan(size=len(buf))
    if not buf.startswith(MAGIC):
        scan.damage = BagDamageError("not a ROS 1 bag (no '#ROSBAG V2.0' line)", 0)
        return scan
    scan.read_to = len(MAGIC)
    try:
        for op, fields, data, offset, end in _records(buf[len(MAGIC) :], len(MAGIC)):
            if op == OP_BAG:
                scan.indexed = _uint(fields, "index_pos", 8, offset) != 0
            elif op == OP_CHUNK:
                found = _chunk(fields, data, offset)
                scan.connections.update(found[0])
                scan.messages.extend(found[1])
                scan.chunks += 1
            elif op == OP_CONN:
                conn = _connection(fields, data, offset)
                scan.connections.setdefault(conn.conn, conn)
            elif op == OP_MSG:  # an unchunked message record
                scan.messages.append(
                    (_uint(fields, "conn", 4, offset), _time(fields.get("time"), offset), data)
                )
            scan.read_to = end
    except BagDamageError as damage:
        scan.damage = damage
    return scan


def _chunk(
    fields: dict[str, bytes], data: bytes, offset: int
) -> tuple[dict[int, ScannedConnection], list[tuple[int, int, bytes]]]:
    inner = _chunk_data(fields, data, offset)
    conns: dict[int, ScannedConnection] = {}
    msgs: list[tuple[int, int, bytes]] = []
    try:
        for op, sub, payload, _pos, _end in _records(inner, 0):
            if op == OP_CONN:
                conn = _connection(sub, payload, offset)
                conns[conn.conn] = conn
            elif op == OP_MSG:
                msgs.append(
                    (_uint(sub, "conn", 4, offset), _time(sub.get("time"), offset), payload)
                )
            else:
                raise BagDamageError(f"a chunk holds a record of op {op}", offset)
    except BagDamageError as err:
        raise BagDamageError(f"the chunk is damaged inside ({err.problem})", offset) from err
    return conns, msgs


def describe_damage(path: Path, err: BaseException) -> str:
    """One line naming the file, the problem and its byte offset, for a bag rosbags could
    not read (``err``); the walk finds the place, ``err`` is the fallback."""
    try:
        scan = scan_bag(path)
    except OSError as oserr:
        return f"{path}: cannot read: {oserr.strerror or oserr}"
    hint = f"; `roverlab bag reindex {path}` rebuilds what can be read"
    if scan.damage is not None:
        if scan.damage.offset == 0:
            return f"{path}: {scan.damage}"
        return f"{path}: {scan.damage} (of {scan.size}){hint}"
    if not scan.indexed:
        return f"{path}: the bag is not indexed (an unfinished recording){hint}"
    return f"{path}: the bag's index is damaged ({err}){hint}"
