"""Writing bags: the output's extension decides the format.

* ``NAME.bag``: a ROS 1 bag (v2.0, chunked and indexed, as ``rosbag record`` writes), Noetic's
  layouts, with each connection's callerid, ``latching``, md5sum and full message definition;
  chunk compression ``none`` (rosbag's default), ``bz2`` or ``lz4``;
* ``NAME.mcap``: MCAP with ROS 2 CDR messages and ``ros2msg`` schemas (``ros2 bag record -s
  mcap``); chunk compression ``zstd`` (default), ``lz4`` or ``none``;
* a folder (a name without extension, or an existing directory) or ``NAME.db3``: a ROS 2 bag
  folder (sqlite3, as rosbags writes it; ``NAME.db3`` names the folder ``NAME``); ``none`` or
  ``zstd`` (per message).

Any other extension is refused before anything is written. A bag is written under a
temporary name (``NAME.part``) and renamed when finished, so an interrupted run never leaves
a file that looks complete.
"""

from __future__ import annotations

import contextlib
import os
import shutil
from abc import ABC, abstractmethod
from pathlib import Path
from typing import IO, Any, Final

import lz4.frame
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.interfaces import Connection
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode

from roverlab.bag.errors import BagError
from roverlab.msgs import (
    STORE,
    MessageError,
    deserialize,
    message_definition,
    normalize_type_name,
    serialize,
)
from roverlab.msgs.ros1 import deserialize_ros1, ros1_definition, serialize_ros1

__all__ = [
    "FORMATS",
    "BagWriter",
    "McapBagWriter",
    "bag_format",
    "open_writer",
    "output_path",
]

#: Format names by what they are called in messages and docs.
FORMATS: Final = {"ros1": "ROS 1 bag", "mcap": "MCAP", "ros2": "ROS 2 bag"}
_COMPRESSIONS: Final = {
    "ros1": ("none", "bz2", "lz4"),
    "mcap": ("zstd", "lz4", "none"),
    "ros2": ("none", "zstd"),
}
#: ROS 1's ``TIME_MIN``: rosbag refuses an index entry before it ("contains invalid time").
ROS1_TIME_MIN_NS: Final = 1
_EXTENSIONS: Final = ".bag (ROS 1), .mcap (MCAP), .db3 or a folder (ROS 2 bag)"


