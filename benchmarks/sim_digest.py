"""Digest of every message a seeded simulation publishes, topic by topic.

    python benchmarks/sim_digest.py [--seconds S] [--robots mybot,mbot,mycar]
        [--worlds maze,office] [--no-cameras]

For each robot and world: a seeded :class:`~roverlab.sim.app.Simulation`, an in-process
subscriber on every topic of the graph (so /tf and the cameras are built too), a driver
that changes its ``/cmd_vel`` every second (it turns, drives into walls and backs off),
and S simulated seconds. Prints one line per topic: the message count and a SHA-256 of
the CDR bytes of every message, taken when it is delivered; and a second digest of the
same messages taken again at the end of the run, from the references the subscriber
kept, which must equal the first (a message changed after delivery, e.g. through an
array shared between messages, would show here).

Run it on two checkouts (``PYTHONPATH=<checkout>/src``) and diff the output: a change
meant to be a pure speed-up must leave every line the same.
"""

from __future__ import annotations

import argparse
import hashlib
from pathlib import Path
from typing import Any

import roverlab
from roverlab.core import Context
from roverlab.msgs import Twist, serialize
from roverlab.sim.app import Simulation

# /robot_description names the xacro file it came from: compare checkouts without it
CHECKOUT = str(Path(roverlab.__file__).resolve().parent.parent)
# (v, w) per second of the run, cycled
COMMANDS = [(0.3, 0.0), (0.2, 0.6), (-0.2, 0.0), (0.5, -0.4), (0.0, 1.2), (0.4, 0.1)]


def _bytes(msg: Any) -> bytes:
    data = getattr(msg, "data", None)
    if isinstance(data, str):  # a std_msgs/String: the checkout's path taken out
        return data.replace(CHECKOUT, "<src>").encode()
    return serialize(msg)


def digest_run(robot: str, world: str, seconds: float, cameras: bool) -> dict[str, str]:
    ctx = Context()
    Simulation(context=ctx, world=world, robot=robot, seed=7, cameras=cameras)
    node = ctx.create_node("digest")
    kept: dict[str, list[Any]] = {}
    hashes: dict[str, Any] = {}

    for name, topic in sorted(ctx.graph.topics.items()):
        if name == "/cmd_vel":
            continue
        kept[name] = []
        hashes[name] = hashlib.sha256()

        def cb(msg: Any, name: str = name) -> None:
            kept[name].append(msg)
            hashes[name].update(_bytes(msg))

        node.create_subscription(topic.typename, name, cb, 1000)

    pub = node.create_publisher(Twist, "/cmd_vel", 10)
    step = [0]

    def drive() -> None:
        v, w = COMMANDS[step[0] % len(COMMANDS)]
        step[0] += 1
        pub.publish(Twist(linear_x=v, angular_z=w))

    drive()
    node.create_timer(1.0, drive)
    ctx.spin_for(seconds)
    out: dict[str, str] = {}
    for name, msgs in kept.items():
        again = hashlib.sha256()
        for m in msgs:
            again.update(_bytes(m))
        first = hashes[name].hexdigest()[:16]
        second = again.hexdigest()[:16]
        out[name] = f"{len(msgs):6d} {first}" + ("" if first == second else f" CHANGED {second}")
    ctx.shutdown()
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--robots", default="mybot,mbot,mycar")
    ap.add_argument("--worlds", default="maze,office")
    ap.add_argument("--no-cameras", action="store_true")
    args = ap.parse_args()
    for robot in args.robots.split(","):
        for world in args.worlds.split(","):
            for topic, line in digest_run(robot, world, args.seconds, not args.no_cameras).items():
                print(f"{robot:6s} {world:7s} {topic:32s} {line}")


if __name__ == "__main__":
    main()
