"""Raw key input on a pseudo-terminal, and the settings always restored."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import termios
import time
from collections.abc import Iterator

import pytest

from roverlab.teleop import NotATerminalError, RawTerminal, Terminated
from roverlab.teleop.terminal import stdin_fd

LFLAG = 3


@pytest.fixture
def pty_pair() -> Iterator[tuple[int, int]]:
    master, slave = os.openpty()
    yield master, slave
    for fd in (master, slave):
        with contextlib.suppress(OSError):
            os.close(fd)


def test_raw_inside_restored_after(pty_pair: tuple[int, int]) -> None:
    _master, slave = pty_pair
    before = termios.tcgetattr(slave)
    assert before[LFLAG] & termios.ICANON and before[LFLAG] & termios.ECHO
    with RawTerminal(slave):
        attrs = termios.tcgetattr(slave)
        assert not attrs[LFLAG] & (termios.ICANON | termios.ECHO | termios.ISIG)
        assert not attrs[0] & termios.ICRNL
        assert attrs[1] & termios.OPOST  # print() still returns to the left margin
        assert attrs[6][termios.VMIN] == 1
    assert termios.tcgetattr(slave) == before


def test_read_key_one_at_a_time_and_timeout(pty_pair: tuple[int, int]) -> None:
    master, slave = pty_pair
    with RawTerminal(slave) as term:
        t0 = time.monotonic()
        assert term.read_key(0.05) == ""
        assert time.monotonic() - t0 >= 0.04
        os.write(master, "iq\x03\ré".encode())
        assert [term.read_key(1.0) for _ in range(5)] == ["i", "q", "\x03", "\r", "é"]
        assert term.read_key(0.0) == ""


def test_typeahead_before_raw_mode_is_kept(pty_pair: tuple[int, int]) -> None:
    master, slave = pty_pair
    os.write(master, b"ij")  # typed while the terminal was still in line mode
    with RawTerminal(slave) as term:
        assert term.read_key(1.0) == "i"
        assert term.read_key(1.0) == "j"


def test_restored_on_exception(pty_pair: tuple[int, int]) -> None:
    _master, slave = pty_pair
    before = termios.tcgetattr(slave)
    with pytest.raises(ZeroDivisionError), RawTerminal(slave):
        assert termios.tcgetattr(slave) != before
        _ = 1 / 0
    assert termios.tcgetattr(slave) == before


def test_sigterm_raises_terminated_and_restores(pty_pair: tuple[int, int]) -> None:
    master, slave = pty_pair
    before = termios.tcgetattr(slave)
    old_handler = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Terminated) as info, RawTerminal(slave) as term:
        os.kill(os.getpid(), signal.SIGTERM)
        term.read_key(5.0)  # interrupted by the signal
    assert info.value.signum == signal.SIGTERM and info.value.exit_code == 143
    assert termios.tcgetattr(slave) == before
    assert signal.getsignal(signal.SIGTERM) is old_handler
    del master


def test_second_signal_during_cleanup_is_ignored(pty_pair: tuple[int, int]) -> None:
    _master, slave = pty_pair
    before = termios.tcgetattr(slave)
    with RawTerminal(slave) as term:
        with pytest.raises(Terminated):
            os.kill(os.getpid(), signal.SIGTERM)
            term.read_key(5.0)
        os.kill(os.getpid(), signal.SIGTERM)  # the cleanup must not be interrupted
        assert term.read_key(0.05) == ""
    assert termios.tcgetattr(slave) == before


def test_closed_terminal_is_end_of_input(pty_pair: tuple[int, int]) -> None:
    master, slave = pty_pair
    with RawTerminal(slave) as term:
        os.close(master)
        with pytest.raises(EOFError):
            term.read_key(1.0)


def test_not_a_tty_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    r, w = os.pipe()
    try:
        with pytest.raises(NotATerminalError, match="not a terminal"):
            RawTerminal(r)
    finally:
        os.close(r)
        os.close(w)
    monkeypatch.setattr("sys.stdin", io.StringIO("i"))
    with pytest.raises(NotATerminalError, match="not a terminal"):
        stdin_fd()
    monkeypatch.setattr("sys.stdin", None)
    with pytest.raises(NotATerminalError):
        RawTerminal()
