"""Reading bags of every format into the runtime's messages.

A ROS 1 ``.bag`` is read with rosbags' ROS 1 reader and decoded with the definitions it
carries (ROS 1 layouts: ``Header.seq``, ``time`` as secs/nsecs) through
:mod:`roverlab.msgs.ros1`; a type roverlab does not know is learnt from the bag's definition.
An ``.mcap`` file or a ROS 2 bag folder (sqlite3 or MCAP) is read with rosbags' AnyReader; its
messages are ROS 2 CDR. Messages come out in time order, as raw bytes with their encoding and
connection, decoded only when asked (:meth:`BagMessage.decode`): copying a bag to one of the
same serialisation never decodes a message.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import Connection, ConnectionExtRosbag1
from rosbags.rosbag1 import Reader as Ros1Reader

from roverlab.bag.errors import BagError
from roverlab.bag.ros1scan import describe_damage
from roverlab.msgs import STORE, MessageError, deserialize
from roverlab.msgs.ros1 import deserialize_ros1, register_ros1_definition

__all__ = ["BagConnection", "BagMessage", "BagReader", "input_path"]

#: Topics played and copied as latched when the bag does not say (ROS 2 bags, MCAP).
LATCHED_TOPICS = frozenset({"/tf_static", "/map", "/map_metadata", "/robot_description"})


@dataclass(frozen=True)
class BagConnection:
    """One connection (ROS 1) or channel (MCAP, ROS 2) of a bag.

    Attributes:
        topic: Topic name.
        typename: Type as the bag names it, in the ``pkg/msg/Name`` form.
        count: Messages on it.
        encoding: ``ros1`` or ``cdr``.
        latched: A ROS 1 connection with ``latching=1``, or a topic ROS latches.
        callerid: The recording's publisher (ROS 1), else ``''``.
        ros1: ``(definition, md5sum)`` of a ROS 1 connection.
        problem: Why its messages cannot be decoded (``''`` when they can).
    """

    topic: str
    typename: str
    count: int
    encoding: str
    latched: bool = False
    callerid: str = ""
    ros1: tuple[str, str] | None = None
    problem: str = ""


@dataclass(frozen=True, slots=True)
class BagMessage:
    """One message of a bag, still serialised."""

    connection: BagConnection
    log_time_ns: int
    data: bytes

    @property
    def topic(self) -> str:
        return self.connection.topic

    @property
    def typename(self) -> str:
        return self.connection.typename

    def decode(self) -> Any:
        """The runtime message (raises :class:`~roverlab.msgs.MessageError`)."""
        if self.connection.encoding == "ros1":
            return deserialize_ros1(self.data, self.connection.typename)
        return deserialize(self.data, self.connection.typename)


def input_path(path: str | Path) -> Path:
    """Check an input bag exists and is not a killed recording; a ROS 2 bag named by its
    ``.db3`` is its folder."""
    p = Path(path)
    if p.name.endswith(".part"):
        raise BagError(
            f"{p}: an unfinished recording (the recorder was killed); "
            f"run `roverlab bag recover {p}` first"
        )
    if not p.exists():
        raise BagError(f"{p}: no such file or directory")
    if p.is_file() and p.suffix.lower() == ".db3":
        return p.parent
    return p


def _ros1_connection(conn: Connection) -> BagConnection:
    ext = conn.ext
    latched = isinstance(ext, ConnectionExtRosbag1) and str(ext.latching or "0") == "1"
    callerid = ext.callerid or "" if isinstance(ext, ConnectionExtRosbag1) else ""
    problem = ""
    typename = conn.msgtype
    try:
        register_ros1_definition(typename, conn.msgdef.data, conn.digest)
    except MessageError as err:
        problem = str(err)
    return BagConnection(
        topic=conn.topic,
        typename=typename,
        count=conn.msgcount,
        encoding="ros1",
        latched=latched,
        callerid=callerid,
        ros1=(conn.msgdef.data, conn.digest),
        problem=problem,
    )


def _cdr_connection(conn: Connection, reader: AnyReader) -> BagConnection:
    typename = conn.msgtype
    problem = ""
    theirs = reader.typestore.fielddefs
    try:
        if STORE.has(typename):
            mine = STORE.typestore.fielddefs[STORE.resolve(typename)][1]
            if typename in theirs and _lower(theirs[typename][1]) != _lower(mine):
                problem = f"{typename}: the bag's definition differs from roverlab's"
        else:
            todo, new = [typename], {}
            while todo:
                name = todo.pop()
                if name in new or STORE.has(name) or name not in theirs:
                    continue
                new[name] = theirs[name]
                todo.extend(_refs(theirs[name][1]))
            STORE.register(new)
            STORE.resolve(typename)
    except MessageError as err:
        problem = str(err)
    return BagConnection(
        topic=conn.topic,
        typename=typename,
        count=conn.msgcount,
        encoding="cdr",
        latched=conn.topic in LATCHED_TOPICS,
        problem=problem,
    )


def _lower(fields: Any) -> list[tuple[str, Any]]:
    return [(name.lower(), desc) for name, desc in fields]


def _refs(fields: Any) -> list[str]:
    out = []
    for _name, desc in fields:
        if desc[0] == 2:  # Nodetype.NAME
            out.append(str(desc[1]))
        elif desc[0] in (3, 4) and desc[1][0][0] == 2:  # array / sequence of messages
            out.append(str(desc[1][0][1]))
    return out


class BagReader:
    """An opened bag of any format (a context manager).

    Attributes:
        path: The bag (a ROS 2 bag's folder).
        format: ``ros1``, ``mcap`` or ``ros2``.
        connections: Its connections, in the bag's order.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = input_path(path)
        if self.path.is_dir():
            self.format = "ros2"
        elif self.path.suffix.lower() == ".bag":
            self.format = "ros1"
        else:
            self.format = "mcap"
        self.connections: list[BagConnection] = []
        self._by_conn: dict[int, BagConnection] = {}  # by id() of rosbags' connection
        self._conns: list[Connection] = []
        self._ros1: Ros1Reader | None = None
        self._any: AnyReader | None = None
        self._stack = contextlib.ExitStack()

    def __enter__(self) -> BagReader:
        try:
            self._open()
        except BaseException:
            self._stack.close()
            raise
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self._stack.close()

    def _open(self) -> None:
        if self.format == "ros1":
            reader = Ros1Reader(self.path)
            try:
                reader.open()
            except Exception as err:  # a damaged file raises any of rosbags' or struct's errors
                raise BagError(describe_damage(self.path, err)) from err
            self._stack.callback(reader.close)
            self._ros1 = reader
            for conn in reader.connections:
                bc = _ros1_connection(conn)
                self._by_conn[id(conn)] = bc
                self._conns.append(conn)
                self.connections.append(bc)
            return
        try:
            anyr = AnyReader([self.path], default_typestore=STORE.typestore)
            anyr.open()
        except (AnyReaderError, OSError, ValueError, KeyError) as err:
            raise BagError(f"{self.path}: cannot read as a ROS bag or MCAP file: {err}") from err
        self._stack.callback(anyr.close)
        self._any = anyr
        for conn in anyr.connections:
            bc = _cdr_connection(conn, anyr)
            self._by_conn[id(conn)] = bc
            self._conns.append(conn)
            self.connections.append(bc)

    @property
    def _reader(self) -> Any:
        reader = self._ros1 if self._ros1 is not None else self._any
        if reader is None:
            raise BagError(f"{self.path}: the bag is not open")
        return reader

    @property
    def message_count(self) -> int:
        return int(self._reader.message_count)

    @property
    def start_ns(self) -> int:
        """Time of the first message (0 when empty)."""
        return int(self._reader.start_time) if self.message_count else 0

    @property
    def end_ns(self) -> int:
        """Time of the last message (0 when empty)."""
        return int(self._reader.end_time) - 1 if self.message_count else 0  # rosbags: last + 1

    def messages(
        self, topics: list[str] | None = None, start_ns: int | None = None
    ) -> Iterator[BagMessage]:
        """The messages of ``topics`` (default all) from ``start_ns`` on, in time order."""
        wanted = [c for c in self._conns if topics is None or c.topic in topics]
        by_conn = self._by_conn
        messages = self._reader.messages(connections=wanted, start=start_ns)
        while True:
            try:
                conn, t, raw = next(messages)
            except StopIteration:
                return
            except Exception as err:  # a damaged file raises any of rosbags' or struct's errors
                if self.format != "ros1":
                    raise BagError(f"{self.path}: cannot read a message: {err}") from err
                raise BagError(describe_damage(self.path, err)) from err
            yield BagMessage(by_conn[id(conn)], t, bytes(raw))
