"""ROSArduinoBridge's serial protocol on a port (blocking I/O, used from a thread).

Every failure is a :class:`~roverlab.drivers.errors.DeviceError` naming the port: the
port cannot be opened, a command gets no answer within ``timeout_s``, or the answer is not
what the command returns (garbage on the line).
"""

from __future__ import annotations

import contextlib
import os
import time
from typing import Final

import serial

from roverlab.drivers.errors import DeviceError

__all__ = ["ArduinoLink"]

_MAX_LINE: Final = 256


class ArduinoLink:
    """A ROSArduinoBridge board on ``port``.

    Args:
        port: the serial device (``/dev/ttyUSB0``, ``/dev/ttyACM0``; a pty in tests).
        baudrate: the firmware's (57600).
        timeout_s: how long a command waits for its answer (ros_arduino_python: 0.5 s).
    """

    def __init__(self, port: str, baudrate: int, *, timeout_s: float = 0.5) -> None:
        self.port = port
        self.baudrate = baudrate
        self.timeout_s = timeout_s
        self._serial: serial.Serial | None = None
        self._pending = bytearray()

    def open(self, *, boot_wait_s: float = 2.0) -> None:
        """Open the port and wait (up to ``boot_wait_s``, an Arduino resets when its port
        opens) until the board answers ``b`` with its baud rate.

        Raises:
            DeviceError: no such port, no answer, or another baud rate.
        """
        try:
            self._serial = serial.Serial(self.port, self.baudrate, timeout=0.02)
        except (serial.SerialException, OSError, ValueError) as err:
            code = getattr(err, "errno", None)
            reason = os.strerror(code) if isinstance(code, int) else str(err)
            raise DeviceError(f"{self.port}: cannot open the serial port: {reason}") from err
        deadline = time.monotonic() + boot_wait_s
        while True:
            try:
                answer = self.execute("b")
                break
            except DeviceError:
                if time.monotonic() > deadline:
                    self.close()
                    raise
        if answer.strip() != str(self.baudrate):
            self.close()
            raise DeviceError(
                f"{self.port}: the board answered {answer!r} to the baud rate query "
                f"(expected {self.baudrate}): not a ROSArduinoBridge firmware at this speed?"
            )

    def close(self) -> None:
        if self._serial is not None:
            with contextlib.suppress(serial.SerialException, OSError):
                self._serial.close()
            self._serial = None
        self._pending.clear()

    @property
    def is_open(self) -> bool:
        return self._serial is not None

    def execute(self, command: str) -> str:
        """Send one command and return its answer line (without ``\\r\\n``).

        Raises:
            DeviceError: no answer within ``timeout_s``, or the port failed.
        """
        port = self._serial
        if port is None:
            raise DeviceError(f"{self.port}: not open")
        try:
            port.reset_input_buffer()
            self._pending.clear()
            port.write((command + "\r").encode("ascii"))
            deadline = time.monotonic() + self.timeout_s
            while True:
                chunk = port.read(max(1, port.in_waiting))
                self._pending += chunk
                cut = self._pending.find(b"\r")
                if cut >= 0:
                    line = bytes(self._pending[:cut])
                    del self._pending[: cut + 1]
                    text = line.decode("ascii", "replace").strip("\n\r ")
                    if text:
                        return text
                    continue
                if len(self._pending) > _MAX_LINE:
                    self._pending.clear()
                if time.monotonic() > deadline:
                    raise DeviceError(
                        f"{self.port}: no answer to '{command}' within {self.timeout_s:g} s"
                    )
        except (serial.SerialException, OSError) as err:
            raise DeviceError(f"{self.port}: {err}") from err

    def _ack(self, command: str) -> None:
        answer = self.execute(command)
        if answer != "OK":
            raise DeviceError(f"{self.port}: '{command}' answered {answer!r}, not OK")

    def get_encoder_counts(self) -> tuple[int, int]:
        """``e``: the cumulative left and right counts.

        Raises:
            DeviceError: no answer, or an answer that is not two integers.
        """
        answer = self.execute("e")
        parts = answer.split()
        if len(parts) != 2:
            raise DeviceError(f"{self.port}: unreadable encoder answer {answer!r}")
        try:
            return int(parts[0]), int(parts[1])
        except ValueError:
            raise DeviceError(f"{self.port}: unreadable encoder answer {answer!r}") from None

    def reset_encoders(self) -> None:
        self._ack("r")

    def drive(self, left: int, right: int) -> None:
        """``m LEFT RIGHT``: wheel speeds in ticks per PID frame."""
        self._ack(f"m {int(left)} {int(right)}")

    def update_pid(self, kp: int, kd: int, ki: int, ko: int) -> None:
        self._ack(f"u {kp}:{kd}:{ki}:{ko}")
