"""``roverlab bag`` end to end: record + SIGTERM, kill -9 + recover, play --clock / --remap."""

from __future__ import annotations

import itertools
import signal
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from rosbags.highlevel import AnyReader

from tests.helpers.procs import Proc

RL = [sys.executable, "-m", "roverlab.cli"]


def _wait_stderr(p: Proc, text: str, timeout: float = 90.0) -> None:
    deadline = time.monotonic() + timeout
    while text not in p.stderr():
        if p.popen.poll() is not None or time.monotonic() > deadline:
            raise AssertionError(f"no {text!r} on stderr: {p.stderr()}")
        time.sleep(0.1)


@pytest.fixture
def talker(daemon: str) -> Iterator[Proc]:
    p = Proc([*RL, "topic", "pub", "/chatter", "std_msgs/String", "{data: hi}", "-r", "20"])
    yield p
    p.stop()


def _times(path: Path, topic: str) -> list[int]:
    with AnyReader([path]) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        out = []
        for c, t, raw in reader.messages(connections=conns):
            assert reader.deserialize(raw, c.msgtype).data == "hi"
            out.append(t)
        return out


def test_record_sigterm_info_and_play(
    tmp_path: Path, talker: Proc, cli: Callable[..., Any]
) -> None:
    rec = Proc([*RL, "bag", "record", "-a", "-o", str(tmp_path / "run.mcap"), "-x", "^/rosout"])
    try:
        _wait_stderr(rec, "subscribed to /chatter")
        time.sleep(2.0)
        rec.popen.send_signal(signal.SIGTERM)
        assert rec.popen.wait(timeout=20) == 0, rec.stderr()
    finally:
        rec.stop()
    out = tmp_path / "run.mcap"
    assert out.is_file() and not (tmp_path / "run.mcap.part").exists()
    assert "recorded" in rec.stderr()
    times = _times(out, "/chatter")
    assert len(times) >= 25  # 20 Hz for > 1.5 s
    info = cli("bag", "info", str(out))
    assert info.returncode == 0, info.stderr
    lines = info.stdout.splitlines()
    assert lines[0] == "Files:             run.mcap"
    assert lines[6] == f"Messages:          {len(times)}"  # only /chatter was published
    assert "Topic: /chatter | Type: std_msgs/msg/String" in info.stdout
    assert f"Count: {len(times)} | Serialization Format: cdr" in info.stdout

    # play it back under another name, with /clock: a subscriber gets both
    echo = Proc([*RL, "topic", "echo", "/talk", "std_msgs/String", "--once"])
    clock = Proc([*RL, "topic", "echo", "/clock", "rosgraph_msgs/Clock", "--once"])
    try:
        time.sleep(1.0)
        play = cli("bag", "play", str(out), "--remap", "/chatter:=/talk", "--clock", timeout=60)
        assert play.returncode == 0, play.stderr
        assert f"published {len(times)} messages" in play.stderr
        assert echo.wait_line(lambda s: s.startswith("data:"), timeout=10) == "data: hi"
        sec = int(clock.wait_line(lambda s: s.strip().startswith("sec:"), timeout=10).split()[1])
        assert abs(sec - times[0] / 1e9) < 5  # the bag's (wall) time, not 0
    finally:
        echo.stop()
        clock.stop()


def test_kill_9_then_recover(tmp_path: Path, talker: Proc, cli: Callable[..., Any]) -> None:
    rec = Proc(
        [*RL, "bag", "record", "/chatter", "-o", str(tmp_path / "k.mcap"), "--compression", "lz4"]
    )
    try:
        _wait_stderr(rec, "subscribed to /chatter")
        time.sleep(3.0)
        rec.popen.send_signal(signal.SIGKILL)
        kill_ns = time.time_ns()
        rec.popen.wait(timeout=10)
    finally:
        rec.stop()
    part = tmp_path / "k.mcap.part"
    assert part.is_file() and not (tmp_path / "k.mcap").exists()
    bad = cli("bag", "info", str(part))
    assert bad.returncode == 2 and "run `roverlab bag recover" in bad.stderr
    res = cli("bag", "recover", str(part))
    assert res.returncode == 0, res.stderr
    times = _times(tmp_path / "k.mcap", "/chatter")
    # all but about one second: the newest recovered message is < 1.5 s older than the kill
    assert len(times) >= 30 and kill_ns - times[-1] < 1.5e9
    # and nothing is missing before it (20 Hz, no gap > 0.3 s)
    assert max(b - a for a, b in itertools.pairwise(times)) < 0.3e9


def test_bad_arguments(tmp_path: Path, cli: Callable[..., Any]) -> None:
    r = cli("bag", "record")
    assert r.returncode == 2 and "give topics to record, or -a" in r.stderr
    r = cli("bag", "play", str(tmp_path / "none.mcap"))
    assert r.returncode == 2 and "none.mcap: no such file" in r.stderr
    r = cli("bag", "record", "-a", "-x", "(")
    assert r.returncode == 2 and "is not a regular expression" in r.stderr


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_sim_record_finishes_the_file_on_a_signal(
    tmp_path: Path, daemon: str, sig: signal.Signals
) -> None:
    out = tmp_path / "sim.mcap"
    p = Proc([*RL, "sim", "--no-expose", "--record", str(out), "--world", "empty"])
    try:
        _wait_stderr(p, "simulating", timeout=60)
        # the first scans come after the ray caster is compiled (seconds on a clean
        # checkout's empty numba cache): wait until flushed chunks hold some data
        part = tmp_path / "sim.mcap.part"
        deadline = time.monotonic() + 90
        while not (part.is_file() and part.stat().st_size > 50_000):
            assert time.monotonic() < deadline and p.popen.poll() is None, p.stderr()
            time.sleep(0.2)
        p.popen.send_signal(sig)
        assert p.popen.wait(timeout=30) == 0, p.stderr()
    finally:
        p.stop()
    assert out.is_file() and not (tmp_path / "sim.mcap.part").exists()
    with AnyReader([out]) as reader:
        topics = {c.topic: c.msgcount for c in reader.connections}
    assert topics["/scan"] > 0 and topics["/odom"] > 0 and topics["/tf_static"] == 1
