"""ROS 1 serialisation of the runtime's messages: Noetic's definitions, md5sums and bytes.

roverlab's messages are ROS 2 (``ROS2_JAZZY``) dataclasses. ROS 1 (TCPROS, ``.bag`` files)
carries the same messages in Noetic's layouts: ``std_msgs/Header`` starts with ``uint32 seq``,
``time``/``duration`` are ``secs``/``nsecs``, and a few types differ (``Marker``, ``Range``,
``SolidPrimitive``). This module gives, for every type:

* :func:`ros1_definition`: the full Noetic message definition (the text ``rosbag`` stores in
  connection records and TCPROS sends as ``message_definition``) and its md5sum; types Noetic
  lacks (``action_msgs``, ``unique_identifier_msgs``) get their ROS 2 definition in ROS 1 form;
* :func:`serialize_ros1` / :func:`deserialize_ros1`: runtime message <-> ROS 1 bytes;
* :func:`register_ros1_definition`: makes a type known from the definition text a bag or a
  publisher carries, so messages of types roverlab does not know can be read and replayed.

The bytes are made by rosbags' generated ROS 1 (de)serialisers, built here over the runtime's
classes: where a type's ROS 1 layout equals its ROS 2 fields (all but a handful), rosbags'
code reads and writes the runtime's dataclasses directly, with ``std_msgs/Header`` handled
here (``seq`` is written as given, 0 by default, and dropped on reading: the ROS 2 Header has
no ``seq``). Types whose layouts differ go through rosbags' Noetic classes, field by field.
"""

from __future__ import annotations

import functools
import struct
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.serde.ros1 import (
    generate_deserialize_ros1,
    generate_getsize_ros1,
    generate_serialize_ros1,
)
from rosbags.serde.utils import check_string
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.base import normalize_fieldname
from rosbags.typesys.store import Typestore

from ._store import NUMERIC_DTYPES, PLACEHOLDER_FIELD, STORE, normalize_type_name
from .cdr import _ERRORS
from .errors import SerializationError, UnknownTypeError

__all__ = [
    "ROS1_STORE",
    "deserialize_ros1",
    "register_ros1_definition",
    "ros1_definition",
    "ros1_typename",
    "serialize_ros1",
]

HEADER: Final = "std_msgs/msg/Header"
_TIME: Final = STORE.typestore.types["builtin_interfaces/msg/Time"]
_HEAD: Final = struct.Struct("<IiII")  # seq, stamp.secs, stamp.nsecs, len(frame_id)
_SEQ: Final = struct.Struct("<I")


def _noetic_store() -> Typestore:
    """Noetic's types, plus the ROS 2 types Noetic lacks (``tf2_msgs`` is not in rosbags'
    Noetic store; ``action_msgs``, ``unique_identifier_msgs``) in their ROS 2 fields."""
    store = get_typestore(Stores.ROS1_NOETIC)
    _copy_missing(store, list(STORE.typestore.fielddefs))
    return store


def _copy_missing(store: Typestore, names: list[str]) -> None:
    """Register in ``store`` the runtime's definitions of ``names`` it lacks (and their
    dependencies); types it has keep their ROS 1 definitions."""
    source = STORE.typestore.fielddefs
    todo = [n for n in names if n not in store.fielddefs]
    new: dict[str, Any] = {}
    while todo:
        name = todo.pop()
        if name in new or name in store.fielddefs or name not in source:
            continue
        new[name] = source[name]
        for _fname, desc in source[name][1]:
            ref = _referenced(desc)
            if ref is not None:
                todo.append(ref)
    if new:
        store.register(new)


def _referenced(desc: Any) -> str | None:
    if desc[0] == Nodetype.NAME:
        return str(desc[1])
    if desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE) and desc[1][0][0] == Nodetype.NAME:
        return str(desc[1][0][1])
    return None


#: Noetic's message types (rosbags' ``ROS1_NOETIC`` store) and the ROS 2 types it lacks.
ROS1_STORE: Final = _noetic_store()
_LOCK: Final = threading.RLock()


def _shape(desc: Any) -> Any:
    """A field description as its ROS 1 wire shape (string bounds and names left out)."""
    node = desc[0]
    if node == Nodetype.BASE:
        return ("base", desc[1][0])
    if node == Nodetype.NAME:
        return ("name", desc[1])
    return (int(node), _shape(desc[1][0]), desc[1][1] if node == Nodetype.ARRAY else 0)


def _fields(store: Typestore, name: str) -> list[tuple[str, Any]]:
    return [(n, d) for n, d in store.fielddefs[name][1] if n != PLACEHOLDER_FIELD]


