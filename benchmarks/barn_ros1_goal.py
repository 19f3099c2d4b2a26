#!/usr/bin/python3
"""BARN's goal to move_base through Debian's real rospy actionlib, for
benchmarks/barn_ros1_baseline.py (run with /usr/bin/python3, never the venv's python).

    barn_ros1_goal.py X Y YAW     (the goal in the odom frame)

Prints one JSON object a line on stdout: ``{"event": "sent", "t": SIM_S}`` once the goal is
out, ``{"event": "recovery", ...}`` for each of move_base's ``recovery_status`` messages,
``{"event": "state", "state": NAME, "text": ...}`` on every change of the goal's state;
a line ``cancel`` on stdin cancels the goal. Exits when the goal is done (or on SIGTERM).
"""

import json
import math
import sys
import threading

import rospy
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal, RecoveryStatus

import actionlib

NAMES = {v: k for k, v in vars(GoalStatus).items() if k.isupper() and isinstance(v, int)}
lock = threading.Lock()


def say(**kw: object) -> None:
    with lock:
        sys.stdout.write(json.dumps(kw) + "\n")
        sys.stdout.flush()


def main() -> int:
    x, y, yaw = (float(v) for v in sys.argv[1:4])
    rospy.init_node("barn_goal", disable_signals=True)
    rospy.Subscriber(
        "move_base/recovery_status",
        RecoveryStatus,
        lambda m: say(
            event="recovery",
            t=rospy.get_time(),
            index=m.current_recovery_number,
            total=m.total_number_of_recoveries,
            name=m.recovery_behavior_name,
        ),
    )
    client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
    if not client.wait_for_server(rospy.Duration(120.0)):
        say(event="error", text="move_base's action server did not come up")
        return 1
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = "odom"
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose.position.x = x
    goal.target_pose.pose.position.y = y
    goal.target_pose.pose.orientation.z = math.sin(yaw / 2)
    goal.target_pose.pose.orientation.w = math.cos(yaw / 2)
    client.send_goal(goal)
    say(event="sent", t=rospy.get_time())

    def cancel() -> None:
        for line in sys.stdin:
            if line.strip() == "cancel":
                client.cancel_goal()

    threading.Thread(target=cancel, daemon=True).start()
    last = None
    while not rospy.is_shutdown():
        state = client.get_state()
        if state != last:
            last = state
            say(
                event="state",
                t=rospy.get_time(),
                state=NAMES.get(state, str(state)),
                text=client.get_goal_status_text(),
            )
        if state not in (GoalStatus.PENDING, GoalStatus.ACTIVE):
            return 0
        rospy.sleep(0.05)
    return 0


if __name__ == "__main__":
    sys.exit(main())
