"""Executor ordering, determinism, QoS dropping, clock modes and fault isolation."""

from __future__ import annotations

import logging
import threading
import time

import numpy as np
import pytest

from roverlab.core import Context, QoSProfile, Time
from roverlab.msgs import Clock, Float64, String


def test_same_time_events_run_in_sequence_order() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    trace: list[str] = []
    pub = node.create_publisher(String, "/t", 10)

    def timer_a() -> None:
        trace.append(f"a@{ctx.now().nanoseconds}")
        pub.publish(String(data="from-a"))

    node.create_timer(1.0, timer_a)
    node.create_timer(1.0, lambda: trace.append(f"b@{ctx.now().nanoseconds}"))
    node.create_subscription(String, "/t", lambda m: trace.append(f"msg:{m.data}"), 10)
    ctx.spin_for(2.0)
    # a and b were both queued for t=1 s before a published: the message comes after b.
    assert trace == [
        "a@1000000000",
        "b@1000000000",
        "msg:from-a",
        "a@2000000000",
        "b@2000000000",
        "msg:from-a",
    ]
    assert ctx.now() == Time(2_000_000_000)


def test_timers_interleave_by_time_without_drift() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    times: dict[str, list[int]] = {"fast": [], "slow": []}
    node.create_timer(0.1, lambda: times["fast"].append(ctx.now().nanoseconds))
    node.create_timer(0.3, lambda: times["slow"].append(ctx.now().nanoseconds))
    ctx.spin_for(1.0)
    assert times["fast"] == [i * 100_000_000 for i in range(1, 11)]
    assert times["slow"] == [300_000_000, 600_000_000, 900_000_000]


def _seeded_run(seed: int) -> list[tuple[int, float]]:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("noise")
    rng = np.random.default_rng(seed)
    pub = node.create_publisher(Float64, "/x", 10)
    out: list[tuple[int, float]] = []
    node.create_subscription(
        Float64, "/x", lambda m: out.append((ctx.now().nanoseconds, m.data)), 10
    )
    node.create_timer(0.013, lambda: pub.publish(Float64(data=float(rng.normal()))))
    node.create_timer(0.007, lambda: pub.publish(Float64(data=float(rng.uniform()))))
    ctx.spin_for(3.0)
    return out


def test_seeded_runs_are_identical_and_seeds_differ() -> None:
    a, b, c = _seeded_run(7), _seeded_run(7), _seeded_run(8)
    assert len(a) > 600
    assert a == b
    assert a != c


def test_qos_depth_drops_oldest_and_counts() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("burst")
    pub = node.create_publisher(String, "/burst", 100)
    got_small: list[str] = []
    got_big: list[str] = []
    small = node.create_subscription(String, "/burst", lambda m: got_small.append(m.data), 5)
    big = node.create_subscription(String, "/burst", lambda m: got_big.append(m.data), 100)

    def burst() -> None:
        for i in range(25):
            pub.publish(String(data=str(i)))

    node.create_timer(1.0, burst)
    ctx.spin_for(1.0)
    assert got_small == [str(i) for i in range(20, 25)]
    assert small.dropped == 20
    assert got_big == [str(i) for i in range(25)]
    assert big.dropped == 0


def test_latched_publisher_reaches_late_subscriber() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("map_server")
    pub = node.create_publisher(String, "/map", QoSProfile(depth=1, durability="transient_local"))
    pub.publish(String(data="old"))
    pub.publish(String(data="map"))
    got: list[str] = []
    ctx.create_node("late").create_subscription(String, "/map", lambda m: got.append(m.data), 10)
    ctx.spin_for(0.1)
    assert got == ["map"]