@dataclass(frozen=True, slots=True)
class _Def:
    """What rosbags' generated ROS 1 code asks of ``typestore.get_msgdef(name)``."""

    name: str
    cls: type[Any]
    size_ros1: int
    getsize_ros1: Callable[..., int]
    serialize_ros1: Callable[..., int]
    deserialize_ros1: Callable[..., tuple[Any, int]]


def _header_getsize(pos: int, message: Any, _ts: Any) -> int:
    return pos + 16 + len(message.frame_id.encode())


def _header_serialize(rawdata: Any, pos: int, message: Any, _ts: Any) -> int:
    frame = message.frame_id.encode()
    stamp = message.stamp
    _HEAD.pack_into(rawdata, pos, 0, stamp.sec, stamp.nanosec, len(frame))
    pos += 16
    rawdata[pos : pos + len(frame)] = frame
    return pos + len(frame)


def _header_deserialize(rawdata: Any, pos: int, cls: Any, _ts: Any) -> tuple[Any, int]:
    _seq, sec, nsec, length = _HEAD.unpack_from(rawdata, pos)
    check_string(rawdata, pos + 12, length, cdr=False)
    frame = bytes(rawdata[pos + 16 : pos + 16 + length]).decode()
    return cls(_TIME(sec, nsec), frame), pos + 16 + length


class _Codec:
    """A duck-typed typestore for rosbags' generated ROS 1 code, over the runtime's classes."""

    max_sequence_length = 2**32 - 1

    def __init__(self) -> None:
        self._defs: dict[str, _Def] = {}

    def get_msgdef(self, name: str) -> _Def:
        found = self._defs.get(name)
        if found is None:
            with _LOCK:
                found = self._defs.get(name) or self._build(name)
                self._defs[name] = found
        return found

    def _build(self, name: str) -> _Def:
        cls = STORE.typestore.types[name]
        if name == HEADER:
            return _Def(name, cls, 0, _header_getsize, _header_serialize, _header_deserialize)
        _ensure_ros1(name)
        mine = _fields(STORE.typestore, name)
        theirs = _fields(ROS1_STORE, name)
        if [_shape(d) for _, d in mine] == [_shape(d) for _, d in theirs]:
            entries = [(normalize_fieldname(n), d) for n, d in mine]
            getsize, size = generate_getsize_ros1(entries, self)  # type: ignore[arg-type]
            return _Def(
                name,
                cls,
                size,
                getsize,
                generate_serialize_ros1(entries, self),  # type: ignore[arg-type]
                generate_deserialize_ros1(entries, self),  # type: ignore[arg-type]
            )
        return _converted_def(name, cls)


def _converted_def(name: str, cls: type[Any]) -> _Def:
    """ROS 1 code for a type whose Noetic layout differs: through rosbags' Noetic class."""
    theirs = ROS1_STORE.get_msgdef(name)
    to_ros1 = _converter(STORE.typestore, ROS1_STORE, name)
    from_ros1 = _converter(ROS1_STORE, STORE.typestore, name)

    def getsize(pos: int, message: Any, _ts: Any) -> int:
        return int(theirs.getsize_ros1(pos, to_ros1(message), ROS1_STORE))

    def serialize(rawdata: Any, pos: int, message: Any, _ts: Any) -> int:
        return int(theirs.serialize_ros1(rawdata, pos, to_ros1(message), ROS1_STORE))

    def deserialize(rawdata: Any, pos: int, _cls: Any, _ts: Any) -> tuple[Any, int]:
        msg, end = theirs.deserialize_ros1(rawdata, pos, theirs.cls, ROS1_STORE)
        return from_ros1(msg), end

    return _Def(name, cls, 0, getsize, serialize, deserialize)


def _zero(store: Typestore, desc: Any) -> Any:
    node = desc[0]
    if node == Nodetype.BASE:
        base = desc[1][0]
        return "" if base == "string" else NUMERIC_DTYPES[base].type(0).item()
    if node == Nodetype.NAME:
        return _zero_message(store, desc[1])
    (sub, count) = desc[1]
    length = count if node == Nodetype.ARRAY else 0
    if sub[0] == Nodetype.NAME:
        return [_zero_message(store, sub[1]) for _ in range(length)]
    if sub[1][0] == "string":
        return [""] * length
    return np.zeros(length, dtype=NUMERIC_DTYPES[sub[1][0]])


