"""ROS 1 on the wire: roverlab against real rospy (Debian's ros_comm), on loopback.

    python benchmarks/ros1_wire.py [--scans N] [--pings N] [--blocks N] [--raw-senders N]
                                   [--json FILE]

Under a real rosmaster (port 11560), with 720-beam LaserScans (5.8 kB in ROS 1 bytes):
- one way, as fast as possible (flood), received scans per second. A flood measures its
  slower side, so each side is measured against a peer that is cheaper than it:
  sending, rospy's and roverlab's publisher (each serialises every scan) into a rospy
  AnyMsg counter (which decodes nothing); receiving, rospy's and roverlab's LaserScan
  subscriber fed by the same sender process (roverlab's ROS 1 peer alone, sending one
  scan's bytes serialised once: rospy's publish costs ~100 us a call even then). Each
  row also shows the sender's own rate, so it can be seen which side set the pace. A
  side's throughput is the lower of its two figures. rospy -> rospy end to end is shown
  too (there rospy's serialising sender sets the pace);
- round trip (ping -> echo -> pong), median and p99: rospy's pinger and roverlab's, each
  against a rospy echo, in alternating blocks (the machine's load falls on both alike).
Targets (issue 26): roverlab's throughput >= rospy's, round trip <= 1.2x rospy's.
The rospy side is benchmarks/ros1_wire_rospy.py, run by /usr/bin/python3.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np

from roverlab.core import Context
from roverlab.core.transport.ros1.errors import MasterError
from roverlab.core.transport.ros1.peer import Ros1Peer
from roverlab.core.transport.ros1.transport import Ros1Transport, topic_spec
from roverlab.core.transport.ros1.xmlrpc import call
from roverlab.msgs import Header, LaserScan
from roverlab.msgs.ros1 import serialize_ros1

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


def rtt_stats(rtts: list[float]) -> dict[str, float]:
    ordered = sorted(rtts)
    return {
        "median": statistics.median(ordered),
        "p99": ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))],
    }


def _flood_result(received: int, seconds: float, senders: list[dict[str, Any]]) -> dict[str, Any]:
    return {
        "received": received,
        "scans_per_s": (received - 1) / seconds if seconds > 0 else 0.0,
        # how fast the sender(s) handed scans to their publisher: when this is well above
        # scans_per_s, the receiver set the pace
        "sender_scans_per_s": sum(s["sent"] / s["seconds"] for s in senders if s["seconds"] > 0),
    }


def flood_rospy_to_rospy(n: int) -> dict[str, Any]:
    """Both sides real rospy (the sender serialises each scan in publish)."""
    counter = rospy("count", "/flood_a", str(n))
    wait_ready(counter)
    sender = rospy("flood", "/flood_a", str(n))
    out = read_json(counter)
    return _flood_result(out["count"], out["seconds"], [read_json(sender)])


def flood_rospy_sends(n: int) -> dict[str, Any]:
    """rospy's sending capacity: rospy publishes LaserScans to a rospy AnyMsg counter."""
    counter = rospy("count_any", "/flood_s1", str(n))
    wait_ready(counter)
    sender = rospy("flood", "/flood_s1", str(n))
    out = read_json(counter)
    return _flood_result(out["count"], out["seconds"], [read_json(sender)])


def flood_roverlab_sends(ctx: Context, n: int) -> dict[str, Any]:
    """roverlab's sending capacity: roverlab publishes to the same rospy AnyMsg counter."""
    counter = rospy("count_any", "/flood_s2", str(n))
    wait_ready(counter)
    node = ctx.create_node("bench_flood")
    pub = node.create_publisher(LaserScan, "/flood_s2", n)  # queue n: no drops, as rospy's
    transport = ctx.transports[0]
    assert isinstance(transport, Ros1Transport)
    end = time.monotonic() + 30
    while not transport.peer.has_subscribers("/flood_s2") and time.monotonic() < end:
        time.sleep(0.01)
    time.sleep(0.3)
    msg = make_scan()
    t0 = time.perf_counter()
    for _ in range(n):
        pub.publish(msg)
    sent = {"sent": n, "seconds": time.perf_counter() - t0}
    out = read_json(counter)
    node.destroy_node()
    return _flood_result(out["count"], out["seconds"], [sent])


