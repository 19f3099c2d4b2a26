"""The RPLIDAR serial protocol (Slamtec's documented A-series protocol), pure bytes.

Requests are ``0xA5 CMD`` or ``0xA5 CMD SIZE PAYLOAD CHECKSUM`` (checksum: XOR of every
byte before it). Answers begin with a 7-byte descriptor ``0xA5 0x5A`` + 30-bit length
and 2-bit send mode (little endian) + a data type byte. A standard scan (``SCAN``, 0x20)
answers once and then streams 5-byte measurement nodes until ``STOP``:

=====  =============================================================
byte   bits
=====  =============================================================
0      quality (6 bits) << 2 | not-start-flag << 1 | start-flag
1      angle_q6 bits 0..6 << 1 | check bit (always 1)
2      angle_q6 bits 7..14          (angle in degrees = angle_q6 / 64, clockwise)
3, 4   distance_q2 (little endian)  (distance in mm = distance_q2 / 4; 0: no return)
=====  =============================================================

A start flag marks the first node of a new revolution. :class:`NodeDecoder` rebuilds
nodes from any chunking of the byte stream and re-synchronises after garbage: as the SDK,
a byte at which the check bits fail is dropped; unlike the SDK, a node is taken only when
the next node's check bits pass too (so a node is decoded once the next one's first two
bytes are in), which keeps a misaligned read from lasting after line noise.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from typing import Final

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.drivers.errors import DeviceError

__all__ = [
    "CMD_FORCE_SCAN",
    "CMD_GET_HEALTH",
    "CMD_GET_INFO",
    "CMD_GET_SAMPLERATE",
    "CMD_RESET",
    "CMD_SCAN",
    "CMD_SET_MOTOR_PWM",
    "CMD_STOP",
    "DESCRIPTOR_LEN",
    "NODE_DTYPE",
    "TYPE_HEALTH",
    "TYPE_INFO",
    "TYPE_SAMPLERATE",
    "TYPE_SCAN",
    "DeviceHealth",
    "DeviceInfo",
    "NodeDecoder",
    "encode_descriptor",
    "encode_nodes",
    "parse_descriptor",
    "parse_health",
    "parse_info",
    "parse_samplerate",
    "request",
]

SYNC: Final = 0xA5
SYNC2: Final = 0x5A
CMD_STOP: Final = 0x25
CMD_RESET: Final = 0x40
CMD_SCAN: Final = 0x20
CMD_FORCE_SCAN: Final = 0x21
CMD_GET_INFO: Final = 0x50
CMD_GET_HEALTH: Final = 0x52
CMD_GET_SAMPLERATE: Final = 0x59
CMD_SET_MOTOR_PWM: Final = 0xF0
TYPE_SCAN: Final = 0x81
TYPE_INFO: Final = 0x04
TYPE_HEALTH: Final = 0x06
TYPE_SAMPLERATE: Final = 0x15
DESCRIPTOR_LEN: Final = 7
NODE_LEN: Final = 5
SEND_SINGLE: Final = 0
SEND_MULTIPLE: Final = 1

NODE_DTYPE: Final = np.dtype(
    [("start", np.bool_), ("quality", np.uint8), ("angle_q6", np.uint16), ("dist_q2", np.uint16)]
)
"""A decoded measurement node: start flag, 6-bit quality, angle in 1/64 degree (clockwise),
distance in 1/4 mm (0: no return)."""

_HEALTH: Final = {0: "OK", 1: "Warning", 2: "Error"}


def request(cmd: int, payload: bytes = b"") -> bytes:
    """The bytes of one request (with size and checksum when there is a payload)."""
    if not payload:
        return bytes((SYNC, cmd))
    body = bytes((SYNC, cmd, len(payload))) + payload
    checksum = 0
    for b in body:
        checksum ^= b
    return body + bytes((checksum,))


def encode_descriptor(length: int, send_mode: int, data_type: int) -> bytes:
    """A response descriptor (the device side: for emulators and tests)."""
    return (
        bytes((SYNC, SYNC2)) + struct.pack("<I", length | (send_mode << 30)) + bytes((data_type,))
    )


def parse_descriptor(data: bytes) -> tuple[int, int, int]:
    """``(length, send_mode, data_type)`` of a 7-byte descriptor.

    Raises:
        DeviceError: the bytes are not a descriptor.
    """
    if len(data) != DESCRIPTOR_LEN or data[0] != SYNC or data[1] != SYNC2:
        raise DeviceError(f"bad response descriptor {data.hex(' ')}")
    word = struct.unpack("<I", data[2:6])[0]
    return word & 0x3FFFFFFF, word >> 30, data[6]


@dataclass(frozen=True)
class DeviceInfo:
    """GET_INFO's answer."""

    model: int
    firmware: tuple[int, int]
    hardware: int
    serial_number: str

    @property
    def model_name(self) -> str:
        """``A1M8``-style name (rplidar_ros's: major series from the model's high nibble)."""
        major, minor = self.model >> 4, self.model & 0xF
        if major <= 5:
            return f"A{major}M{minor}"
        if major <= 8:
            return f"S{major - 5}M{minor}"
        return f"T{major - 8}M{minor}"


