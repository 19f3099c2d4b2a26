"""``python -m roverlab.cli teleop`` through a real pty: keys in, Twists out, terminal restored.

The teleop process joins the session's isolated daemon; a receiver in this process
subscribes to ``/cmd_vel`` over Zenoh, as a simulator in another process would.
"""

from __future__ import annotations

import contextlib
import os
import select
import signal
import subprocess
import sys
import termios
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import pytest

from roverlab.core import Context
from roverlab.core.transport.daemon import connect_context
from roverlab.msgs import Twist
from roverlab.teleop import CTRL_C, SmoothTeleop
from tests.teleop.twists import IQJJ_STOP_T, ZERO, Fields

pytestmark = pytest.mark.zenoh


class Receiver:
    """Collects the Twists that reach ``/cmd_vel`` from other processes."""

    def __init__(self, topic: str = "/cmd_vel") -> None:
        self.ctx = Context(clock="wall")
        self._lock = threading.Lock()
        self._msgs: list[Fields] = []
        node = self.ctx.create_node("teleop_test_receiver")
        node.create_subscription(Twist, topic, self._on_twist, 1000)
        connect_context(self.ctx)
        self.ctx.spin_in_thread()

    def _on_twist(self, msg: Any) -> None:
        assert msg.angular.x == 0.0 and msg.angular.y == 0.0
        with self._lock:
            self._msgs.append((msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.z))

    @property
    def msgs(self) -> list[Fields]:
        with self._lock:
            return list(self._msgs)

    def wait_for(self, predicate: Callable[[list[Fields]], bool], timeout: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate(self.msgs):
                return True
            time.sleep(0.02)
        return predicate(self.msgs)

    def close(self) -> None:
        self.ctx.shutdown()


class PtyTeleop:
    """``python -m roverlab.cli teleop ARGS`` with a pseudo-terminal as stdin and stdout."""

    def __init__(self, *args: str) -> None:
        self.master, self.slave = os.openpty()
        self.settings_before = termios.tcgetattr(self.slave)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "roverlab.cli", "teleop", *args],
            stdin=self.slave,
            stdout=self.slave,
            stderr=subprocess.PIPE,
            env=dict(os.environ),
            start_new_session=True,
        )
        self._output = bytearray()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()

    def _drain(self) -> None:  # keep the pty's output buffer empty, or the child blocks
        while not self._stop.is_set():
            ready, _, _ = select.select([self.master], [], [], 0.05)
            if not ready:
                continue
            try:
                data = os.read(self.master, 4096)
            except OSError:
                return
            if not data:
                return
            with self._lock:
                self._output += data

    @property
    def output(self) -> str:
        with self._lock:
            return self._output.decode("utf-8", "replace")

    def wait_output(self, needle: str, timeout: float = 20.0) -> None:
        deadline = time.monotonic() + timeout
        while needle not in self.output:
            if self.proc.poll() is not None or time.monotonic() > deadline:
                raise AssertionError(
                    f"{needle!r} never appeared; output {self.output!r}; stderr {self.stderr()}"
                )
            time.sleep(0.02)

    def type(self, keys: str) -> None:
        os.write(self.master, keys.encode())

    def wait_exit(self, timeout: float = 15.0) -> int:
        return self.proc.wait(timeout=timeout)

    def stderr(self) -> str:
        if self.proc.poll() is None or self.proc.stderr is None:
            return "(still running)"
        return self.proc.stderr.read().decode("utf-8", "replace")

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=5)
        self._stop.set()
        self._reader.join(timeout=2)
        for fd in (self.master, self.slave):
            with contextlib.suppress(OSError):
                os.close(fd)
        if self.proc.stderr is not None:
            self.proc.stderr.close()


@pytest.fixture
def receiver(daemon: str) -> Iterator[Receiver]:
    rx = Receiver()
    yield rx
    rx.close()


@pytest.fixture
def start_teleop(daemon: str) -> Iterator[Callable[..., PtyTeleop]]:
    procs: list[PtyTeleop] = []

    def start(*args: str) -> PtyTeleop:
        p = PtyTeleop(*args)
        procs.append(p)
        return p

    yield start
    for p in procs:
        p.close()


def _synchronise(teleop: PtyTeleop, rx: Receiver, key: str = "k") -> int:
    """Press a stop key until a Twist gets through (Zenoh has matched publisher and
    subscriber); return the number of messages received so far, all zero."""
    deadline = time.monotonic() + 20.0
    while not rx.msgs:
        assert teleop.proc.poll() is None, teleop.stderr()
        assert time.monotonic() < deadline, "no Twist ever reached the receiver"
        teleop.type(key)
        time.sleep(0.2)
    time.sleep(0.5)  # let the other presses arrive
    msgs = rx.msgs
    assert set(msgs) == {ZERO}
    return len(msgs)