def _zero_message(store: Typestore, name: str) -> Any:
    cls = store.types[name]
    return cls(*(_zero(store, d) for _, d in store.fielddefs[name][1]))


def _step_zero(store: Typestore, desc: Any, _msg: Any) -> Any:
    return _zero(store, desc)


def _step_copy(attr: str, msg: Any) -> Any:
    return getattr(msg, attr)


def _step_one(attr: str, sub: Callable[[Any], Any], msg: Any) -> Any:
    return sub(getattr(msg, attr))


def _step_many(attr: str, sub: Callable[[Any], Any], msg: Any) -> Any:
    return [sub(item) for item in getattr(msg, attr)]


def _converter(src: Typestore, dst: Typestore, name: str) -> Callable[[Any], Any]:
    """Copies a message of ``src``'s class of ``name`` into ``dst``'s class, field by field
    (matched by name, case aside: ROS 1 ``D`` is ROS 2 ``d``); fields only ``dst`` has are
    zero, fields only ``src`` has are dropped."""
    cls = dst.types[name]
    have = {n.lower(): (normalize_fieldname(n), d) for n, d in src.fielddefs[name][1]}
    steps: list[Callable[[Any], Any]] = []
    for fname, desc in dst.fielddefs[name][1]:
        found = have.get(fname.lower())
        if found is None:
            steps.append(functools.partial(_step_zero, dst, desc))
            continue
        attr, sdesc = found
        ref = _referenced(desc)
        if ref is None or ref != _referenced(sdesc):
            steps.append(functools.partial(_step_copy, attr))
        elif desc[0] == Nodetype.NAME:
            steps.append(functools.partial(_step_one, attr, _converter(src, dst, ref)))
        else:
            steps.append(functools.partial(_step_many, attr, _converter(src, dst, ref)))

    def convert(msg: Any) -> Any:
        return cls(*(step(msg) for step in steps))

    return convert


_CODEC: Final = _Codec()
_Serializer = Callable[[Any, int], bytes]
_SERIALIZERS: dict[type[Any], _Serializer] = {}
_DESERIALIZERS: dict[str, Callable[[bytes], Any]] = {}


def _ensure_ros1(name: str) -> None:
    """Give ``ROS1_STORE`` a type registered in the runtime after start (interface packages,
    definitions carried by bags)."""
    if name not in ROS1_STORE.fielddefs:
        with _LOCK:
            _copy_missing(ROS1_STORE, [name])


def _resolve(typename: object) -> str:
    """The runtime's full name of a type; a type only Noetic has (``rosgraph_msgs/Log``,
    ``nav_msgs/GetMapActionResult``) is added to the runtime with Noetic's fields first."""
    try:
        return STORE.resolve(typename)
    except UnknownTypeError:
        if type(typename) is not str:
            raise
        full = normalize_type_name(typename)
        if full not in ROS1_STORE.fielddefs:
            raise
    with _LOCK:
        source = ROS1_STORE.fielddefs
        todo, new = [full], {}
        while todo:
            name = todo.pop()
            if name in new or name in STORE.typestore.fielddefs or STORE.has(name):
                continue
            new[name] = source[name]
            todo.extend(r for _, d in source[name][1] if (r := _referenced(d)) is not None)
        STORE.register(new)
    return STORE.resolve(full)


def ros1_typename(typename: object) -> str:
    """The ROS 1 name (``sensor_msgs/LaserScan``) of a type given in any form."""
    pkg, _kind, short = _resolve(typename).split("/")
    return f"{pkg}/{short}"


def ros1_definition(typename: object) -> tuple[str, str]:
    """The full ROS 1 message definition of a type and its md5sum.

    The text is what ``rosbag`` writes in a connection record and TCPROS sends as
    ``message_definition`` (the type's fields, then ``MSG: pkg/Type`` sections for each type
    it uses); the md5sum is Noetic's (``rosmsg md5``).

    Args:
        typename: Type name in any form (``sensor_msgs/LaserScan``), class or message.

    Returns:
        ``(definition, md5sum)``.

    Raises:
        UnknownTypeError: Unknown type.
    """
    full = _resolve(typename)
    _ensure_ros1(full)
    text, md5 = ROS1_STORE.generate_msgdef(full, ros_version=1)
    return str(text), str(md5)


