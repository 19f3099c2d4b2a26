"""ROS 1 on the wire: roverlab against real rospy (Debian's ros_comm), on loopback.

    python benchmarks/ros1_wire.py [--scans N] [--pings N] [--json FILE]

Under a real rosmaster (port 11560), with 720-beam LaserScans (5.8 kB in ROS 1 bytes):
- one way, as fast as the sender can (flood), received scans per second:
  rospy -> rospy, roverlab -> rospy, rospy -> roverlab;
- round trip (ping -> echo -> pong), median and p99: rospy <-> rospy, and roverlab's pinger
  against a rospy echo.
Targets (issue 26): roverlab's throughput >= rospy's, round trip <= 1.2x rospy's.
The rospy side is benchmarks/ros1_wire_rospy.py, run by /usr/bin/python3.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.core import Context
from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.transport import Ros1Transport
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.msgs import Header, LaserScan

HERE = Path(__file__).resolve().parent
PEER = str(HERE / "ros1_wire_rospy.py")
PORT = 11560
MASTER = f"http://127.0.0.1:{PORT}/"


def ros_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env.update(ROS_MASTER_URI=MASTER, ROS_HOSTNAME="127.0.0.1", PATH="/usr/bin:/bin")
    return env


def rospy(*args: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        ["/usr/bin/python3", PEER, *args],
        env=ros_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )


def read_json(proc: subprocess.Popen[str]) -> dict[str, Any]:
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.startswith("{"):
            proc.wait(30)
            return dict(json.loads(line))
    raise RuntimeError("the rospy peer printed no result")


def wait_ready(proc: subprocess.Popen[str]) -> None:
    assert proc.stdout is not None
    line = proc.stdout.readline()
    if line.strip() != "ready":
        raise RuntimeError(f"the rospy peer did not start: {line!r}")


def make_scan() -> Any:
    return LaserScan(
        header=Header(frame_id="laser"),
        angle_min=-np.pi,
        angle_max=np.pi,
        angle_increment=2 * np.pi / 720,
        range_min=0.1,
        range_max=30.0,
        ranges=(1.0 + 0.001 * np.arange(720)).astype(np.float32),
        intensities=np.zeros(720, np.float32),
    )


def rate(times: list[float]) -> float:
    return (len(times) - 1) / (times[-1] - times[0]) if len(times) > 1 else 0.0


def rtt_stats(rtts: list[float]) -> dict[str, float]:
    ordered = sorted(rtts)
    return {
        "median": statistics.median(ordered),
        "p99": ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))],
    }


def flood_rospy_to_rospy(n: int) -> dict[str, Any]:
    counter = rospy("count", "/flood_a", str(n))
    wait_ready(counter)
    sender = rospy("flood", "/flood_a", str(n))
    out = read_json(counter)
    sender.wait(60)
    return {"received": out["count"], "scans_per_s": (out["count"] - 1) / out["seconds"]}


def flood_roverlab_to_rospy(ctx: Context, n: int) -> dict[str, Any]:
    counter = rospy("count", "/flood_b", str(n))
    wait_ready(counter)
    node = ctx.create_node("bench_flood")
    pub = node.create_publisher(LaserScan, "/flood_b", n)  # queue n: no drops, as rospy's
    transport = ctx.transports[0]
    assert isinstance(transport, Ros1Transport)
    end = time.monotonic() + 30
    while not transport.peer.has_subscribers("/flood_b") and time.monotonic() < end:
        time.sleep(0.01)
    time.sleep(0.3)
    msg = make_scan()
    for _ in range(n):
        pub.publish(msg)
    out = read_json(counter)
    node.destroy_node()
    return {"received": out["count"], "scans_per_s": (out["count"] - 1) / out["seconds"]}


def flood_rospy_to_roverlab(ctx: Context, n: int) -> dict[str, Any]:
    node = ctx.create_node("bench_count")
    times: list[float] = []
    node.create_subscription(LaserScan, "/flood_c", lambda _m: times.append(time.perf_counter()), n)
    sender = rospy("flood", "/flood_c", str(n))
    end = time.monotonic() + 120
    while time.monotonic() < end:
        time.sleep(0.2)
        if len(times) >= n or (times and time.perf_counter() - times[-1] > 2.0):
            break
    sender.wait(60)
    node.destroy_node()
    return {"received": len(times), "scans_per_s": rate(times)}


def rtt_rospy(pings: int) -> dict[str, float]:
    echo = rospy("echo", "/ping_a", "/pong_a")
    wait_ready(echo)
    try:
        out = read_json(rospy("ping", "/ping_a", "/pong_a", str(pings)))
    finally:
        echo.terminate()
        echo.wait(10)
    return rtt_stats(out["rtt_ms"])


def rtt_roverlab(ctx: Context, pings: int) -> dict[str, float]:
    echo = rospy("echo", "/ping_b", "/pong_b")
    wait_ready(echo)
    node = ctx.create_node("bench_ping")
    got = threading.Event()
    node.create_subscription(LaserScan, "/pong_b", lambda _m: got.set(), 10)
    pub = node.create_publisher(LaserScan, "/ping_b", 10)
    msg = make_scan()
    try:
        end = time.monotonic() + 30
        while not got.is_set() and time.monotonic() < end:  # both links up
            pub.publish(msg)
            got.wait(0.1)
        rtts = []
        for _ in range(pings):
            got.clear()
            t0 = time.perf_counter()
            pub.publish(msg)
            if got.wait(2.0):
                rtts.append((time.perf_counter() - t0) * 1000.0)
    finally:
        echo.terminate()
        echo.wait(10)
        node.destroy_node()
    return rtt_stats(rtts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scans", type=int, default=5000, help="scans per flood")
    parser.add_argument("--pings", type=int, default=500, help="round trips per pair")
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    args = parser.parse_args()
    if not Path("/usr/bin/rosmaster").exists():
        raise SystemExit(
            "needs Debian's ROS 1 (/usr/bin/rosmaster): scripts/install-system-deps.sh"
        )
    master = subprocess.Popen(
        ["/usr/bin/rosmaster", "--core", "-p", str(PORT)],
        env=ros_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    ctx = None
    try:
        for _ in range(100):
            try:
                call(MASTER, "getUri", "/bench", timeout_s=1.0)
                break
            except MasterError:
                time.sleep(0.1)
        ctx = Context(clock="wall", publish_clock=False)
        ctx.add_transport(Ros1Transport(MASTER))
        ctx.spin_in_thread()
        res: dict[str, Any] = {
            "flood_rospy_to_rospy": flood_rospy_to_rospy(args.scans),
            "flood_roverlab_to_rospy": flood_roverlab_to_rospy(ctx, args.scans),
            "flood_rospy_to_roverlab": flood_rospy_to_roverlab(ctx, args.scans),
            "rospy_rtt_ms": rtt_rospy(args.pings),
            "roverlab_rtt_ms": rtt_roverlab(ctx, args.pings),
        }
    finally:
        if ctx is not None:
            ctx.shutdown()
            for t in ctx.transports:
                t.close()
        master.terminate()
        master.wait(10)
    res["rospy_scans_per_s"] = res["flood_rospy_to_rospy"]["scans_per_s"]
    res["roverlab_scans_per_s"] = min(
        res["flood_roverlab_to_rospy"]["scans_per_s"], res["flood_rospy_to_roverlab"]["scans_per_s"]
    )
    rows = [
        ("rospy -> rospy", res["flood_rospy_to_rospy"]),
        ("roverlab -> rospy", res["flood_roverlab_to_rospy"]),
        ("rospy -> roverlab", res["flood_rospy_to_roverlab"]),
    ]
    print(f"720-beam LaserScan over TCPROS, {args.scans} scans per flood, loopback")
    for label, r in rows:
        print(f"  {label:<20} {r['scans_per_s']:>9,.0f} scans/s  ({r['received']} received)")
    for label, key in (
        ("rospy <-> rospy", "rospy_rtt_ms"),
        ("roverlab <-> rospy", "roverlab_rtt_ms"),
    ):
        r = res[key]
        print(f"  round trip {label:<20} median {r['median']:.3f} ms  p99 {r['p99']:.3f} ms")
    ratio = res["roverlab_rtt_ms"]["median"] / res["rospy_rtt_ms"]["median"]
    ours, theirs = res["roverlab_scans_per_s"], res["rospy_scans_per_s"]
    print(
        f"targets: throughput {ours:,.0f} >= {theirs:,.0f} scans/s: "
        f"{'met' if ours >= theirs else 'NOT met'}; "
        f"round trip {ratio:.2f}x rospy <= 1.2x: {'met' if ratio <= 1.2 else 'NOT met'}"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
