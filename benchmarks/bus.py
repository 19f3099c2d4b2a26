"""Message bus benchmark: in-process delivery rate, Zenoh round trip and throughput.

    python benchmarks/bus.py [--messages N] [--pings N] [--scans N]

Prints:
- in-process 720-beam LaserScan publish -> callback rate (target >= 200,000 msg/s);
- Zenoh two-process round trip of a 720-beam LaserScan, median and p99 (target median
  <= 0.5 ms);
- Zenoh two-process throughput of 720-beam LaserScans (target >= 20,000 scans/s);
- service round trips (rospy_tutorials/AddTwoInts): in process, through the executor
  (call_async completed by the executor; target >= 20,000 calls/s) and inline (``call``
  while nothing spins), and across two processes over Zenoh, median and p99 of ``call``
  (target median <= 1 ms).
The second process is this script run with ``--child``.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import socket
import subprocess
import sys
import time
from typing import Any

import numpy as np

from roverlab.core import Context
from roverlab.core.transport.daemon import ensure_daemon, stop_daemon
from roverlab.core.transport.zenoh import ZenohOptions, ZenohTransport
from roverlab.msgs import Header, LaserScan, String


def make_scan(seq: int = 0) -> Any:
    return LaserScan(
        header=Header(frame_id="laser", stamp={"sec": seq, "nanosec": 0}),
        angle_min=-np.pi,
        angle_max=np.pi,
        angle_increment=2 * np.pi / 720,
        range_min=0.12,
        range_max=12.0,
        ranges=np.linspace(0.5, 10.0, 720, dtype=np.float32),
        intensities=np.zeros(720, dtype=np.float32),
    )


def bench_inprocess(n: int) -> float:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("bench")
    pub = node.create_publisher(LaserScan, "/scan", 10)
    got = [0]

    def cb(_msg: Any) -> None:
        got[0] += 1

    node.create_subscription(LaserScan, "/scan", cb, 1000)
    scan = make_scan()
    batch = 1000

    def burst() -> None:
        for _ in range(batch):
            pub.publish(scan)

    node.create_timer(0.001, burst)
    periods = n // batch
    t0 = time.perf_counter()
    ctx.spin_for(periods * 0.001)
    dt = time.perf_counter() - t0
    assert got[0] == periods * batch, got[0]
    return got[0] / dt


def _add(req: Any, resp: Any) -> Any:
    resp.sum = req.a + req.b
    return resp


def bench_service_inprocess(n: int) -> tuple[float, float]:
    """Calls per second: call_async + the executor completing it, and inline call()."""
    ctx = Context(publish_clock=False)
    ctx.create_node("server").create_service("rospy_tutorials/AddTwoInts", "/add", _add)
    client = ctx.create_node("client").create_client("rospy_tutorials/AddTwoInts", "/add")
    req = client.srv_type.Request(a=1, b=2)
    t0 = time.perf_counter()
    for _ in range(n):
        future = client.call_async(req)
        ctx.spin_until_future_complete(future)
        assert future.result().sum == 3
    executor_rate = n / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    for _ in range(n):
        client.call(req)
    inline_rate = n / (time.perf_counter() - t0)
    ctx.shutdown()
    return executor_rate, inline_rate


def _options(endpoint: str) -> ZenohOptions:
    return ZenohOptions(listen=("tcp/127.0.0.1:0",), connect=(endpoint,))


def child(endpoint: str) -> None:
    """Echo /ping to /pong; count /flood and report on /flood_count."""
    ctx = Context(clock="wall")
    node = ctx.create_node("bench_child")
    pong = node.create_publisher(LaserScan, "/pong", 1000)
    node.create_subscription(LaserScan, "/ping", pong.publish, 1000)
    report = node.create_publisher(String, "/flood_count", 10)
    count = [0]

    def on_flood(msg: Any) -> None:
        count[0] += 1
        if msg.header.frame_id == "last":
            report.publish(String(data=str(count[0])))
            count[0] = 0

    node.create_subscription(LaserScan, "/flood", on_flood, 100000)
    node.create_service("rospy_tutorials/AddTwoInts", "/add_two_ints", _add)
    ctx.add_transport(ZenohTransport(_options(endpoint)))
    print("READY", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        ctx.spin()


def bench_zenoh(
    endpoint: str, pings: int, scans: int
) -> tuple[float, float, float, int, float, float]:
    proc = subprocess.Popen(
        [sys.executable, __file__, "--child", "--endpoint", endpoint],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        if proc.stdout.readline().strip() != "READY":
            raise RuntimeError("benchmark child did not start")
        ctx = Context(clock="wall")
        node = ctx.create_node("bench_parent")
        ping = node.create_publisher(LaserScan, "/ping", 10)
        flood = node.create_publisher(LaserScan, "/flood", 10)
        got: list[int] = []
        counts: list[int] = []
        node.create_subscription(LaserScan, "/pong", lambda m: got.append(m.header.stamp.sec), 1000)
        node.create_subscription(String, "/flood_count", lambda m: counts.append(int(m.data)), 10)
        client = node.create_client("rospy_tutorials/AddTwoInts", "/add_two_ints")
        ctx.add_transport(ZenohTransport(_options(endpoint)))
        deadline = time.monotonic() + 10
        while (
            ping.topic.remote_send is None or flood.topic.remote_send is None
        ) and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.3)
        ex = ctx.executor
        rtts: list[float] = []
        for i in range(pings + 50):
            scan = make_scan(i)
            t0 = time.perf_counter()
            ping.publish(scan)
            ctx.spin_until_condition(lambda i=i: bool(got) and got[-1] == i, timeout_sec=2.0)
            rtt = time.perf_counter() - t0
            if i >= 50:  # warm-up
                rtts.append(rtt)
        del ex
        scan = make_scan()
        last = make_scan()
        last.header.frame_id = "last"
        t0 = time.perf_counter()
        for _ in range(scans - 1):
            flood.publish(scan)
        flood.publish(last)
        ctx.spin_until_condition(lambda: bool(counts), timeout_sec=60)
        dt = time.perf_counter() - t0
        received = counts[0] if counts else 0
        if not client.wait_for_service(timeout_sec=10):
            raise RuntimeError("the benchmark child's service did not appear")
        req = client.srv_type.Request(a=1, b=2)
        calls: list[float] = []
        for i in range(pings + 50):
            t0 = time.perf_counter()
            assert client.call(req, timeout_sec=5).sum == 3
            if i >= 50:
                calls.append(time.perf_counter() - t0)
        ctx.shutdown()
        a = np.asarray(rtts) * 1e3
        c = np.asarray(calls) * 1e3
        return (
            float(np.median(a)),
            float(np.percentile(a, 99)),
            received / dt,
            received,
            float(np.median(c)),
            float(np.percentile(c, 99)),
        )
    finally:
        proc.terminate()
        proc.wait(timeout=5)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--messages", type=int, default=500_000)
    parser.add_argument("--pings", type=int, default=2000)
    parser.add_argument("--scans", type=int, default=50_000)
    parser.add_argument("--calls", type=int, default=100_000)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--endpoint", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.endpoint)
        return
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
        f"Python {platform.python_version()}"
    )
    rate = bench_inprocess(args.messages)
    print(f"in-process LaserScan(720) publish->callback: {rate:,.0f} msg/s (target >= 200,000)")
    srv_rate, inline_rate = bench_service_inprocess(args.calls)
    print(
        f"in-process service call (call_async, completed by the executor): {srv_rate:,.0f} "
        f"calls/s (target >= 20,000); inline call(): {inline_rate:,.0f} calls/s"
    )
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    os.environ["ROVERLAB_DAEMON"] = endpoint
    ensure_daemon(endpoint)
    try:
        med, p99, tput, received, s_med, s_p99 = bench_zenoh(endpoint, args.pings, args.scans)
    finally:
        stop_daemon(endpoint)
    print(
        f"zenoh 2-process LaserScan(720) round trip: median {med:.3f} ms, p99 {p99:.3f} ms "
        f"(target median <= 0.5 ms)"
    )
    print(
        f"zenoh 2-process LaserScan(720) throughput: {tput:,.0f} scans/s "
        f"({received}/{args.scans} delivered; target >= 20,000)"
    )
    print(
        f"zenoh 2-process service call round trip: median {s_med:.3f} ms, p99 {s_p99:.3f} ms "
        f"({1000 / s_med:,.0f} calls/s sequential; target median <= 1 ms)"
    )


if __name__ == "__main__":
    main()
