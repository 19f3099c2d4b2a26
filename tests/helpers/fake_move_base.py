"""A stand-in move_base for rospy script tests: ``python fake_move_base.py BEHAVIOUR RATE``.

It runs its own sim clock paced at RATE x real time (publishing /clock) and serves the
``move_base`` action (move_base_msgs/MoveBaseAction): ``succeed`` ends each goal SUCCEEDED
after 2 s of sim time (feedback every 0.5 s), ``abort`` ABORTED after 1 s, ``hang`` never
ends a goal (the client's timeout must). Prints READY, then one line per goal received
and per cancel, and listens to /cmd_vel (printing ``cmd_vel X Z``).
"""

from __future__ import annotations

import sys
from typing import Any

from child_main import echo_cmd_vel, serve_ready

from roverlab.actionlib import SimpleActionServer
from roverlab.core import Context


def main(behaviour: str, rate: float) -> None:
    ctx = Context(clock="paced", rate=rate)
    node = ctx.create_node("move_base")
    server = SimpleActionServer(node, "move_base", "move_base_msgs/MoveBaseAction")
    state: dict[str, Any] = {"goal": None, "since": 0.0}

    def on_goal() -> None:
        goal = server.accept_new_goal()
        p = goal.target_pose.pose.position
        print(f"goal {goal.target_pose.header.frame_id} {p.x:.3f} {p.y:.3f}", flush=True)
        state.update(goal=goal, since=ctx.now().seconds)

    def on_preempt() -> None:
        print("preempt", flush=True)

    def step() -> None:
        if not server.is_active():
            return
        if server.is_preempt_requested():
            server.set_preempted()
            return
        elapsed = ctx.now().seconds - state["since"]
        server.publish_feedback({"base_position": state["goal"].target_pose})
        if behaviour == "succeed" and elapsed >= 2.0:
            server.set_succeeded(None, "Goal reached.")
        elif behaviour == "abort" and elapsed >= 1.0:
            server.set_aborted(None, "Failed to find a valid plan.")

    server.register_goal_callback(on_goal)
    server.register_preempt_callback(on_preempt)
    node.create_timer(0.5, step)

    echo_cmd_vel(node)
    serve_ready(ctx)


if __name__ == "__main__":
    main(sys.argv[1], float(sys.argv[2]))
