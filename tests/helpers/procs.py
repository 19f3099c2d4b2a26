"""Child processes for tests that need more than one process."""

from __future__ import annotations

import os
import queue
import subprocess
import threading
import time
from collections.abc import Callable

__all__ = ["Proc", "twist_pub_args"]


def twist_pub_args(linear_x: float, angular_z: float) -> list[str]:
    """``roverlab`` arguments that publish a ``geometry_msgs/Twist`` on /cmd_vel at 10 Hz."""
    twist = f"{{linear: {{x: {linear_x}}}, angular: {{z: {angular_z}}}}}"
    return ["topic", "pub", "-r", "10", "/cmd_vel", "geometry_msgs/Twist", twist]


class Proc:
    """A child process whose stdout lines are read with a timeout.

    A thread reads stdout line by line into a queue (a selector on the pipe misses lines
    that a buffered read already took in when several arrive at once).
    """

    def __init__(self, args: list[str]) -> None:
        self.popen = subprocess.Popen(
            args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._err: list[str] = []
        self._err_reader = threading.Thread(target=self._read_err, daemon=True)
        self._err_reader.start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self._lines.put(line)
        self._lines.put(None)  # end of output

    def _read_err(self) -> None:
        assert self.popen.stderr is not None
        for line in self.popen.stderr:
            self._err.append(line)

    def stderr(self, timeout: float = 5.0) -> str:
        """All of stderr so far (up to its end if the process has ended)."""
        if self.popen.poll() is not None:
            self._err_reader.join(timeout)
        return "".join(self._err)

    def wait_line(
        self, predicate: Callable[[str], bool] | None = None, timeout: float = 15.0
    ) -> str:
        """The next stdout line (without its newline) for which ``predicate`` holds;
        lines before it are consumed."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self._lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            if line is None:
                self._lines.put(None)
                break
            if predicate is None or predicate(line):
                return line.rstrip("\n")
        err = self.stderr()
        raise AssertionError(f"no expected line within {timeout} s; stderr: {err}")

    def rest(self, timeout: float = 10.0) -> str:
        """The stdout not consumed yet, up to the end of the process's output."""
        self._reader.join(timeout)
        out: list[str] = []
        while True:
            try:
                line = self._lines.get_nowait()
            except queue.Empty:
                break
            if line is None:
                self._lines.put(None)
                break
            out.append(line)
        return "".join(out)

    def communicate(self, timeout: float) -> tuple[str, str]:
        """Wait for the process to end; the stdout not consumed yet and all of stderr
        (``Popen.communicate`` would race the reader thread for stdout)."""
        self.popen.wait(timeout=timeout)
        err = self.stderr()
        return self.rest(), err

    def stop(self) -> str:
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
        return self.stderr()
