"""Single key presses from a terminal, with the terminal always put back as it was.

:class:`RawTerminal` is a context manager over a TTY file descriptor (stdin by default).
Inside it, input is raw: no line buffering, no echo, Ctrl-C arrives as the key ``'\\x03'``
instead of a signal, Enter as ``'\\r'``; :meth:`RawTerminal.read_key` returns one key,
waiting at most a timeout as teleop's ``getKey()`` does with ``select``. On leaving -- at
the end, on any exception, or on SIGTERM / SIGHUP, which are turned into
:class:`Terminated` so that ``finally`` blocks (the zero Twist) still run -- the saved
settings are restored.

Two deliberate differences from the scripts' ``getKey()``, which call ``tty.setraw`` before
and restore the settings after each key:

* raw mode lasts for the whole ``with`` block, and is entered without flushing input, so
  keys typed while the last Twist was being published are not thrown away (``setraw``
  flushes them);
* output post-processing stays on, so ``print`` still starts new lines at the left margin
  while the terminal is raw.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import os
import select
import signal
import sys
import termios
import threading
from types import FrameType, TracebackType
from typing import Any, Final

from roverlab.teleop.errors import NotATerminalError

__all__ = ["RawTerminal", "Terminated", "raw_mode_attributes", "stdin_fd"]

_HANDLED_SIGNALS: Final = (signal.SIGTERM, signal.SIGHUP)
_NOT_A_TTY: Final = (
    "stdin is not a terminal: teleop reads single key presses from a TTY "
    "(run it in a terminal, not with input from a pipe or file)"
)


class Terminated(Exception):  # noqa: N818 (a signal, not a failure)
    """SIGTERM or SIGHUP arrived while keys were being read."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"terminated by signal {signal.Signals(signum).name}")
        self.signum = signum

    @property
    def exit_code(self) -> int:
        """The shell's convention for death by a signal: 128 + its number."""
        return 128 + self.signum


def stdin_fd() -> int:
    """The file descriptor of stdin if it is a TTY; else raise :class:`NotATerminalError`."""
    stream = sys.stdin
    try:
        fd = stream.fileno() if stream is not None else -1
    except (AttributeError, OSError, ValueError):
        fd = -1
    if fd < 0 or not os.isatty(fd):
        raise NotATerminalError(_NOT_A_TTY)
    return fd


def raw_mode_attributes(attrs: list[Any]) -> list[Any]:
    """Raw input settings derived from ``termios.tcgetattr`` output; output processing kept.

    As ``cfmakeraw`` for the input, local and control flags: no break/CR/parity/strip/flow
    processing, 8-bit characters, no echo, no canonical lines, no signal keys, and reads
    that return after one byte.
    """
    iflag, oflag, cflag, lflag, ispeed, ospeed, cc = attrs
    iflag &= ~(
        termios.BRKINT
        | termios.ICRNL
        | termios.INPCK
        | termios.ISTRIP
        | termios.IXON
        | termios.INLCR
        | termios.IGNCR
        | termios.PARMRK
    )
    cflag = (cflag & ~(termios.CSIZE | termios.PARENB)) | termios.CS8
    lflag &= ~(termios.ECHO | termios.ECHONL | termios.ICANON | termios.IEXTEN | termios.ISIG)
    cc = list(cc)
    cc[termios.VMIN] = 1
    cc[termios.VTIME] = 0
    return [iflag, oflag, cflag, lflag, ispeed, ospeed, cc]


class RawTerminal:
    """Raw key input on a TTY for the duration of a ``with`` block.

    Args:
        fd: the terminal's file descriptor; stdin when omitted.
        handle_signals: turn SIGTERM and SIGHUP into :class:`Terminated` inside the block
            (only possible in the main thread; elsewhere they are left alone).

    Raises:
        NotATerminalError: ``fd`` (or stdin) is not a TTY.
    """

    def __init__(self, fd: int | None = None, *, handle_signals: bool = True) -> None:
        if fd is None:
            fd = stdin_fd()
        elif not os.isatty(fd):
            raise NotATerminalError(_NOT_A_TTY)
        self.fd = fd
        self._handle_signals = handle_signals
        self._saved: list[Any] | None = None
        self._old_handlers: dict[int, Any] = {}
        self._signalled: int | None = None
        self._decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")

    # ----------------------------------------------------------------- context manager
    def __enter__(self) -> RawTerminal:
        self._saved = termios.tcgetattr(self.fd)
        if self._handle_signals and threading.current_thread() is threading.main_thread():
            for sig in _HANDLED_SIGNALS:
                self._old_handlers[sig] = signal.signal(sig, self._on_signal)
        try:
            termios.tcsetattr(self.fd, termios.TCSADRAIN, raw_mode_attributes(self._saved))
        except BaseException:
            self.restore()
            raise
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.restore()

    def restore(self) -> None:
        """Put the saved settings and signal handlers back (safe to call twice)."""
        saved, self._saved = self._saved, None
        if saved is not None:
            # The terminal may be gone (SIGHUP): then there is nothing left to restore.
            with contextlib.suppress(termios.error, OSError):
                termios.tcsetattr(self.fd, termios.TCSADRAIN, saved)
        handlers, self._old_handlers = self._old_handlers, {}
        for sig, handler in handlers.items():
            signal.signal(sig, handler)

    def _on_signal(self, signum: int, frame: FrameType | None) -> None:
        if self._signalled is not None:  # already shutting down: let the cleanup finish
            return
        self._signalled = signum
        raise Terminated(signum)

    # ----------------------------------------------------------------- input
    def read_key(self, timeout_s: float | None = None) -> str:
        """One key (one character); ``''`` if none came within ``timeout_s`` seconds.

        ``None`` waits for ever. Multi-byte UTF-8 characters are returned whole.

        Raises:
            EOFError: the terminal was closed (end of input or hang-up).
        """
        while True:
            ready, _, _ = select.select([self.fd], [], [], timeout_s)
            if not ready:
                return ""
            try:
                data = os.read(self.fd, 1)
            except OSError as err:
                if err.errno == errno.EIO:  # the other side of a pty has gone away
                    raise EOFError("terminal closed") from err
                raise
            if not data:
                raise EOFError("end of input")
            key = self._decoder.decode(data)
            if key:
                return key