def raw_send(topic: str, n: int) -> None:
    """A sender cheaper than either receiver (run in its own process): roverlab's ROS 1
    peer alone, publishing one scan's ROS 1 bytes, serialised once, ``n`` times."""
    peer = Ros1Peer(MASTER)
    node = f"/bench_raw_{os.getpid()}"
    spec = topic_spec("sensor_msgs/msg/LaserScan")
    peer.advertise(node, topic, spec, queue_size=n)
    data = serialize_ros1(make_scan(), "sensor_msgs/msg/LaserScan")
    end = time.monotonic() + 30
    while not peer.has_subscribers(topic) and time.monotonic() < end:
        time.sleep(0.01)
    time.sleep(0.3)
    t0 = time.perf_counter()
    for _ in range(n):
        peer.publish(topic, data)
    print(json.dumps({"sent": n, "seconds": time.perf_counter() - t0}), flush=True)
    time.sleep(2.0)
    peer.close()


def _raw_senders(topic: str, n: int, senders: int) -> list[subprocess.Popen[str]]:
    share = [n // senders + (1 if i < n % senders else 0) for i in range(senders)]
    return [
        subprocess.Popen(
            [sys.executable, __file__, "--raw-send", topic, str(k)],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        for k in share
    ]


def flood_rospy_receives(n: int, senders: int) -> dict[str, Any]:
    """rospy's receiving capacity: pre-serialised scans (a cheap sender) to a rospy
    LaserScan subscriber."""
    counter = rospy("count", "/flood_r1", str(n))
    wait_ready(counter)
    procs = _raw_senders("/flood_r1", n, senders)
    out = read_json(counter)
    return _flood_result(out["count"], out["seconds"], [read_json(p) for p in procs])


def flood_roverlab_receives(ctx: Context, n: int, senders: int) -> dict[str, Any]:
    """roverlab's receiving capacity: the same senders to a roverlab subscription."""
    node = ctx.create_node("bench_count")
    times: list[float] = []
    node.create_subscription(
        LaserScan, "/flood_r2", lambda _m: times.append(time.perf_counter()), n
    )
    procs = _raw_senders("/flood_r2", n, senders)
    end = time.monotonic() + 120
    while time.monotonic() < end:
        time.sleep(0.2)
        if len(times) >= n or (times and time.perf_counter() - times[-1] > 2.0):
            break
    sent = [read_json(p) for p in procs]
    node.destroy_node()
    seconds = times[-1] - times[0] if len(times) > 1 else 0.0
    return _flood_result(len(times), seconds, sent)


def round_trips(ctx: Context, pings: int, blocks: int) -> tuple[list[float], list[float]]:
    """Round trip times (ms) of rospy's pinger and of roverlab's, each against its own
    rospy echo, in ``blocks`` alternating blocks (a load change on the shared machine
    falls on both alike)."""
    echo_a = rospy("echo", "/ping_a", "/pong_a")
    echo_b = rospy("echo", "/ping_b", "/pong_b")
    wait_ready(echo_a)
    wait_ready(echo_b)
    node = ctx.create_node("bench_ping")
    got = threading.Event()
    node.create_subscription(LaserScan, "/pong_b", lambda _m: got.set(), 10)
    pub = node.create_publisher(LaserScan, "/ping_b", 10)
    msg = make_scan()
    ours: list[float] = []
    theirs: list[float] = []
    try:
        end = time.monotonic() + 30
        while not got.is_set() and time.monotonic() < end:  # both links up
            pub.publish(msg)
            got.wait(0.1)
        share = max(1, pings // blocks)
        for _ in range(blocks):
            theirs += read_json(rospy("ping", "/ping_a", "/pong_a", str(share)))["rtt_ms"]
            for _ in range(share):
                got.clear()
                t0 = time.perf_counter()
                pub.publish(msg)
                if got.wait(2.0):
                    ours.append((time.perf_counter() - t0) * 1000.0)
    finally:
        for echo in (echo_a, echo_b):
            echo.terminate()
            echo.wait(10)
        node.destroy_node()
    return theirs, ours


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scans", type=int, default=5000, help="scans per flood")
    parser.add_argument("--pings", type=int, default=500, help="round trips per pair")
    parser.add_argument(
        "--blocks", type=int, default=5, help="alternating blocks the round trips come in"
    )
    parser.add_argument(
        "--raw-senders",
        type=int,
        default=1,
        help="pre-serialising sender processes in the receive floods (more make sure the "
        "receiver, not the sender, sets the pace)",
    )
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    parser.add_argument("--raw-send", nargs=2, help=argparse.SUPPRESS)  # a sender process
    args = parser.parse_args()
    if args.raw_send:
        raw_send(args.raw_send[0], int(args.raw_send[1]))
        return
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
            "flood_rospy_sends": flood_rospy_sends(args.scans),
            "flood_roverlab_sends": flood_roverlab_sends(ctx, args.scans),
            "flood_rospy_receives": flood_rospy_receives(args.scans, args.raw_senders),
            "flood_roverlab_receives": flood_roverlab_receives(ctx, args.scans, args.raw_senders),
        }
        theirs, ours = round_trips(ctx, args.pings, args.blocks)
        res["rospy_rtt_ms"] = rtt_stats(theirs)
        res["roverlab_rtt_ms"] = rtt_stats(ours)
    finally:
        if ctx is not None:
            ctx.shutdown()
            for t in ctx.transports:
                t.close()
        master.terminate()
        master.wait(10)
    # a side's throughput is what its slower half sustains: sending or receiving
    res["rospy_scans_per_s"] = min(
        res["flood_rospy_sends"]["scans_per_s"], res["flood_rospy_receives"]["scans_per_s"]
    )
    res["roverlab_scans_per_s"] = min(
        res["flood_roverlab_sends"]["scans_per_s"], res["flood_roverlab_receives"]["scans_per_s"]
    )
    rows = [
        ("rospy -> rospy (end to end)", res["flood_rospy_to_rospy"]),
        ("send: rospy -> AnyMsg counter", res["flood_rospy_sends"]),
        ("send: roverlab -> AnyMsg counter", res["flood_roverlab_sends"]),
        ("receive: raw -> rospy", res["flood_rospy_receives"]),
        ("receive: raw -> roverlab", res["flood_roverlab_receives"]),
    ]
    print(f"720-beam LaserScan over TCPROS, {args.scans} scans per flood, loopback")
    for label, r in rows:
        print(
            f"  {label:<34} {r['scans_per_s']:>9,.0f} scans/s  ({r['received']} received; "
            f"sender {r['sender_scans_per_s']:,.0f}/s)"
        )
    for label, key in (
        ("rospy <-> rospy", "rospy_rtt_ms"),
        ("roverlab <-> rospy", "roverlab_rtt_ms"),
    ):
        r = res[key]
        print(f"  round trip {label:<20} median {r['median']:.3f} ms  p99 {r['p99']:.3f} ms")
    ratio = res["roverlab_rtt_ms"]["median"] / res["rospy_rtt_ms"]["median"]
    res["rtt_ratio"] = ratio
    ours, theirs = res["roverlab_scans_per_s"], res["rospy_scans_per_s"]
    print(
        f"targets: throughput (min of send, receive) {ours:,.0f} >= {theirs:,.0f} scans/s: "
        f"{'met' if ours >= theirs else 'NOT met'}; "
        f"round trip {ratio:.2f}x rospy <= 1.2x: {'met' if ratio <= 1.2 else 'NOT met'}"
    )
    if args.json is not None:
        args.json.write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
