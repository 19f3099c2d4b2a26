"""A real actionlib move_base_msgs/MoveBase server (run by /usr/bin/python3 with Debian's
rospy and actionlib) standing in for move_base: each goal gets one feedback (the goal's
own pose) and succeeds, or is aborted when its x is negative; one line per goal on
stdout (``goal FRAME X Y``). Prints ``ready`` once it serves."""

import time

import rospy
from move_base_msgs.msg import MoveBaseAction, MoveBaseFeedback, MoveBaseResult

import actionlib

rospy.init_node("move_base", anonymous=False)


def execute(goal):
    pose = goal.target_pose
    x, y = pose.pose.position.x, pose.pose.position.y
    print(f"goal {pose.header.frame_id} {x:.2f} {y:.2f}", flush=True)
    # ROS 1 delivers nothing to a subscriber whose TCPROS link is still being set up, and a
    # client's wait_for_server waits for the status and goal links only: let the client's
    # feedback link come up first (a goal sent at once may otherwise miss its feedback)
    feedback = server.action_server.feedback_pub
    end = time.monotonic() + 5.0
    while feedback.get_num_connections() == 0 and time.monotonic() < end:
        time.sleep(0.02)
    server.publish_feedback(MoveBaseFeedback(base_position=pose))
    # feedback and result travel on two TCPROS links, so a result published at once can
    # overtake the feedback and end the client's wait first; a real move_base sends
    # feedback for the whole drive before its result
    time.sleep(0.3)
    if pose.pose.position.x < 0:
        server.set_aborted(MoveBaseResult(), "negative x")
    else:
        server.set_succeeded(MoveBaseResult())


server = actionlib.SimpleActionServer("move_base", MoveBaseAction, execute, auto_start=False)
server.start()
print("ready", flush=True)
rospy.spin()
