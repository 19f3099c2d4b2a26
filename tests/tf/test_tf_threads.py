"""Buffer: locking, waiting lookups with a timeout, futures."""

from __future__ import annotations

import threading
import time
from concurrent.futures import Future

import pytest

from roverlab.core.time import Duration, Time
from roverlab.geometry import Transform3
from roverlab.tf import (
    Buffer,
    ExtrapolationException,
    ForwardExtrapolationException,
    LookupException,
    TimeoutException,
)


def s(seconds: float) -> Time:
    return Time.from_seconds(seconds)


def later(delay_s: float, fn: object, *args: object) -> threading.Thread:
    def run() -> None:
        time.sleep(delay_s)
        fn(*args)  # type: ignore[operator]

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def test_lookup_waits_for_a_transform_set_by_another_thread() -> None:
    buf = Buffer()
    thread = later(0.05, buf.set_transform, "odom", "base_link", s(1.0), Transform3((1, 2, 3)))
    start = time.monotonic()
    t, stamp = buf.lookup_transform("odom", "base_link", Time(0), timeout=1.0)
    elapsed = time.monotonic() - start
    thread.join()
    assert t.translation == (1.0, 2.0, 3.0)
    assert stamp == s(1.0)
    assert 0.03 < elapsed < 0.9  # woken by set_transform, not by the timeout


def test_lookup_never_set_raises_the_lookup_error_after_the_timeout() -> None:
    buf = Buffer()
    buf.set_transform("odom", "base_link", s(1.0), Transform3())
    start = time.monotonic()
    with pytest.raises(LookupException, match="laser"):
        buf.lookup_transform("odom", "laser", Time(0), timeout=Duration.from_seconds(0.1))
    elapsed = time.monotonic() - start
    assert 0.09 <= elapsed < 0.6


def test_lookup_waits_for_newer_data_then_interpolates() -> None:
    buf = Buffer()
    buf.set_transform("odom", "base_link", s(1.0), Transform3((1, 0, 0)))
    thread = later(0.05, buf.set_transform, "odom", "base_link", s(3.0), Transform3((3, 0, 0)))
    t, _ = buf.lookup_transform("odom", "base_link", s(2.0), timeout=1.0)
    thread.join()
    assert t.translation[0] == pytest.approx(2.0)


def test_timeout_expiry_raises_extrapolation_when_data_stays_old() -> None:
    buf = Buffer()
    buf.set_transform("odom", "base_link", s(1.0), Transform3())
    buf.set_transform("odom", "base_link", s(2.0), Transform3())
    with pytest.raises(ForwardExtrapolationException):
        buf.lookup_transform("odom", "base_link", s(5.0), timeout=0.05)


def test_can_transform_with_timeout() -> None:
    buf = Buffer()
    assert not buf.can_transform("map", "odom", Time(0), timeout=0.05)
    thread = later(0.05, buf.set_transform, "map", "odom", s(1.0), Transform3())
    assert buf.can_transform("map", "odom", Time(0), timeout=1.0)
    thread.join()


def test_wait_for_transform_raises_timeout_exception() -> None:
    buf = Buffer()
    buf.set_transform("map", "odom", s(1.0), Transform3())
    with pytest.raises(TimeoutException) as info:
        buf.wait_for_transform("map", "base_link", Time(0), timeout=0.05)
    assert isinstance(info.value.__cause__, LookupException)
    buf.wait_for_transform("map", "odom", Time(0), timeout=0.05)  # available: returns


def test_future_resolves_when_data_arrives() -> None:
    buf = Buffer()
    fut: Future[tuple[Transform3, Time]] = buf.wait_for_transform_async("map", "odom", s(1.5))
    assert not fut.done()
    buf.set_transform("map", "odom", s(1.0), Transform3((1, 0, 0)))
    assert not fut.done()
    buf.set_transform("map", "odom", s(2.0), Transform3((2, 0, 0)))
    t, stamp = fut.result(timeout=0)
    assert t.translation[0] == pytest.approx(1.5) and stamp == s(1.5)
    # already available: resolved at once
    assert buf.wait_for_transform_async("odom", "map", s(1.0)).result(timeout=0)[0].translation[
        0
    ] == pytest.approx(-1.0)


def test_future_fails_when_the_time_falls_out_of_the_cache() -> None:
    buf = Buffer(cache_time=1.0)
    buf.set_transform("map", "odom", s(10.0), Transform3())
    buf.set_transform("map", "odom", s(10.2), Transform3())
    # already hopeless (5 s + cache time < latest data): fails at once, as tf2
    assert isinstance(
        buf.wait_for_transform_async("map", "odom", s(5.0)).exception(timeout=0),
        ExtrapolationException,
    )
    fut = buf.wait_for_transform_async("map", "odom", s(9.5))
    buf.set_transform("map", "odom", s(10.4), Transform3())
    assert not fut.done()  # 9.5 s + 1 s is not yet behind the latest data
    buf.set_transform("map", "odom", s(11.0), Transform3())
    assert isinstance(fut.exception(timeout=0), ExtrapolationException)


def test_cancelled_future_is_dropped() -> None:
    buf = Buffer()
    fut = buf.wait_for_transform_async("map", "odom", Time(0))
    assert fut.cancel()
    buf.set_transform("map", "odom", s(1.0), Transform3())
    assert fut.cancelled()


def test_concurrent_writers_and_readers() -> None:
    buf = Buffer(cache_time=100.0)
    errors: list[BaseException] = []

    def writer(child: str) -> None:
        for k in range(1, 301):
            buf.set_transform("odom", child, Time(k * 1000), Transform3((float(k), 0, 0)))

    def reader() -> None:
        try:
            for _ in range(300):
                if buf.can_transform("a", "b", Time(0)):
                    t, stamp = buf.lookup_transform("a", "b", Time(0))
                    assert t.translation[0] == pytest.approx(0.0)
                    assert stamp.nanoseconds % 1000 == 0
        except BaseException as err:
            errors.append(err)

    threads = [threading.Thread(target=writer, args=(c,)) for c in ("a", "b")]
    threads += [threading.Thread(target=reader) for _ in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert errors == []
    assert buf.get_latest_common_time("a", "b") == Time(300_000)
