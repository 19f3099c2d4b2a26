"""Executor.run_now_or_soon: work from another thread runs in that thread only while the
executor is parked, never beside another callback, and in order."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

from roverlab.core import Context, QoSProfile
from roverlab.core.executor import ClockMode, Executor
from roverlab.msgs import String


def _wait(cond: Callable[[], bool], timeout_s: float = 2.0) -> bool:
    end = time.monotonic() + timeout_s
    while not cond() and time.monotonic() < end:
        time.sleep(0.002)
    return cond()


def _parked(ex: Executor) -> bool:
    return _wait(lambda: ex._sleeping and not ex._inbox and not ex._ready)


def test_idle_executor_runs_the_work_and_its_callbacks_in_the_calling_thread() -> None:
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("n")
    seen: list[tuple[str, int, bool]] = []

    def on_msg(m: object) -> None:
        seen.append((m.data, threading.get_ident(), ctx.executor.on_executor_thread()))  # type: ignore[attr-defined]

    sub = node.create_subscription(String, "/t", on_msg, 10)
    ctx.spin_in_thread()
    try:
        assert _parked(ctx.executor)
        inline = ctx.executor.run_now_or_soon(lambda: sub._enqueue(String(data="a")))
        assert inline
        # the delivery's callback ran here, before run_now_or_soon returned
        assert seen == [("a", threading.get_ident(), True)]
        assert not ctx.executor.on_executor_thread()  # the executor got its thread back
    finally:
        ctx.shutdown()


def test_a_busy_executor_gets_the_work_queued_and_nothing_overlaps() -> None:
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("n")
    running = threading.Lock()
    overlaps: list[str] = []
    order: list[str] = []
    release = threading.Event()
    started = threading.Event()

    def work(tag: str, block: bool = False) -> Callable[[], None]:
        def fn() -> None:
            if not running.acquire(blocking=False):
                overlaps.append(tag)
                return
            try:
                order.append(tag)
                if block:
                    started.set()
                    release.wait(2.0)
            finally:
                running.release()

        return fn

    ticks: list[int] = []
    node.create_timer(0.005, work("timer"))
    node.create_timer(0.005, lambda: ticks.append(1))
    ctx.spin_in_thread()
    try:
        assert _wait(lambda: len(ticks) >= 2)
        # a slow piece of work, run inline or on the executor, holds the executor
        holder = threading.Thread(
            target=lambda: ctx.executor.run_now_or_soon(work("first", block=True))
        )
        holder.start()
        assert started.wait(2.0)
        n_ticks = len(ticks)
        # while it runs, nothing else runs: no timer, and a second hand-in is queued
        assert not ctx.executor.run_now_or_soon(work("second"))
        time.sleep(0.05)
        assert len(ticks) == n_ticks
        assert "second" not in order
        release.set()
        holder.join(2.0)
        assert _wait(lambda: "second" in order and len(ticks) > n_ticks)
        assert order.index("second") > order.index("first")
        assert overlaps == []
    finally:
        release.set()
        ctx.shutdown()


def test_messages_from_one_thread_keep_their_order_inline_or_queued() -> None:
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("n")
    got: list[int] = []
    inline = [0]

    def on_msg(m: object) -> None:
        got.append(int(m.data))  # type: ignore[attr-defined]
        if len(got) % 7 == 0:
            time.sleep(0.002)  # sometimes busy: later messages queue behind it

    sub = node.create_subscription(String, "/t", on_msg, 1000)
    ctx.spin_in_thread()
    try:

        def feed() -> None:
            for i in range(300):
                data = String(data=str(i))
                inline[0] += ctx.executor.run_now_or_soon(lambda d=data: sub._enqueue(d))

        feeders = [threading.Thread(target=feed)]
        for t in feeders:
            t.start()
        for t in feeders:
            t.join(10)
        assert _wait(lambda: len(got) == 300)
        assert got == list(range(300))
        assert inline[0] > 0
    finally:
        ctx.shutdown()


def test_sim_mode_never_runs_work_outside_its_thread() -> None:
    ex = Executor(mode=ClockMode.SIM)
    ran: list[int] = []
    assert not ex.run_now_or_soon(lambda: ran.append(threading.get_ident()))
    assert ran == []
    ex.spin()
    assert ran == [threading.get_ident()]


def test_a_spin_until_a_condition_returns_when_inline_work_meets_it() -> None:
    ctx = Context(clock="wall", publish_clock=False)
    ctx.create_node("n")
    seen: list[int] = []
    done: list[float] = []

    def spin() -> None:
        ctx.spin_until_condition(lambda: bool(seen), timeout_sec=10.0)
        done.append(time.monotonic())

    thread = threading.Thread(target=spin)
    thread.start()
    try:
        assert _parked(ctx.executor)
        t0 = time.monotonic()
        assert ctx.executor.run_now_or_soon(lambda: seen.append(1))
        thread.join(5.0)
        assert done and done[0] - t0 < 2.0  # not the 10 s timeout
    finally:
        ctx.executor.stop()
        thread.join(5.0)
        ctx.shutdown()


def test_a_late_subscription_from_another_thread_gets_the_latched_message() -> None:
    ctx = Context(clock="wall", publish_clock=False)
    node = ctx.create_node("n")
    pub = node.create_publisher(
        String, "/latched", QoSProfile(depth=1, durability="transient_local")
    )
    ctx.spin_in_thread()
    try:
        assert _parked(ctx.executor)
        pub.publish(String(data="kept"))  # from this thread, while the executor is idle
        got: list[str] = []
        node.create_subscription(String, "/latched", lambda m: got.append(m.data), 1)
        assert _wait(lambda: got == ["kept"])  # the executor was woken for it (or ran here)
    finally:
        ctx.shutdown()
