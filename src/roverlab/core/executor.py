"""Single-threaded executor ordering every callback by (time, sequence) on a clock it owns.

Clock modes:

``sim``
    Simulated time that jumps from event to event as fast as the CPU allows. Nothing
    waits on the wall clock, so a seeded run is reproducible bit for bit.
``paced``
    Simulated time that advances with the wall clock times ``rate`` (``rate=1`` is real
    time). Callbacks scheduled at a time see exactly that time. When the callbacks need
    more CPU than the pace allows, the clock waits for them (as Gazebo's real-time factor
    drops): it never runs more than :data:`PACED_MAX_LAG_S` of wall time ahead of the
    executor, so other threads' sim-time timeouts count time the simulation has lived.
``wall``
    The system clock (nanoseconds since the Unix epoch), for processes that talk to
    hardware or to other processes in real time.
``external``
    Time follows ``/clock`` messages received from another process (``use_sim_time``);
    timers fire as that time passes. Until the first ``/clock`` message the time is the
    start time and no timer runs: timers made before it start at that first time, as
    rospy's timers and sleeps wait for the clock (a node started before the simulator, or
    long after it, does not take the time jump for seconds without data).

Messages published at time *t* are delivered at time *t*, after every event that was
already queued for *t*: the sequence number breaks ties. Work handed in from other
threads (the Zenoh transport, a user's main thread) goes through a locked inbox and is
run at the executor's current time.

In the real-time modes, work from another thread may instead run at once in that thread
(:meth:`Executor.run_now_or_soon`) when the executor is parked with nothing queued or
due: the executor stays parked until it is done, so callbacks still never run two at a
time and keep their order, and a message from a socket reaches its callback without a
thread wake-up (rospy runs a subscriber's callback in its connection's thread).
"""

from __future__ import annotations

import heapq
import itertools
import math
import threading
import time
from collections import deque
from collections.abc import Callable
from enum import Enum
from typing import Any

__all__ = ["ClockMode", "Executor"]

_INF = 1 << 62

#: In ``paced`` mode, how far (wall seconds) the executor may fall behind the pace before
#: the clock is re-anchored on it instead of running ahead.
PACED_MAX_LAG_S = 0.05


class ClockMode(Enum):
    SIM = "sim"
    PACED = "paced"
    WALL = "wall"
    EXTERNAL = "external"


ErrorHandler = Callable[[Any, BaseException], None]


