"""An RPLIDAR on a serial port: requests, answers and the scan stream (blocking I/O).

No bus, no clock: :class:`RplidarDevice` is used from the node's reader thread. Every
failure is a :class:`~roverlab.drivers.errors.DeviceError` naming the port.
"""

from __future__ import annotations

import contextlib
import os
import struct
import time
from typing import Final

import serial

from roverlab.drivers.errors import DeviceError
from roverlab.drivers.rplidar.protocol import (
    CMD_GET_HEALTH,
    CMD_GET_INFO,
    CMD_GET_SAMPLERATE,
    CMD_SCAN,
    CMD_SET_MOTOR_PWM,
    CMD_STOP,
    DESCRIPTOR_LEN,
    SYNC,
    SYNC2,
    TYPE_HEALTH,
    TYPE_INFO,
    TYPE_SAMPLERATE,
    TYPE_SCAN,
    DeviceHealth,
    DeviceInfo,
    parse_descriptor,
    parse_health,
    parse_info,
    parse_samplerate,
    request,
)

__all__ = ["DEFAULT_MOTOR_PWM", "RplidarDevice"]

DEFAULT_MOTOR_PWM: Final = 600
"""The motor duty rplidar_ros sets on A-series devices."""
_ANSWER_TIMEOUT_S: Final = 1.0


class RplidarDevice:
    """One RPLIDAR on ``port``.

    Args:
        port: the serial device (``/dev/ttyUSB0``; a pty in tests).
        baudrate: 115200 for A1/A2, 256000 for A3.
    """

    def __init__(self, port: str, baudrate: int) -> None:
        self.port = port
        self.baudrate = baudrate
        self._serial: serial.Serial | None = None

    # ----------------------------------------------------------------- link
    def open(self) -> None:
        """Open the port.

        Raises:
            DeviceError: no such port, or it cannot be opened.
        """
        try:
            self._serial = serial.Serial(self.port, self.baudrate, timeout=0.05)
        except (serial.SerialException, OSError, ValueError) as err:
            code = getattr(err, "errno", None)
            reason = os.strerror(code) if isinstance(code, int) else str(err)
            raise DeviceError(f"{self.port}: cannot open the serial port: {reason}") from err

    def close(self) -> None:
        if self._serial is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._serial.close()
            self._serial = None

    @property
    def is_open(self) -> bool:
        return self._serial is not None

    def _port(self) -> serial.Serial:
        if self._serial is None:
            raise DeviceError(f"{self.port}: not open")
        return self._serial

    def send(self, cmd: int, payload: bytes = b"") -> None:
        try:
            self._port().write(request(cmd, payload))
        except (serial.SerialException, OSError) as err:
            raise DeviceError(f"{self.port}: write failed: {err}") from err

    def read(self, timeout_s: float) -> bytes:
        """What has arrived, waiting up to ``timeout_s`` for at least one byte.

        Raises:
            DeviceError: nothing arrived in ``timeout_s`` (the device stopped answering),
                or the port failed.
        """
        port = self._port()
        deadline = time.monotonic() + timeout_s
        try:
            while True:
                waiting = port.in_waiting
                data = port.read(max(1, waiting))
                if data:
                    return bytes(data)
                if time.monotonic() >= deadline:
                    raise DeviceError(
                        f"{self.port}: the device stopped answering (no data for {timeout_s:g} s)"
                    )
        except (serial.SerialException, OSError) as err:
            raise DeviceError(f"{self.port}: read failed: {err}") from err

    def _read_exact(self, n: int, deadline: float, what: str) -> bytes:
        port = self._port()
        out = bytearray()
        try:
            while len(out) < n:
                out += port.read(n - len(out))
                if len(out) < n and time.monotonic() > deadline:
                    raise DeviceError(f"{self.port}: no answer to {what}")
        except (serial.SerialException, OSError) as err:
            raise DeviceError(f"{self.port}: read failed: {err}") from err
        return bytes(out)

    def _answer(self, cmd: int, expected_type: int, what: str) -> tuple[int, int]:
        """Send ``cmd`` and wait for its descriptor (garbage before it is skipped)."""
        self.send(cmd)
        deadline = time.monotonic() + _ANSWER_TIMEOUT_S
        window = bytearray()
        while True:
            window += self._read_exact(1, deadline, what)
            if len(window) >= 2 and window[-2] == SYNC and window[-1] == SYNC2:
                rest = self._read_exact(DESCRIPTOR_LEN - 2, deadline, what)
                length, mode, dtype = parse_descriptor(bytes((SYNC, SYNC2)) + rest)
                if dtype != expected_type:
                    raise DeviceError(
                        f"{self.port}: {what} answered with data type 0x{dtype:02x}, "
                        f"expected 0x{expected_type:02x}"
                    )
                return length, mode
            if len(window) > 4096:
                raise DeviceError(f"{self.port}: no answer to {what} (only unreadable bytes)")

    def _single(self, cmd: int, expected_type: int, what: str) -> bytes:
        length, _ = self._answer(cmd, expected_type, what)
        return self._read_exact(length, time.monotonic() + _ANSWER_TIMEOUT_S, what)

    # ----------------------------------------------------------------- commands
    def stop(self) -> None:
        """STOP any scan and drop what is buffered (the SDK waits a moment for it)."""
        self.send(CMD_STOP)
        time.sleep(0.02)
        try:
            self._port().reset_input_buffer()
        except (serial.SerialException, OSError) as err:
            raise DeviceError(f"{self.port}: {err}") from err

    def get_info(self) -> DeviceInfo:
        return parse_info(self._single(CMD_GET_INFO, TYPE_INFO, "GET_INFO"))

    def get_health(self) -> DeviceHealth:
        return parse_health(self._single(CMD_GET_HEALTH, TYPE_HEALTH, "GET_HEALTH"))

    def get_samplerate(self) -> tuple[int, int]:
        return parse_samplerate(self._single(CMD_GET_SAMPLERATE, TYPE_SAMPLERATE, "GET_SAMPLERATE"))

    def set_motor(self, pwm: int) -> None:
        """Spin the motor: DTR low enables an A1's motor, SET_MOTOR_PWM drives an A2/A3's
        (a device without PWM control ignores it); 0 stops it."""
        port = self._port()
        with contextlib.suppress(serial.SerialException, OSError):  # a pty: no modem lines
            port.dtr = pwm == 0
        self.send(CMD_SET_MOTOR_PWM, struct.pack("<H", pwm))

    def start_scan(self) -> None:
        """Start a standard scan; the nodes then stream (see :meth:`read`)."""
        length, mode = self._answer(CMD_SCAN, TYPE_SCAN, "SCAN")
        if length != 5 or mode != 1:
            raise DeviceError(f"{self.port}: SCAN answered length {length} mode {mode}")
