"""Emulated serial devices on a pty: an RPLIDAR and a ros_arduino_bridge base.

The driver under test opens :attr:`PtyDevice.port` (the pty's slave side) with pyserial,
as it would ``/dev/ttyUSB0``; the emulator answers on the master side from a thread, at
the device's pace. ``silent`` makes it stop answering and sending (a device that hangs or
is unplugged); ``garbage_every`` makes it insert random bytes (a noisy line).
"""

from __future__ import annotations

import contextlib
import math
import os
import select
import struct
import threading
import time
import tty
from collections.abc import Callable

import numpy as np

from roverlab.drivers.rplidar.protocol import (
    CMD_GET_HEALTH,
    CMD_GET_INFO,
    CMD_GET_SAMPLERATE,
    CMD_SCAN,
    CMD_SET_MOTOR_PWM,
    CMD_STOP,
    NODE_DTYPE,
    TYPE_HEALTH,
    TYPE_INFO,
    TYPE_SAMPLERATE,
    TYPE_SCAN,
    encode_descriptor,
    encode_nodes,
)

__all__ = ["ArduinoBaseEmulator", "PtyDevice", "RplidarEmulator"]


class PtyDevice:
    """A pty whose master side a thread serves; subclasses implement :meth:`serve`."""

    def __init__(self, *, seed: int = 0) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        self.port = os.ttyname(self.slave)
        self.rng = np.random.default_rng(seed)
        self.silent = False
        self.garbage_every: int | None = None
        self.garbage_sent = 0
        self._writes = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    def start(self) -> PtyDevice:
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)

    def __enter__(self) -> PtyDevice:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def write(self, data: bytes) -> None:
        """Send ``data`` (dropped when the pty is full: nobody reads it)."""
        if self.silent:
            return
        self._writes += 1
        if self.garbage_every and self._writes % self.garbage_every == 0:
            junk = self.rng.integers(0, 256, int(self.rng.integers(1, 12)), dtype=np.uint8)
            data = junk.tobytes() + data
            self.garbage_sent += len(junk)
        with contextlib.suppress(BlockingIOError, OSError):
            os.write(self.master, data)

    def _loop(self) -> None:
        while not self._stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.002)
            data = b""
            if ready:
                with contextlib.suppress(BlockingIOError, OSError):
                    data = os.read(self.master, 4096)
            if self.silent:
                self.idle(time.monotonic())
                continue
            self.serve(data, time.monotonic())

    def serve(self, data: bytes, now: float) -> None:
        raise NotImplementedError

    def idle(self, now: float) -> None:
        """Time passes while the device is silent (what it would have sent is lost)."""


