"""Bags: read and write throughput per format, beside Debian's rosbag reading the same .bag.

    python benchmarks/bags.py [--seconds 30]

1. Records ``--seconds`` of sim time of mybot in the maze (every topic: /scan, /odom, /tf,
   /tf_static, /imu, /image_raw, /camera_info, /joint_states, /clock, ...), driven by a
   constant /cmd_vel: a demo-sized recording (the demo records the same topics).
2. Writes those messages (runtime messages, serialised by the writer) to each format:
   ROS 1 ``.bag`` (none, lz4, bz2), ``.mcap`` (zstd) and a ROS 2 bag folder (sqlite3).
3. Reads each back with :class:`roverlab.bag.reader.BagReader`, decoding every message into
   the runtime's types, and has Debian's rosbag module (``/usr/bin/python3``, python3-rosbag
   1.15) read and deserialise every message of the same uncompressed ``.bag`` in the same run.
4. Converts the ``.bag`` into ``.mcap`` under tracemalloc: the peak Python allocation beside
   the file's size shows the conversion streams (a chunk at a time), never loads the bag.

MB/s are MiB of message data per second (the uncompressed ``.bag``'s size, the same messages
in every format; "size" is each file on disk), messages/s of every message; best of
``--repeat``.
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path
from typing import Any

from roverlab.bag import BagRecorder
from roverlab.bag.files import convert_bag
from roverlab.bag.reader import BagReader
from roverlab.bag.writers import open_writer
from roverlab.core import Context
from roverlab.msgs import Twist
from roverlab.sim.app import Simulation

ROSBAG_READ = r"""
import json, sys, time
import rosbag
path, repeat = sys.argv[1], int(sys.argv[2])
best = None
for _ in range(repeat):
    t0 = time.perf_counter()
    n = 0
    with rosbag.Bag(path) as bag:
        for _topic, _msg, _t in bag.read_messages():
            n += 1
    dt = time.perf_counter() - t0
    best = dt if best is None else min(best, dt)
print(json.dumps({"seconds": best, "messages": n}))
"""


def record(folder: Path, seconds: float) -> list[tuple[str, str, bool, int, Any]]:
    """(topic, type, latched, time, message) of ``seconds`` of the maze run, in order."""
    ctx = Context()
    recording = folder / "source.mcap"
    ctx.add_transport(BagRecorder(recording))
    Simulation(context=ctx, world="maze", robot="mybot", seed=0)
    pub = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 10)
    ctx.create_node("timer").create_timer(
        0.1, lambda: pub.publish(Twist(linear_x=0.2, angular_z=0.3))
    )
    ctx.spin_for(seconds)
    ctx.shutdown()
    with BagReader(recording) as reader:
        return [
            (m.topic, m.typename, m.connection.latched, m.log_time_ns, m.decode())
            for m in reader.messages()
        ]


def best_of(repeat: int, fn: Callable[[], Any]) -> tuple[float, Any]:
    best, result = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def write(path: Path, msgs: list[tuple[str, str, bool, int, Any]], compression: str | None) -> Path:
    out = open_writer(path, compression)
    handles: dict[str, int] = {}
    for topic, typename, latched, t, msg in msgs:
        handle = handles.get(topic)
        if handle is None:
            handle = handles[topic] = out.add_topic(topic, typename, latched=latched)
        out.write(handle, t, msg)
    out.finish()
    return out.path


def read(path: Path) -> int:
    n = 0
    with BagReader(path) as reader:
        for m in reader.messages():
            m.decode()
            n += 1
    return n


def size_mib(path: Path) -> float:
    files = [path] if path.is_file() else [p for p in path.iterdir() if p.is_file()]
    return sum(p.stat().st_size for p in files) / 2**20


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=30.0, help="sim seconds recorded")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per figure (best)")
    args = ap.parse_args()
    print(
        f"# bags: {platform.processor() or platform.machine()}, python {platform.python_version()}"
    )
    source = tempfile.TemporaryDirectory(prefix="roverlab-bench-source-")
    msgs = record(Path(source.name), args.seconds)
    source.cleanup()
    print(f"recorded {len(msgs)} messages on {len({m[0] for m in msgs})} topics "
          f"({args.seconds:g} s of the maze run)")  # fmt: skip
    formats = [
        ("ros1 .bag", "rec.bag", "none"),
        ("ros1 .bag lz4", "rec_lz4.bag", "lz4"),
        ("ros1 .bag bz2", "rec_bz2.bag", "bz2"),
        ("mcap zstd", "rec.mcap", "zstd"),
        ("ros2 folder", "rec_ros2", None),
    ]
    rows = []
    with tempfile.TemporaryDirectory(prefix="roverlab-bench-bags-") as tmp:
        folder = Path(tmp)
        for label, name, comp in formats:
            path = folder / name
            runs = []
            for i in range(args.repeat):
                target = path if i == 0 else folder / f"again{i}_{name}"
                t0 = time.perf_counter()
                write(target, msgs, comp)
                runs.append(time.perf_counter() - t0)
            w = min(runs)
            r, n = best_of(args.repeat, lambda p=path: read(p))  # type: ignore[misc]
            mib = size_mib(path)
            data = rows[0][1] if rows else mib  # the messages' bytes: the plain .bag's size
            rows.append((label, mib, data / w, len(msgs) / w, data / r, n / r))
        bag = folder / "rec.bag"
        debian = None
        if Path("/usr/bin/python3").exists():
            done = subprocess.run(
                ["/usr/bin/python3", "-c", ROSBAG_READ, str(bag), str(args.repeat)],
                capture_output=True,
                text=True,
                check=False,
                env={"PATH": "/usr/bin:/bin"},
            )
            if done.returncode == 0:
                debian = json.loads(done.stdout)
        tracemalloc.start()
        convert_bag(bag, folder / "converted.mcap")
        _now, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()

    print(f"{'format':<16}{'size MiB':>10}{'write MB/s':>12}{'write msg/s':>13}"
          f"{'read MB/s':>11}{'read msg/s':>12}")  # fmt: skip
    for label, mib, wmb, wmsg, rmb, rmsg in rows:
        print(f"{label:<16}{mib:>10.1f}{wmb:>12.1f}{wmsg:>13.0f}{rmb:>11.1f}{rmsg:>12.0f}")
    if debian is not None:
        mib = rows[0][1]
        print(f"{'Debian rosbag':<16}{mib:>10.1f}{'':>12}{'':>13}"
              f"{mib / debian['seconds']:>11.1f}{debian['messages'] / debian['seconds']:>12.0f}"
              "  (same rec.bag, python3-rosbag 1.15 read_messages)")  # fmt: skip
        ratio = (rows[0][5]) / (debian["messages"] / debian["seconds"])
        print(f"roverlab .bag read / Debian rosbag read: {ratio:.2f}x (messages/s)")
    else:
        print("Debian rosbag: not installed (scripts/install-system-deps.sh)")
    print(f"convert .bag -> .mcap: peak Python allocation {peak / 2**20:.1f} MiB "
          f"for a {rows[0][1]:.1f} MiB bag")  # fmt: skip


if __name__ == "__main__":
    main()