def test_keyboard_keys_in_twists_out_terminal_restored(
    receiver: Receiver, start_teleop: Callable[..., PtyTeleop]
) -> None:
    teleop = start_teleop("_speed:=0.4", "_turn:=0.8")
    teleop.wait_output("CTRL-C to quit")
    start = _synchronise(teleop, receiver)

    teleop.type("iqJj t")  # typed faster than they are handled: none may be lost
    expected = IQJJ_STOP_T
    assert receiver.wait_for(lambda m: len(m) >= start + len(expected)), receiver.msgs
    assert receiver.msgs[start:] == expected

    teleop.type(CTRL_C)
    assert teleop.wait_exit() == 0, teleop.stderr()
    assert receiver.wait_for(lambda m: len(m) >= start + len(expected) + 1)
    time.sleep(0.3)
    assert receiver.msgs[start:] == [*expected, ZERO]  # the last message is a zero Twist
    assert termios.tcgetattr(teleop.slave) == teleop.settings_before

    out = teleop.output
    assert "Reading from the keyboard  and Publishing to Twist!\r\n" in out
    assert "currently:\tspeed 0.4\tturn 0.8 \r\n" in out
    assert "currently:\tspeed 0.44\tturn 0.88 \r\n" in out
    assert out.index("CTRL-C to quit") < out.index("speed 0.44")
    assert "iqJj" not in out  # raw mode: keys are not echoed


def test_smooth_ramps_force_stops_and_idles_to_zero(
    receiver: Receiver, start_teleop: Callable[..., PtyTeleop]
) -> None:
    teleop = start_teleop("--smooth", "_scale_linear:=0.1", "_scale_angular:=0.4")
    teleop.wait_output("Control mbot!")
    teleop.wait_output("currently:\tspeed 0.1\tturn 0.4 ")
    start = _synchronise(teleop, receiver)

    # one press: ramp up while the key counts, ramp down after five idle steps
    model = SmoothTeleop(speed=0.1, turn=0.4)
    ramp = []
    for key in ["i", *[""] * 20]:
        twist = model.handle_key(key).twist
        assert twist is not None
        if twist.is_zero:
            break
        ramp.append(twist.linear_x)
    assert max(ramp) == 0.1 and len(ramp) >= 9
    teleop.type("i")

    def ramp_done(msgs: list[Fields]) -> bool:
        lin = [m[0] for m in msgs[start:]]
        return any(lin) and lin[-1] == 0.0

    assert receiver.wait_for(ramp_done), receiver.msgs[start:]
    got = [m[0] for m in receiver.msgs[start:] if m[0] != 0.0]
    assert got == ramp  # exactly the script's arithmetic, 0.02 per 0.1 s step
    start = len(receiver.msgs)

    teleop.type("iii ")  # space stops at once, without ramping down
    assert receiver.wait_for(lambda m: any(x[0] for x in m[start:]) and m[-1] == ZERO)
    lin = [m[0] for m in receiver.msgs[start:]]
    first = next(i for i, v in enumerate(lin) if v)
    assert lin[first : first + 4] == pytest.approx([0.02, 0.04, 0.06, 0.0])

    teleop.type(CTRL_C)
    assert teleop.wait_exit() == 0, teleop.stderr()
    time.sleep(0.3)
    assert receiver.msgs[-1] == ZERO
    assert termios.tcgetattr(teleop.slave) == teleop.settings_before


def test_sigterm_publishes_zero_and_restores_terminal(
    receiver: Receiver, start_teleop: Callable[..., PtyTeleop]
) -> None:
    teleop = start_teleop("--speed", "0.25", "--turn", "0.6")
    teleop.wait_output("currently:\tspeed 0.25\tturn 0.6 ")
    start = _synchronise(teleop, receiver)
    teleop.type("u")
    assert receiver.wait_for(lambda m: (0.25, 0.0, 0.0, 0.6) in m[start:])
    assert termios.tcgetattr(teleop.slave) != teleop.settings_before  # raw now
    teleop.proc.send_signal(signal.SIGTERM)
    assert teleop.wait_exit() == 128 + signal.SIGTERM
    assert receiver.wait_for(lambda m: m[-1] == ZERO), receiver.msgs[start:]
    assert receiver.msgs[start:] == [(0.25, 0.0, 0.0, 0.6), ZERO]
    assert termios.tcgetattr(teleop.slave) == teleop.settings_before


def test_remap_reaches_the_other_topic(daemon: str, start_teleop: Callable[..., PtyTeleop]) -> None:
    rx = Receiver("/robot1/cmd_vel")
    try:
        teleop = start_teleop("cmd_vel:=/robot1/cmd_vel")
        teleop.wait_output("CTRL-C to quit")
        start = _synchronise(teleop, rx)
        teleop.type("," + CTRL_C)
        assert teleop.wait_exit() == 0, teleop.stderr()
        assert rx.wait_for(lambda m: len(m) >= start + 2)
        assert rx.msgs[start:] == [(-0.3, 0.0, 0.0, 0.0), ZERO]  # the seed's default speed
    finally:
        rx.close()


def _run(*args: str, stdin: Any = subprocess.DEVNULL) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "teleop", *args],
        stdin=stdin,
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ),
    )


def test_stdin_not_a_tty_is_one_line_and_exit_2(daemon: str) -> None:
    r = _run("--speed", "0.3")
    assert r.returncode == 2
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "stdin is not a terminal" in lines[0]


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["_speed:=abc"], "_speed:=abc: not a number"),
        (["--speed", "nan"], "--speed must be a finite number"),
        (["_foo:=1"], "unknown parameter '_foo'"),
        (["_turn:=.inf"], "_turn must be a finite number"),
    ],
)
def test_bad_values_are_one_line_and_exit_2(daemon: str, args: list[str], match: str) -> None:
    master, slave = os.openpty()
    try:
        r = _run(*args, stdin=slave)  # even on a terminal, before any key is read
    finally:
        os.close(master)
        os.close(slave)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and match in lines[0], r.stderr
