"""ROS 2 CDR serialisation of messages, through the rosbags typestore's generated code.

Hot path of the inter-process transport: the callables are built once per type and cached
by class (serialise) or by the exact type reference the caller passes (deserialise), so a
call costs one dict lookup plus rosbags' generated (de)serialiser.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any, Final

from rosbags.serde import SerdeError

from ._store import STORE, normalize_type_name
from .errors import SerializationError

__all__ = ["cdr_size", "deserialize", "message_definition", "serialize"]

_ERRORS: Final = (
    struct.error,
    SerdeError,
    TypeError,
    ValueError,
    AttributeError,
    IndexError,
    UnicodeError,
)

_Serializer = Callable[[Any], bytes]
_Deserializer = Callable[[bytes | bytearray | memoryview], Any]

_SERIALIZERS: dict[type[Any], _Serializer] = {}
_DESERIALIZERS: dict[object, _Deserializer] = {}


def _make_serializer(typename: str) -> _Serializer:
    typestore = STORE.typestore
    msgdef = typestore.get_msgdef(typename)
    getsize = msgdef.getsize_cdr
    write = msgdef.serialize_cdr_le

    def run(msg: Any) -> bytes:
        try:
            size = getsize(0, msg, typestore)
            buf = bytearray(size + 4)
            buf[1] = 1  # encapsulation CDR_LE: 00 01 00 00
            write(memoryview(buf)[4:], 0, msg, typestore)
        except _ERRORS as exc:
            raise SerializationError(f"cannot serialise {typename}: {exc}") from exc
        return bytes(buf)

    return run


def _make_deserializer(typename: str) -> _Deserializer:
    typestore = STORE.typestore
    msgdef = typestore.get_msgdef(typename)
    cls = msgdef.cls
    read_le = msgdef.deserialize_cdr_le
    read_be = msgdef.deserialize_cdr_be

    def run(data: bytes | bytearray | memoryview) -> Any:
        if type(data) is not bytes:
            data = bytes(data)  # arrays of the message are views of the buffer: keep it immutable
        if len(data) < 4 or data[0] != 0 or data[1] > 1:
            raise SerializationError(
                f"cannot deserialise {typename}: not a CDR buffer (header {data[:4]!r})"
            )
        read = read_le if data[1] else read_be
        try:
            msg, pos = read(memoryview(data)[4:], 0, cls, typestore)
        except _ERRORS as exc:
            raise SerializationError(f"cannot deserialise {typename}: {exc}") from exc
        if pos + 4 + 3 < len(data):
            raise SerializationError(
                f"cannot deserialise {typename}: {len(data) - 4 - pos} bytes left over"
            )
        return msg

    return run


def serialize(msg: Any) -> bytes:
    """Serialise a message to ROS 2 CDR (little endian, with the 4-byte encapsulation header).

    Args:
        msg: A message (rosbags dataclass instance) of any store type.

    Returns:
        The CDR bytes, as ``rclpy.serialization.serialize_message`` gives them.

    Raises:
        UnknownTypeError: ``msg`` is not a message of the store.
        SerializationError: A field holds a value of the wrong kind (build messages with the
            factories to avoid this).
    """
    try:
        return _SERIALIZERS[type(msg)](msg)
    except KeyError:
        pass
    cls = type(msg)
    typename = STORE.resolve(cls)
    func = _make_serializer(typename)
    _SERIALIZERS[cls] = func
    return func(msg)


def deserialize(data: bytes | bytearray | memoryview, typename: object) -> Any:
    """Deserialise ROS 2 CDR bytes (either endianness) into a message.

    Number-array fields of the result are zero-copy, read-only numpy views of ``data``
    (copied first unless it is ``bytes``); ``.copy()`` them before writing in place.

    Args:
        data: CDR bytes with the 4-byte encapsulation header.
        typename: Type name in any accepted form, rosbags class or factory.

    Returns:
        The message.

    Raises:
        UnknownTypeError: Unknown type.
        SerializationError: ``data`` is not a valid serialisation of the type.
    """
    try:
        func = _DESERIALIZERS[typename]
    except (KeyError, TypeError):
        full = STORE.resolve(typename)
        func = _DESERIALIZERS.get(full) or _make_deserializer(full)
        _DESERIALIZERS[full] = func
        if type(typename) is str or getattr(typename, "__hash__", None) is not None:
            _DESERIALIZERS[typename] = func
    return func(data)


def cdr_size(msg: Any) -> int:
    """Size in bytes of ``serialize(msg)``, without serialising."""
    typename = STORE.resolve(type(msg))
    return 4 + int(STORE.typestore.get_msgdef(typename).getsize_cdr(0, msg, STORE.typestore))


def message_definition(typename: str) -> str:
    """The ``.msg`` text of a type with its dependencies (the ``ros2msg`` schema of MCAP
    files and ROS 2 bags)."""
    text, _ = STORE.typestore.generate_msgdef(STORE.resolve(normalize_type_name(typename)))
    return str(text)