def parse_info(data: bytes) -> DeviceInfo:
    """The 20-byte GET_INFO payload."""
    if len(data) != 20:
        raise DeviceError(f"GET_INFO answer has {len(data)} bytes, not 20")
    return DeviceInfo(data[0], (data[2], data[1]), data[3], data[4:20].hex().upper())


@dataclass(frozen=True)
class DeviceHealth:
    """GET_HEALTH's answer: status 0 OK, 1 Warning, 2 Error, and an error code."""

    status: int
    error_code: int

    @property
    def name(self) -> str:
        return _HEALTH.get(self.status, f"unknown ({self.status})")


def parse_health(data: bytes) -> DeviceHealth:
    """The 3-byte GET_HEALTH payload."""
    if len(data) != 3:
        raise DeviceError(f"GET_HEALTH answer has {len(data)} bytes, not 3")
    return DeviceHealth(data[0], struct.unpack("<H", data[1:3])[0])


def parse_samplerate(data: bytes) -> tuple[int, int]:
    """GET_SAMPLERATE: microseconds per sample in standard and express scans."""
    if len(data) != 4:
        raise DeviceError(f"GET_SAMPLERATE answer has {len(data)} bytes, not 4")
    std, express = struct.unpack("<HH", data)
    return int(std), int(express)


def encode_nodes(nodes: NDArray[np.void]) -> bytes:
    """Nodes (:data:`NODE_DTYPE`) as the device sends them (for emulators and tests)."""
    n = len(nodes)
    out = np.empty((n, NODE_LEN), np.uint8)
    start = nodes["start"].astype(np.uint8)
    out[:, 0] = (nodes["quality"].astype(np.uint8) << 2) | ((1 - start) << 1) | start
    angle = nodes["angle_q6"].astype(np.uint16)
    out[:, 1] = ((angle & 0x7F) << 1) | 1
    out[:, 2] = angle >> 7
    dist = nodes["dist_q2"].astype(np.uint16)
    out[:, 3] = dist & 0xFF
    out[:, 4] = dist >> 8
    return out.tobytes()


@numba.njit(cache=True, nogil=True)
def _decode(
    buf: NDArray[np.uint8], synced: bool
) -> tuple[NDArray[np.uint8], NDArray[np.uint16], int, int, bool]:
    """Scan ``buf`` for 5-byte nodes: rows of (start, quality, angle low/high, dist
    low/high) packed as start/quality bytes and angle/dist words; returns them with the
    bytes consumed, the bytes dropped and the sync state."""
    n = buf.size
    flags = np.empty((n // NODE_LEN + 1, 2), np.uint8)
    words = np.empty((n // NODE_LEN + 1, 2), np.uint16)
    k = 0
    i = 0
    dropped = 0
    while i + NODE_LEN + 2 <= n:
        b0 = buf[i]
        b1 = buf[i + 1]
        c0 = buf[i + NODE_LEN]
        c1 = buf[i + NODE_LEN + 1]
        if (
            ((b0 ^ (b0 >> 1)) & 1) != 1
            or (b1 & 1) != 1
            or ((c0 ^ (c0 >> 1)) & 1) != 1
            or (c1 & 1) != 1
        ):
            i += 1
            dropped += 1
            continue
        start = b0 & 1
        if start == 1:
            synced = True
        angle = (np.uint16(b1) >> 1) | (np.uint16(buf[i + 2]) << 7)
        if synced and angle < 360 * 64:
            flags[k, 0] = start
            flags[k, 1] = b0 >> 2
            words[k, 0] = angle
            words[k, 1] = np.uint16(buf[i + 3]) | (np.uint16(buf[i + 4]) << 8)
            k += 1
        i += NODE_LEN
    return flags[:k], words[:k], i, dropped, synced


class NodeDecoder:
    """Turns a standard-scan byte stream into nodes, whatever its chunking.

    Nodes before the first start flag are dropped (the SDK waits for one too); a byte at
    which the check bits of this node or the next fail is skipped, counted in
    :attr:`dropped_bytes`, and decoding resumes at the next byte; a node with an angle of
    360 degrees or more is dropped. The last node waits for two bytes of the next one.
    """

    def __init__(self) -> None:
        self._buf = bytearray()
        self.synced = False
        self.dropped_bytes = 0

    def feed(self, data: bytes) -> NDArray[np.void]:
        """Decode what ``data`` completes; returns the nodes in arrival order."""
        self._buf += data
        flags, words, used, dropped, self.synced = _decode(
            np.frombuffer(bytes(self._buf), np.uint8), self.synced
        )
        del self._buf[:used]
        self.dropped_bytes += dropped
        out = np.empty(len(flags), NODE_DTYPE)
        out["start"] = flags[:, 0].astype(bool)
        out["quality"] = flags[:, 1]
        out["angle_q6"] = words[:, 0]
        out["dist_q2"] = words[:, 1]
        return out
