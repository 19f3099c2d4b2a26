"""Child processes for tests that need more than one process."""

from __future__ import annotations

import os
import selectors
import subprocess
import time
from collections.abc import Callable

__all__ = ["Proc"]


class Proc:
    """A child process whose stdout lines are read with a timeout."""

    def __init__(self, args: list[str]) -> None:
        self.popen = subprocess.Popen(
            args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )

    def wait_line(
        self, predicate: Callable[[str], bool] | None = None, timeout: float = 15.0
    ) -> str:
        sel = selectors.DefaultSelector()
        assert self.popen.stdout is not None
        sel.register(self.popen.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if not sel.select(timeout=max(0.0, deadline - time.monotonic())):
                break
            line = self.popen.stdout.readline()
            if not line:
                break
            if predicate is None or predicate(line):
                return line.rstrip("\n")
        err = (
            self.popen.stderr.read() if self.popen.poll() is not None and self.popen.stderr else ""
        )
        raise AssertionError(f"no expected line within {timeout} s; stderr: {err}")

    def stop(self) -> str:
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
        return self.popen.stderr.read() if self.popen.stderr else ""