def test_callback_exception_is_logged_and_others_keep_running(
    caplog: pytest.LogCaptureFixture,
) -> None:
    ctx = Context(publish_clock=False)
    bad = ctx.create_node("bad_node")
    good = ctx.create_node("good_node")
    pub = good.create_publisher(String, "/t", 10)
    got: list[str] = []

    def explode(_m: object) -> None:
        raise RuntimeError("boom")

    bad.create_subscription(String, "/t", explode, 10)
    good.create_subscription(String, "/t", lambda m: got.append(m.data), 10)
    good.create_timer(0.5, lambda: pub.publish(String(data="x")))
    logger = logging.getLogger("roverlab")
    logger.propagate = True
    with caplog.at_level(logging.ERROR, logger="roverlab"):
        ctx.spin_for(2.0)
    assert got == ["x"] * 4
    assert ctx.executor.callback_errors == 4
    errors = [r for r in caplog.records if r.levelno == logging.ERROR]
    assert errors and "bad_node" in errors[0].name
    assert "RuntimeError: boom" in errors[0].getMessage()
    assert "/t" in errors[0].getMessage()


def test_sim_clock_is_published_on_clock_topic() -> None:
    ctx = Context(clock_period_s=0.01)
    stamps: list[int] = []
    ctx.create_node("c").create_subscription(
        Clock, "/clock", lambda m: stamps.append(m.clock.sec * 10**9 + m.clock.nanosec), 10
    )
    ctx.spin_for(1.0)
    assert len(stamps) == 100
    assert stamps[0] == 10_000_000 and stamps[-1] == 1_000_000_000


def test_sim_mode_runs_faster_than_real_time() -> None:
    ctx = Context()
    n = [0]
    ctx.create_node("t").create_timer(0.001, lambda: n.__setitem__(0, n[0] + 1))
    start = time.perf_counter()
    ctx.spin_for(60.0)
    wall = time.perf_counter() - start
    assert n[0] == 60_000
    assert wall < 30.0  # 60 s of sim time must not take real time


def test_paced_mode_follows_wall_clock_times_rate() -> None:
    ctx = Context(clock="paced", rate=4.0, publish_clock=False)
    ticks: list[float] = []
    ctx.create_node("t").create_timer(0.1, lambda: ticks.append(time.perf_counter()))
    start = time.perf_counter()
    ctx.spin_for(2.0)  # 2 sim seconds at 4x: 0.5 s of wall time
    wall = time.perf_counter() - start
    assert len(ticks) == 20
    assert 0.45 <= wall <= 0.9
    # ticks are spread over the run, not bunched: the 10th is near the middle
    assert 0.15 <= ticks[9] - start <= 0.45


def test_an_overloaded_paced_clock_waits_for_the_executor() -> None:
    """Callbacks needing twice the CPU the pace allows: the clock other threads read (and
    their wait_for deadlines) follows the time the executor has lived through, instead of
    running ahead of it by a growing margin."""
    ctx = Context(clock="paced", rate=2.0, publish_clock=False)
    ticks: list[int] = []

    def busy() -> None:
        ticks.append(ctx.executor.now_ns)
        time.sleep(0.1)  # 0.1 s of sim time paced at 2x is 0.05 s of wall time

    ctx.create_node("t").create_timer(0.1, busy)
    ctx.spin_in_thread()
    try:
        start = ctx.now().nanoseconds
        assert not ctx.wait_for(lambda: False, 1.0)
        done = [t for t in ticks if start < t <= start + 1_000_000_000]
        # a clock running at the pace would end the wait after ~5 of the 10 periods
        assert len(done) >= 8, (len(done), len(ticks))
        lag = ctx.executor.clock_now_ns() - ctx.executor.now_ns
        assert lag <= 300_000_000, lag  # 0.05 s of wall time at 2x, plus one period
    finally:
        ctx.shutdown()


def test_publish_from_another_thread_is_queued_into_the_executor() -> None:
    ctx = Context(clock="wall")
    node = ctx.create_node("n")
    pub = node.create_publisher(String, "/t", 10)
    got: list[tuple[str, bool]] = []
    executor_thread: list[int] = []

    def on_msg(m: object) -> None:
        got.append((m.data, threading.get_ident() == executor_thread[0]))  # type: ignore[attr-defined]

    node.create_subscription(String, "/t", on_msg, 10)
    thread = ctx.spin_in_thread()
    executor_thread.append(thread.ident or 0)
    for i in range(5):
        pub.publish(String(data=str(i)))
    deadline = time.monotonic() + 2
    while len(got) < 5 and time.monotonic() < deadline:
        time.sleep(0.01)
    ctx.shutdown()
    assert got == [(str(i), True) for i in range(5)]
    assert not thread.is_alive()


