"""The TCPROS connection header: ``key=value`` fields, each length-prefixed.

A header on the wire is a 4-byte little-endian total length, then fields, each a 4-byte
little-endian length and ``key=value`` bytes (the value may itself contain ``=``; the first
one splits). Unknown fields are kept and ignored by callers; an empty header is valid.
"""

from __future__ import annotations

import struct

from roverlab.core.transport.ros1.errors import HeaderError

__all__ = ["MAX_HEADER_BYTES", "decode_header", "encode_header"]

MAX_HEADER_BYTES = 1 << 20  # a full message_definition is tens of kB; rospy has no cap
_U32 = struct.Struct("<I")


def encode_header(fields: dict[str, str]) -> bytes:
    """The header's bytes, with the 4-byte total length in front."""
    parts = []
    for key, value in fields.items():
        if "=" in key:
            raise HeaderError(f"header field name {key!r} contains '='")
        raw = f"{key}={value}".encode()
        parts.append(_U32.pack(len(raw)))
        parts.append(raw)
    body = b"".join(parts)
    return _U32.pack(len(body)) + body


def decode_header(body: bytes | bytearray | memoryview) -> dict[str, str]:
    """The fields of a header body (the bytes after the total length).

    Raises:
        HeaderError: a field length past the end, a field without ``=``, bad UTF-8.
    """
    data = bytes(body)
    fields: dict[str, str] = {}
    pos = 0
    end = len(data)
    while pos < end:
        if end - pos < 4:
            raise HeaderError(f"connection header cut short: {end - pos} stray byte(s)")
        (size,) = _U32.unpack_from(data, pos)
        pos += 4
        if size > end - pos:
            raise HeaderError(
                f"connection header field of {size} bytes overruns the header ({end - pos} left)"
            )
        raw = data[pos : pos + size]
        pos += size
        key, sep, value = raw.partition(b"=")
        if not sep:
            raise HeaderError(f"connection header field {raw[:40]!r} has no '='")
        try:
            fields[key.decode()] = value.decode()
        except UnicodeDecodeError as err:
            raise HeaderError(f"connection header field is not UTF-8: {err}") from None
    return fields
