"""A roverlab process for transport tests: ``python node_proc.py MODE``.

Modes: talker (/chatter at 50 Hz), pong (echo /ping to /pong), clock (paced sim
publishing /clock), latched (/map latched once), listener (print /cmd_vel as lines),
services (/add_two_ints, and /fail whose callback raises), fibonacci (the
actionlib_tutorials Fibonacci action on /fibonacci, one step per 50 ms; order 13 aborts).
Prints READY on stdout once its nodes exist.
"""

from __future__ import annotations

import sys
from typing import Any

from child_main import echo_cmd_vel, serve_ready

from roverlab.actionlib import SimpleActionServer
from roverlab.core import Context, QoSProfile
from roverlab.msgs import String


def _fibonacci_server(node: Any) -> None:
    server = SimpleActionServer(node, "/fibonacci", "actionlib_tutorials/FibonacciAction")
    state: dict[str, Any] = {"order": 0, "seq": []}

    def on_goal() -> None:
        state["order"] = int(server.accept_new_goal().order)
        state["seq"] = [0, 1]

    def step() -> None:
        if not server.is_active():
            return
        seq = state["seq"]
        if server.is_preempt_requested():
            server.set_preempted({"sequence": seq}, "canceled")
        elif state["order"] == 13:
            server.set_aborted(None, "13 is unlucky")
        elif len(seq) - 2 >= state["order"]:
            server.set_succeeded({"sequence": seq}, "done")
        else:
            seq.append(seq[-1] + seq[-2])
            server.publish_feedback({"sequence": seq})

    server.register_goal_callback(on_goal)
    node.create_timer(0.05, step)


def main(mode: str) -> None:
    ctx = Context(clock="paced" if mode == "clock" else "wall", publish_clock=mode == "clock")
    node = ctx.create_node(f"proc_{mode}")
    node.declare_parameter("gain", 1.5)
    if mode == "talker":
        pub = node.create_publisher(String, "/chatter", 10)
        count = [0]

        def tick() -> None:
            pub.publish(String(data=f"hello world {count[0]}"))
            count[0] += 1

        node.create_timer(0.02, tick)
    elif mode == "pong":
        pong = node.create_publisher(String, "/pong", 1000)
        node.create_subscription(String, "/ping", pong.publish, 1000)
    elif mode == "latched":
        pub = node.create_publisher(
            String, "/map", QoSProfile(depth=1, durability="transient_local")
        )
        pub.publish(String(data="the map"))
    elif mode == "services":

        def add(req: Any, resp: Any) -> Any:
            resp.sum = req.a + req.b
            return resp

        def fail(req: Any, resp: Any) -> Any:
            raise RuntimeError("the callback broke")

        node.create_service("rospy_tutorials/AddTwoInts", "/add_two_ints", add)
        node.create_service("std_srvs/Trigger", "/fail", fail)
    elif mode == "fibonacci":
        _fibonacci_server(node)
    elif mode == "listener":
        echo_cmd_vel(node)
    serve_ready(ctx)


if __name__ == "__main__":
    main(sys.argv[1])