def _make_serializer(full: str) -> _Serializer:
    msgdef = _CODEC.get_msgdef(full)
    getsize, write = msgdef.getsize_ros1, msgdef.serialize_ros1
    stamped = bool(ROS1_STORE.fielddefs[full][1]) and (
        ROS1_STORE.fielddefs[full][1][0][1] == (Nodetype.NAME, HEADER)
    )
    codec = _CODEC

    def run(msg: Any, seq: int) -> bytes:
        try:
            buf = bytearray(getsize(0, msg, codec))
            write(memoryview(buf), 0, msg, codec)
            if seq and stamped:
                _SEQ.pack_into(buf, 0, seq)
        except _ERRORS as exc:
            raise SerializationError(f"cannot serialise {full} for ROS 1: {exc}") from exc
        return bytes(buf)

    return run


def serialize_ros1(msg: Any, typename: object = None, *, seq: int = 0) -> bytes:
    """Serialise a runtime message in ROS 1's layout (what TCPROS and ``.bag`` files carry).

    Args:
        msg: A message of the runtime (rosbags ``ROS2_JAZZY`` dataclass).
        typename: Its type, if not the message's own (any name form).
        seq: ``header.seq`` of a message that starts with a Header (rospy numbers each
            publisher's messages); 0 otherwise.

    Returns:
        The ROS 1 bytes.

    Raises:
        UnknownTypeError: Unknown type.
        SerializationError: A field holds a value of the wrong kind.
    """
    cls = type(msg)
    func = _SERIALIZERS.get(cls) if typename is None else None
    if func is None:
        full = _resolve(cls if typename is None else typename)
        func = _make_serializer(full)
        if typename is None:
            _SERIALIZERS[cls] = func
    return func(msg, seq)


def _make_deserializer(full: str) -> Callable[[bytes], Any]:
    msgdef = _CODEC.get_msgdef(full)
    read, cls = msgdef.deserialize_ros1, msgdef.cls
    codec = _CODEC

    def run(data: bytes) -> Any:
        try:
            msg, pos = read(memoryview(data), 0, cls, codec)
        except _ERRORS as exc:
            raise SerializationError(f"cannot deserialise ROS 1 {full}: {exc}") from exc
        if pos != len(data):
            raise SerializationError(
                f"cannot deserialise ROS 1 {full}: {len(data) - pos} bytes left over"
            )
        return msg

    return run


def deserialize_ros1(data: bytes | bytearray | memoryview, typename: object) -> Any:
    """Read ROS 1 bytes into a runtime message (``header.seq`` is dropped: the ROS 2 Header
    has none).

    Number-array fields of the result are read-only numpy views of ``data`` (copied first
    unless it is ``bytes``).

    Args:
        data: The ROS 1 serialisation.
        typename: Type name in any form (``sensor_msgs/LaserScan``), class or factory.

    Raises:
        UnknownTypeError: Unknown type (see :func:`register_ros1_definition`).
        SerializationError: ``data`` is not a serialisation of the type.
    """
    if type(data) is not bytes:
        data = bytes(data)
    key = typename if type(typename) is str else _resolve(typename)
    func = _DESERIALIZERS.get(key)
    if func is None:
        full = _resolve(key)
        func = _DESERIALIZERS.get(full) or _make_deserializer(full)
        _DESERIALIZERS[full] = func
        _DESERIALIZERS[key] = func
    return func(data)


def register_ros1_definition(typename: str, definition: str, md5sum: str | None = None) -> str:
    """Make a type readable from the ROS 1 definition a bag or a publisher carries.

    Types the runtime lacks are added (to the runtime and to :data:`ROS1_STORE`), so their
    messages can be deserialised, published in-process and written again. A type the runtime
    knows is kept; if ``md5sum`` is given and differs from the known type's (another version
    of the message), the type cannot be read with the known layout.

    Args:
        typename: Type name in any form (``my_msgs/Status``).
        definition: The full definition text (``message_definition``).
        md5sum: The md5sum the bag or publisher gives, checked against a known type's.

    Returns:
        The type's full ROS 2 name (``my_msgs/msg/Status``).

    Raises:
        UnknownTypeError: The definition cannot be parsed, or it contradicts a known type.
    """
    full = normalize_type_name(typename)
    if not STORE.has(full):
        try:
            parsed = get_types_from_msg(definition, full)
        except Exception as err:  # rosbags raises its parser's own errors
            raise UnknownTypeError(f"cannot parse the definition of {typename}: {err}") from err
        known = STORE.typestore.fielddefs
        STORE.register({k: v for k, v in parsed.items() if k not in known and not STORE.has(k)})
    if md5sum not in (None, "", "*"):
        _text, mine = ros1_definition(full)
        if mine != md5sum:
            raise UnknownTypeError(
                f"{typename}: md5sum {md5sum} differs from the known definition's {mine}"
            )
    return full