def bag_format(path: str | Path) -> str:
    """``ros1``, ``mcap`` or ``ros2``: the format a path names by its extension.

    Raises:
        BagError: Another extension.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix == ".bag":
        return "ros1"
    if suffix == ".mcap":
        return "mcap"
    if suffix == ".db3" or not suffix or p.is_dir():
        return "ros2"
    raise BagError(f"{p}: unknown bag format {p.suffix!r}: use {_EXTENSIONS}")


def output_path(path: str | Path) -> Path:
    """The file or folder written for ``path`` (``NAME.db3`` -> the ROS 2 bag folder ``NAME``)."""
    p = Path(path)
    return p.with_suffix("") if p.suffix.lower() == ".db3" else p


def default_compression(fmt: str) -> str:
    return _COMPRESSIONS[fmt][0]


def check_output(path: str | Path, compression: str | None = None) -> tuple[str, str]:
    """The format and compression for an output, checked before anything runs.

    Raises:
        BagError: Unknown extension, or a compression the format does not have.
    """
    fmt = bag_format(path)
    comp = default_compression(fmt) if compression in (None, "") else str(compression)
    if comp not in _COMPRESSIONS[fmt]:
        raise BagError(
            f"{path}: a {FORMATS[fmt]} has no {comp!r} compression "
            f"(use {', '.join(_COMPRESSIONS[fmt])})"
        )
    return fmt, comp


class BagWriter(ABC):
    """One output bag. Topics are added with :meth:`add_topic`; messages are written either
    as runtime messages (:meth:`write`) or as bytes already serialised (:meth:`write_raw`).

    Attributes:
        path: The finished bag's path.
        part: Where it is written until :meth:`finish`.
        count: Messages written.
    """

    encoding: str = "cdr"  #: the serialisation this format stores

    def __init__(self, path: Path, compression: str, part_suffix: str = ".part") -> None:
        self.path = path
        self.compression = compression
        self.part = path.with_name(path.name + part_suffix)
        self.count = 0
        self._types: list[str] = []

    @abstractmethod
    def _add(self, topic: str, typename: str, latched: bool, callerid: str, ros1: Any) -> int: ...

    @abstractmethod
    def _write(self, handle: int, time_ns: int, data: bytes) -> None: ...

    def add_topic(
        self,
        topic: str,
        typename: str,
        *,
        latched: bool = False,
        callerid: str = "/roverlab",
        ros1: tuple[str, str] | None = None,
    ) -> int:
        """A handle for writing ``topic``'s messages of ``typename`` (any name form).

        Args:
            latched: The topic is latched (transient local): a ROS 1 bag says ``latching=1``.
            callerid: The publishing node (ROS 1 connection records).
            ros1: ``(definition, md5sum)`` carried by a ROS 1 source, for its types; default
                Noetic's.
        """
        try:
            full = STORE.resolve(typename)
        except MessageError:
            if ros1 is None or self.encoding != "ros1":
                raise
            full = normalize_type_name(typename)  # copied as bytes, with the source's definition
        handle = self._add(topic, full, latched, callerid, ros1)
        while len(self._types) <= handle:
            self._types.append("")
        self._types[handle] = full
        return handle

    def write(self, handle: int, time_ns: int, msg: Any) -> None:
        """Write a runtime message."""
        data = serialize_ros1(msg) if self.encoding == "ros1" else serialize(msg)
        self._write(handle, time_ns, data)
        self.count += 1

    def write_raw(self, handle: int, time_ns: int, data: bytes, encoding: str) -> None:
        """Write bytes serialised as ``encoding`` (``ros1`` or ``cdr``), converting if needed."""
        if encoding != self.encoding:
            typename = self._types[handle]
            msg = (
                deserialize_ros1(data, typename)
                if encoding == "ros1"
                else deserialize(data, typename)
            )
            data = serialize_ros1(msg) if self.encoding == "ros1" else serialize(msg)
        self._write(handle, time_ns, data)
        self.count += 1

    @abstractmethod
    def flush(self) -> None:
        """Put what is written so far on disk as whole chunks (a kill loses no more)."""

    @abstractmethod
    def _close(self) -> None: ...

    def finish(self) -> None:
        """Finish the bag and give it its name."""
        self._close()
        os.replace(self.part, self.path)

    @abstractmethod
    def abort(self) -> None:
        """Drop the unfinished bag."""


class McapBagWriter(BagWriter):
    def __init__(self, path: Path, compression: str, part_suffix: str = ".part") -> None:
        super().__init__(path, compression, part_suffix)
        comp = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}.get(
            compression, CompressionType.NONE
        )
        self.fh: IO[bytes] = open(self.part, "wb")  # noqa: SIM115 - closed in _close()
        self.writer = McapWriter(self.fh, compression=comp)
        self.writer.start(profile="ros2", library="roverlab")
        self.schemas: dict[str, int] = {}

    def _add(self, topic: str, typename: str, latched: bool, callerid: str, ros1: Any) -> int:
        return self.add_channel(topic, typename, message_definition(typename))

    def add_channel(self, topic: str, typename: str, schema_text: str) -> int:
        """A channel with the ``ros2msg`` schema ``schema_text`` (copying MCAP records)."""
        schema = self.schemas.get(typename)
        if schema is None:
            schema = self.writer.register_schema(
                name=typename, encoding="ros2msg", data=schema_text.encode()
            )
            self.schemas[typename] = schema
        channel = self.writer.register_channel(
            topic=topic, message_encoding="cdr", schema_id=schema
        )
        return int(channel)

    def _write(self, handle: int, time_ns: int, data: bytes) -> None:
        self.writer.add_message(
            channel_id=handle, log_time=time_ns, publish_time=time_ns, data=data
        )

    def write_record(self, handle: int, log_ns: int, publish_ns: int, data: bytes) -> None:
        """Write CDR bytes with both MCAP times (copying MCAP records)."""
        self.writer.add_message(
            channel_id=handle, log_time=log_ns, publish_time=publish_ns, data=data
        )
        self.count += 1

    def flush(self) -> None:
        self.writer.flush()  # ends the chunk in progress: complete on disk

    def _close(self) -> None:
        self.writer.finish()
        self.fh.flush()
        os.fsync(self.fh.fileno())
        self.fh.close()

    def abort(self) -> None:
        self.fh.close()
        with contextlib.suppress(OSError):
            self.part.unlink()


def _roslz4_compress(data: bytes) -> bytes:
    """An LZ4 frame as ROS 1's roslz4 writes and reads it: independent 1 MB blocks, a content
    checksum and no content size (rosbags' default frames make Debian's rosbag fail with
    "malformed data to decompress")."""
    return bytes(
        lz4.frame.compress(
            data,
            block_size=lz4.frame.BLOCKSIZE_MAX1MB,
            block_linked=False,
            content_checksum=True,
            store_size=False,
        )
    )


class _Ros1(BagWriter):
    encoding = "ros1"

    def __init__(self, path: Path, compression: str, part_suffix: str = ".part") -> None:
        super().__init__(path, compression, part_suffix)
        with contextlib.suppress(FileNotFoundError):
            self.part.unlink()  # a stale part of an earlier run
        self.writer = Ros1Writer(self.part)
        if compression != "none":
            self.writer.set_compression(Ros1Writer.CompressionFormat[compression.upper()])
            if compression == "lz4":
                self.writer.compressor = _roslz4_compress
        self.writer.open()
        self.conns: list[Connection] = []

    def _add(self, topic: str, typename: str, latched: bool, callerid: str, ros1: Any) -> int:
        msgdef, md5 = ros1 if ros1 is not None else ros1_definition(typename)
        conn = self.writer.add_connection(
            topic,
            typename,
            msgdef=msgdef,
            md5sum=md5,
            callerid=callerid,
            latching=1 if latched else None,
        )
        self.conns.append(conn)
        return len(self.conns) - 1

    def _write(self, handle: int, time_ns: int, data: bytes) -> None:
        self.writer.write(self.conns[handle], max(time_ns, ROS1_TIME_MIN_NS), data)

    def flush(self) -> None:
        chunk = self.writer.chunks[-1]
        if chunk.data.tell():
            self.writer.write_chunk(chunk)
        assert self.writer.bio is not None
        self.writer.bio.flush()

    def _close(self) -> None:
        self.writer.close()

    def abort(self) -> None:
        self.writer.abort()
        with contextlib.suppress(OSError):
            self.part.unlink()


class _Ros2(BagWriter):
    def __init__(self, path: Path, compression: str, part_suffix: str = ".part") -> None:
        super().__init__(path, compression, part_suffix)
        self.part = path.parent / f".{path.name}{part_suffix}"
        if self.part.exists():
            shutil.rmtree(self.part)
        self.part.mkdir(parents=True)
        self.writer = Ros2Writer(self.part / path.name, version=9)
        if compression == "zstd":
            self.writer.set_compression(CompressionMode.MESSAGE, CompressionFormat.ZSTD)
        self.writer.open()
        self.conns: list[Connection] = []

    def _add(self, topic: str, typename: str, latched: bool, callerid: str, ros1: Any) -> int:
        self.conns.append(self.writer.add_connection(topic, typename, typestore=STORE.typestore))
        return len(self.conns) - 1

    def _write(self, handle: int, time_ns: int, data: bytes) -> None:
        self.writer.write(self.conns[handle], time_ns, data)

    def flush(self) -> None:
        pass  # rosbags' sqlite3 storage commits on close only

    def _close(self) -> None:
        self.writer.close()

    def finish(self) -> None:
        self._close()
        if self.path.exists():
            raise BagError(f"{self.path}: exists already; not overwriting a ROS 2 bag folder")
        os.replace(self.part / self.path.name, self.path)
        self.part.rmdir()

    def abort(self) -> None:
        with contextlib.suppress(Exception):
            self.writer.close()
        shutil.rmtree(self.part, ignore_errors=True)


def open_writer(
    path: str | Path, compression: str | None = None, *, part_suffix: str = ".part"
) -> BagWriter:
    """A writer for the format ``path``'s extension names (see the module's doc), writing
    to ``path`` + ``part_suffix`` until finished.

    Raises:
        BagError: Unknown extension or compression, or the file cannot be written.
    """
    fmt, comp = check_output(path, compression)
    out = output_path(path)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        if fmt == "ros1":
            return _Ros1(out, comp, part_suffix)
        if fmt == "mcap":
            return McapBagWriter(out, comp, part_suffix)
        return _Ros2(out, comp, part_suffix)
    except OSError as err:
        raise BagError(f"{out}: cannot write: {err.strerror or err}") from err