class Executor:
    """Runs timers, message deliveries and scheduled calls in (time, sequence) order.

    Args:
        mode: clock mode, see the module docstring.
        rate: for ``paced``: simulated seconds per wall second (``math.inf`` = ``sim``).
        start_ns: initial simulated time (``sim``/``paced``/``external``).
        on_error: called with (callback owner, exception) when a callback raises; the
            executor then goes on with the next callback.
    """

    def __init__(
        self,
        *,
        mode: ClockMode = ClockMode.SIM,
        rate: float = 1.0,
        start_ns: int = 0,
        on_error: ErrorHandler | None = None,
    ) -> None:
        if mode is ClockMode.PACED and math.isinf(rate):
            mode = ClockMode.SIM
        if not (rate > 0 and not math.isnan(rate)):
            raise ValueError(f"executor rate must be > 0, got {rate}")
        self.mode = mode
        self.rate = rate
        self.now_ns = time.time_ns() if mode is ClockMode.WALL else start_ns
        self._heap: list[tuple[int, int, Callable[[], Any]]] = []
        self._ready: deque[tuple[int, Callable[[], Any]]] = deque()
        self._seq = itertools.count()
        self._inbox: deque[Callable[[], Any]] = deque()
        self._cv = threading.Condition()
        self._thread_id: int | None = None
        self._sleeping = False
        self._inline = False  # another thread runs callbacks while the executor is parked
        self._wait_target = _INF  # the clock time the parked executor waits for
        self._spin_checks = False  # the spin has a stop condition or an event budget
        self._stopped = False
        self._pace_origin: tuple[int, int] | None = None  # (sim ns, perf_counter ns)
        self.clock_received = mode is not ClockMode.EXTERNAL
        """False in ``external`` mode until the first ``/clock`` message."""
        self._on_clock_start: list[Callable[[], Any]] = []
        self._max_lag_ns = round(PACED_MAX_LAG_S * 1e9 * rate) if mode is ClockMode.PACED else _INF
        self.on_error = on_error
        self.callback_errors = 0
        self.events_run = 0

    # ----------------------------------------------------------------- scheduling
    def next_seq(self) -> int:
        return next(self._seq)

    def call_at(self, t_ns: int, fn: Callable[[], Any]) -> None:
        """Run ``fn`` when the clock reaches ``t_ns`` (not before any earlier event)."""
        heapq.heappush(self._heap, (max(t_ns, self.now_ns), next(self._seq), fn))

    def when_clock_starts(self, fn: Callable[[], Any]) -> None:
        """Call ``fn`` once the clock runs: now, or (``external`` mode) at the first
        ``/clock`` message, on the executor's thread."""
        if self.clock_received:
            fn()
        else:
            self._on_clock_start.append(fn)

    def call_soon(self, fn: Callable[[], Any]) -> None:
        """Run ``fn`` at the current time, after what is already queued (executor thread)."""
        self._ready.append((next(self._seq), fn))

    def call_soon_threadsafe(self, fn: Callable[[], Any]) -> None:
        """Hand ``fn`` in from any thread; it runs at the executor's current time.

        The append is atomic; the condition is only touched when the executor sleeps
        (it sets ``_sleeping`` under the lock before it checks the inbox and waits).
        """
        self._inbox.append(fn)
        if self._sleeping:
            with self._cv:
                self._cv.notify()

    def run_now_or_soon(self, fn: Callable[[], Any], *, drain: bool = True) -> bool:
        """Run ``fn`` now in the calling thread if the executor is parked (a real-time
        mode waiting for its next event) with nothing queued or due; else hand it in as
        :meth:`call_soon_threadsafe` does. True if it ran here.

        While it runs here the calling thread stands for the executor's (time, thread
        checks) and the executor stays parked, so callbacks never overlap. With ``drain``
        the work ``fn`` queued for now (a delivery's callback) runs here too; else the
        executor is woken for it.
        """
        cv = self._cv
        with cv:
            ok = (
                self._sleeping
                and not self._inline
                and not self._stopped
                and not self._inbox
                and not self._ready
            )
            if ok and self._heap:
                now = self.now_ns if self.mode is ClockMode.EXTERNAL else self._wall_now()
                ok = self._heap[0][0] > now
            if not ok:
                self._inbox.append(fn)
                if self._sleeping:
                    cv.notify()
                return False
            self._inline = True
            owner = self._thread_id
            self._thread_id = threading.get_ident()
        try:
            if self.mode in (ClockMode.PACED, ClockMode.WALL):
                self.now_ns = max(self.now_ns, self._wall_now())
            self._run_one(fn)
            if drain:
                self._run_current()
        finally:
            with cv:
                self._thread_id = owner
                self._inline = False
                heap = self._heap
                if (
                    self._inbox
                    or self._ready
                    or self._stopped
                    or self._spin_checks  # the work may have met the spin's stop_when
                    or (heap and heap[0][0] < self._wait_target)
                    or (self.mode is ClockMode.EXTERNAL and self.now_ns >= self._wait_target)
                ):
                    cv.notify()
        return True

    def _run_current(self) -> None:
        """Run what is queued for the current time (ready work, due timers) in order."""
        heap = self._heap
        ready = self._ready
        while True:
            due = bool(heap) and heap[0][0] <= self.now_ns
            if ready and not (due and heap[0][1] < ready[0][0]):
                self._run_one(ready.popleft()[1])
            elif due:
                self._run_one(heapq.heappop(heap)[2])
            else:
                return

    def on_executor_thread(self) -> bool:
        """True when called from the spinning thread, or when nothing is spinning."""
        tid = self._thread_id
        return tid is None or tid == threading.get_ident()

    def wake(self) -> None:
        with self._cv:
            self._cv.notify()

    def stop(self) -> None:
        """Make the current (or next) spin return as soon as the running callback ends."""
        self._stopped = True
        self.wake()

    @property
    def stopped(self) -> bool:
        return self._stopped

    def reset_stop(self) -> None:
        self._stopped = False

    # ----------------------------------------------------------------- clock
    def _wall_now(self) -> int:
        """The time the clock would show now, for the real-time modes."""
        if self.mode is ClockMode.WALL:
            return time.time_ns()
        if self.mode is ClockMode.PACED:
            if self._pace_origin is None:
                self._pace_origin = (self.now_ns, time.perf_counter_ns())
            sim0, wall0 = self._pace_origin
            return sim0 + int((time.perf_counter_ns() - wall0) * self.rate)
        return self.now_ns

    def clock_now_ns(self) -> int:
        """The clock as a caller sees it: inside a callback, the event's time; from another
        thread (or while nothing spins) in the real-time modes, the live clock."""
        tid = self._thread_id
        if tid is not None and tid == threading.get_ident():
            return self.now_ns
        if self.mode is ClockMode.WALL:
            return max(self.now_ns, time.time_ns())
        if self.mode is ClockMode.PACED and self._pace_origin is not None:
            return max(self.now_ns, self._wall_now())
        return self.now_ns

    def set_external_time(self, t_ns: int) -> None:
        """Advance an ``external`` clock (called with each /clock message)."""
        if not self.clock_received:
            # the first /clock: the timers made before it start now
            self.clock_received = True
            self.now_ns = max(self.now_ns, t_ns)
            waiting, self._on_clock_start = self._on_clock_start, []
            for fn in waiting:
                fn()
            return
        if t_ns > self.now_ns:
            self.now_ns = t_ns
        elif t_ns < self.now_ns - 1_000_000_000:
            # Time jumped back by more than a second (the simulation restarted): follow
            # it, as rclpy's time jump handling does, and drop timers planned far ahead.
            self.now_ns = t_ns
            self._heap[:] = [(min(t, t_ns), s, f) for (t, s, f) in self._heap]
            heapq.heapify(self._heap)

    # ----------------------------------------------------------------- running
    def _run_one(self, fn: Callable[[], Any]) -> None:
        try:
            fn()
        except Exception as err:  # a node's bug must not stop the others
            self._report(fn, err)
        self.events_run += 1

    def _report(self, fn: Callable[[], Any], err: Exception) -> None:
        self.callback_errors += 1
        if self.on_error is not None:
            owner = getattr(fn, "__self__", fn)
            # a bound method of a wrapper (a timer's firing) names the wrapper's owner
            owner = getattr(owner, "__self__", owner)
            self.on_error(owner, err)

    def _spin_sim(self, limit: int) -> None:
        """The ``sim`` mode's loop without stop conditions: the hot path of simulation."""
        heap = self._heap
        ready = self._ready
        inbox = self._inbox
        pop = heapq.heappop
        popleft = ready.popleft
        count = 0
        try:
            while not self._stopped:
                if inbox:
                    self._drain_inbox()
                    heap = self._heap
                    continue
                if ready:
                    if heap and heap[0][0] <= self.now_ns and heap[0][1] < ready[0][0]:
                        fn = pop(heap)[2]
                    else:
                        fn = popleft()[1]
                elif heap and heap[0][0] <= limit:
                    t, _, fn = pop(heap)
                    if t > self.now_ns:
                        self.now_ns = t
                else:
                    if limit != _INF and limit > self.now_ns:
                        self.now_ns = limit
                    return
                try:
                    fn()
                except Exception as err:  # a node's bug must not stop the others
                    self._report(fn, err)
                count += 1
        finally:
            self.events_run += count

    def _drain_inbox(self) -> None:
        inbox = self._inbox
        items = [inbox.popleft() for _ in range(len(inbox))]
        if self.mode in (ClockMode.PACED, ClockMode.WALL):
            t = self._wall_now()
            if self.mode is ClockMode.WALL or not self._heap or t <= self._heap[0][0]:
                self.now_ns = max(self.now_ns, t)
            else:
                self.now_ns = max(self.now_ns, min(t, self._heap[0][0]))
        for fn in items:
            self._run_one(fn)

    def spin(
        self,
        *,
        until_ns: int | None = None,
        wall_timeout_s: float | None = None,
        stop_when: Callable[[], bool] | None = None,
        max_events: int | None = None,
    ) -> None:
        """Run events until ``until_ns`` (clock time), a wall timeout, ``stop_when()``,
        ``max_events`` events, :meth:`stop`, or (in ``sim`` mode) no event left.

        On return because ``until_ns`` was reached, the clock shows ``until_ns``.
        """
        heap = self._heap
        ready = self._ready
        inbox = self._inbox
        self._thread_id = threading.get_ident()
        wall_deadline = None if wall_timeout_s is None else time.monotonic() + wall_timeout_s
        limit = _INF if until_ns is None else until_ns
        start_events = self.events_run
        sim = self.mode is ClockMode.SIM
        self._spin_checks = stop_when is not None or max_events is not None
        try:
            if sim and stop_when is None and max_events is None:
                self._spin_sim(limit)
                return
            while not self._stopped:
                if stop_when is not None and stop_when():
                    return
                if max_events is not None and self.events_run - start_events >= max_events:
                    return
                if inbox:
                    self._drain_inbox()
                    heap = self._heap
                    continue
                if ready:
                    if heap and heap[0][0] <= self.now_ns and heap[0][1] < ready[0][0]:
                        self._run_one(heapq.heappop(heap)[2])
                    else:
                        self._run_one(ready.popleft()[1])
                    continue
                next_t = heap[0][0] if heap else _INF
                if sim:
                    if next_t <= limit:
                        if next_t > self.now_ns:
                            self.now_ns = next_t
                        self._run_one(heapq.heappop(heap)[2])
                        continue
                    if until_ns is not None and until_ns > self.now_ns:
                        self.now_ns = until_ns
                    return
                # real-time modes: wait for the next event, the limit or the inbox
                target = min(next_t, limit)
                if self.mode is ClockMode.EXTERNAL:
                    if self.now_ns >= target:
                        if next_t <= limit:
                            self._run_one(heapq.heappop(heap)[2])
                            continue
                        return
                    wait_s: float | None = None
                else:
                    now = self._wall_now()
                    if now >= target:
                        if next_t <= limit:
                            t = heap[0][0]
                            if self.mode is ClockMode.PACED and now - t > self._max_lag_ns:
                                # overloaded: the clock waits for the executor rather than
                                # running ahead of it (what other threads read, their
                                # wait_for deadlines) and making the executor burst
                                self._pace_origin = (t, time.perf_counter_ns())
                            self.now_ns = max(
                                self.now_ns, now if self.mode is ClockMode.WALL else t
                            )
                            self._run_one(heapq.heappop(heap)[2])
                            continue
                        self.now_ns = max(self.now_ns, limit)
                        return
                    wait_s = (
                        (target - now) / 1e9 / (self.rate if self.mode is ClockMode.PACED else 1.0)
                    )
                if wall_deadline is not None:
                    remaining = wall_deadline - time.monotonic()
                    if remaining <= 0:
                        return
                    wait_s = remaining if wait_s is None else min(wait_s, remaining)
                with self._cv:
                    self._sleeping = True
                    self._wait_target = target
                    if not self._inbox and not self._stopped:
                        self._cv.wait(timeout=wait_s)
                    while self._inline:  # another thread runs callbacks: stay parked
                        self._cv.wait()
                    self._sleeping = False
                if self.mode is not ClockMode.EXTERNAL and self.mode is not ClockMode.SIM:
                    self.now_ns = max(self.now_ns, min(self._wall_now(), target))
        finally:
            self._thread_id = None

    def pending(self) -> int:
        """Number of queued events (timers, deliveries, inbox items)."""
        return len(self._heap) + len(self._ready) + len(self._inbox)