def test_external_clock_follows_clock_messages_and_fires_timers() -> None:
    ctx = Context(clock="external")
    fired: list[int] = []
    node = ctx.create_node("follower")
    node.create_timer(0.5, lambda: fired.append(ctx.now().nanoseconds))
    feeder = ctx.create_node("feeder")
    pub = feeder.create_publisher(Clock, "/clock", 10)
    for k in range(1, 11):
        pub.publish(Clock(clock=Time(k * 200_000_000).to_msg()))
        ctx.executor.spin(wall_timeout_s=0.01)
    assert ctx.now() == Time(2_000_000_000)
    # the timer starts at the first /clock (0.2 s), as rospy's do; due at 0.7 s, it fires
    # when /clock passes it (at 0.8 s); no drift afterwards
    assert fired == [800_000_000, 1_200_000_000, 1_800_000_000]


def test_external_clock_timers_start_at_the_first_clock_message() -> None:
    """A node that follows a simulator running for a minute already: its timers start at
    the first /clock, not at 0 (they would all fire at once, a minute late)."""
    ctx = Context(clock="external")
    fired: list[int] = []
    node = ctx.create_node("follower")
    node.create_timer(15.0, lambda: fired.append(ctx.now().nanoseconds))
    cancelled = node.create_timer(1.0, lambda: fired.append(-1))
    cancelled.cancel()
    pub = ctx.create_node("feeder").create_publisher(Clock, "/clock", 10)
    for t_s in (60.0, 70.0, 75.0, 80.0):
        pub.publish(Clock(clock=Time.from_seconds(t_s).to_msg()))
        ctx.executor.spin(wall_timeout_s=0.01)
    assert fired == [75_000_000_000]


def test_timer_skips_periods_the_clock_jumped_over() -> None:
    ctx = Context(clock="external")
    fired: list[int] = []
    ctx.create_node("n").create_timer(0.1, lambda: fired.append(ctx.now().nanoseconds))
    pub = ctx.create_node("feeder").create_publisher(Clock, "/clock", 10)
    pub.publish(Clock(clock=Time(0).to_msg()))  # the clock starts (and the timer with it)
    ctx.executor.spin(wall_timeout_s=0.01)
    pub.publish(Clock(clock=Time(5_050_000_000).to_msg()))
    ctx.executor.spin(wall_timeout_s=0.01)
    pub.publish(Clock(clock=Time(5_100_000_000).to_msg()))
    ctx.executor.spin(wall_timeout_s=0.01)
    # one call for the jump to 5.05 s (not 50), then the regular one at 5.1 s
    assert fired == [5_050_000_000, 5_100_000_000]


def test_clock_pauses_without_listeners_and_resumes_for_a_late_subscriber() -> None:
    ctx = Context(clock_period_s=0.01)
    ctx.spin_for(1.0)
    runs_idle = ctx.executor.events_run
    assert runs_idle <= 2  # one tick found nobody listening and paused the timer
    stamps: list[int] = []
    ctx.create_node("late").create_subscription(
        Clock, "/clock", lambda m: stamps.append(m.clock.sec * 10**9 + m.clock.nanosec), 10
    )
    ctx.spin_for(1.0)
    assert 99 <= len(stamps) <= 100
    assert stamps[0] > 1_000_000_000 and stamps[-1] <= 2_000_000_000


def test_wait_for_from_another_thread_counts_the_time_the_executor_lived() -> None:
    """A callback holding a paced executor for 2 s of wall time does not use up a
    sim-time timeout another thread waits with: the simulation stood still meanwhile."""
    ctx = Context(clock="paced", rate=10.0)
    node = ctx.create_node("busy")
    held: list[bool] = []

    def hold() -> None:
        if not held:
            held.append(True)
            time.sleep(2.0)  # e.g. a costmap's first inflation on a loaded machine

    node.create_timer(0.1, hold)
    ctx.spin_in_thread()
    try:
        started = time.monotonic()
        assert not ctx.wait_for(lambda: False, 5.0)  # 5 sim s = 0.5 s wall at rate 10
        assert time.monotonic() - started >= 2.0
        assert ctx.executor.now_ns >= 5_000_000_000
    finally:
        ctx.shutdown()