class RplidarEmulator(PtyDevice):
    """An RPLIDAR A1 in standard scan mode: ``samples_per_rev`` nodes per turn at
    ``scan_hz`` turns per second, sent every 10 ms as a real one streams them.

    Args:
        range_mm: distance in mm for device angles in degrees (clockwise, 0 = front of
            the device); 0 means no return.
    """

    def __init__(
        self,
        range_mm: Callable[[np.ndarray], np.ndarray],
        *,
        samples_per_rev: int = 200,
        scan_hz: float = 10.0,
        seed: int = 0,
    ) -> None:
        super().__init__(seed=seed)
        self.range_mm = range_mm
        self.n = samples_per_rev
        self.scan_hz = scan_hz
        self.us_per_sample = round(1e6 / (samples_per_rev * scan_hz))
        self.scanning = False
        self.motor_pwm: int | None = None
        self.commands: list[int] = []
        self._sent = 0  # nodes sent since the scan started
        self._t0 = 0.0
        self._cmd = bytearray()
        angles = np.arange(self.n) * 360.0 / self.n
        self.nodes = np.zeros(self.n, NODE_DTYPE)
        self.nodes["start"][0] = True
        self.nodes["quality"] = 47
        self.nodes["angle_q6"] = np.round(angles * 64).astype(np.uint16)
        self.nodes["dist_q2"] = np.round(np.asarray(range_mm(angles)) * 4).astype(np.uint16)

    def serve(self, data: bytes, now: float) -> None:
        self._cmd += data
        while len(self._cmd) >= 2:
            if self._cmd[0] != 0xA5:
                del self._cmd[0]
                continue
            cmd = self._cmd[1]
            if cmd & 0x80 or cmd == CMD_SET_MOTOR_PWM:  # with payload: size, payload, sum
                if len(self._cmd) < 3 or len(self._cmd) < 4 + self._cmd[2]:
                    break
                payload = bytes(self._cmd[3 : 3 + self._cmd[2]])
                del self._cmd[: 4 + self._cmd[2]]
            else:
                payload = b""
                del self._cmd[:2]
            self._command(cmd, payload, now)
        if self.scanning:
            due = int((now - self._t0) * self.n * self.scan_hz)
            if due > self._sent:
                idx = np.arange(self._sent, due) % self.n
                self.write(encode_nodes(self.nodes[idx]))
                self._sent = due

    def idle(self, now: float) -> None:
        if self.scanning:
            self._sent = int((now - self._t0) * self.n * self.scan_hz)

    def _command(self, cmd: int, payload: bytes, now: float) -> None:
        self.commands.append(cmd)
        if cmd == CMD_STOP:
            self.scanning = False
        elif cmd == CMD_GET_INFO:
            serial = bytes(range(16))
            self.write(encode_descriptor(20, 0, TYPE_INFO) + bytes((0x18, 29, 1, 7)) + serial)
        elif cmd == CMD_GET_HEALTH:
            self.write(encode_descriptor(3, 0, TYPE_HEALTH) + bytes((0, 0, 0)))
        elif cmd == CMD_GET_SAMPLERATE:
            body = struct.pack("<HH", self.us_per_sample, self.us_per_sample // 2)
            self.write(encode_descriptor(4, 0, TYPE_SAMPLERATE) + body)
        elif cmd == CMD_SET_MOTOR_PWM:
            self.motor_pwm = struct.unpack("<H", payload)[0]
        elif cmd == CMD_SCAN:
            self.write(encode_descriptor(5, 1, TYPE_SCAN))
            self.scanning = True
            self._t0 = now
            self._sent = 0


class ArduinoBaseEmulator(PtyDevice):
    """ROSArduinoBridge firmware on a differential base: ``m L R`` sets the wheel speeds in
    ticks per 1/30 s PID frame, ``e`` answers the cumulative encoder counts, ``r`` resets
    them, ``u``, ``b`` and ``o`` as the firmware; counts advance at the commanded speeds
    (the firmware's PID on ideal motors) and stop after the auto-stop interval (2 s)."""

    AUTO_STOP_S = 2.0

    def __init__(self, *, seed: int = 0) -> None:
        super().__init__(seed=seed)
        self.left = 0.0
        self.right = 0.0
        self.speed = (0, 0)
        self.commands: list[str] = []
        self._line = bytearray()
        self._last = time.monotonic()
        self._last_motor = 0.0

    def serve(self, data: bytes, now: float) -> None:
        dt = now - self._last
        self._last = now
        if now - self._last_motor > self.AUTO_STOP_S:
            self.speed = (0, 0)
        self.left += self.speed[0] * 30.0 * dt
        self.right += self.speed[1] * 30.0 * dt
        self._line += data
        while b"\r" in self._line:
            raw, _, rest = bytes(self._line).partition(b"\r")
            self._line = bytearray(rest)
            self._command(raw.decode("ascii", "replace").strip(), now)

    def _command(self, line: str, now: float) -> None:
        if not line:
            return
        self.commands.append(line)
        parts = line.split()
        cmd, args = parts[0], parts[1:]
        if cmd == "e":
            self.write(f"{math.floor(self.left)} {math.floor(self.right)}\r\n".encode())
        elif cmd == "r":
            self.left = self.right = 0.0
            self.write(b"OK\r\n")
        elif cmd == "m" and len(args) == 2:
            self.speed = (int(args[0]), int(args[1]))
            self._last_motor = now
            self.write(b"OK\r\n")
        elif cmd == "u" or cmd == "o":
            self.write(b"OK\r\n")
        elif cmd == "b":
            self.write(b"57600\r\n")
        else:
            self.write(b"Invalid Command\r\n")
