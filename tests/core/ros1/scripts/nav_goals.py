"""An rbx1-style navigation script (run by /usr/bin/python3 with Debian's rospy and
actionlib): send each goal ``x,y,yaw`` of the command line to move_base through
actionlib.SimpleActionClient, wait for its result, print one line per goal; exit 0 when
every goal succeeded."""

import math
import sys

import rospy
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import Point, Pose, Quaternion
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

import actionlib

rospy.init_node("nav_goals", anonymous=True)
client = actionlib.SimpleActionClient("move_base", MoveBaseAction)
if not client.wait_for_server(rospy.Duration(60)):
    print("no move_base action server", flush=True)
    sys.exit(2)
print("connected to move_base", flush=True)
ok = True
for arg in sys.argv[1:]:
    x, y, yaw = (float(v) for v in arg.split(","))
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = "map"
    goal.target_pose.header.stamp = rospy.Time.now()
    goal.target_pose.pose = Pose(
        Point(x, y, 0.0), Quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    )
    client.send_goal(goal)
    finished = client.wait_for_result(rospy.Duration(120))
    state = client.get_state()
    print(f"goal {arg}: {'SUCCEEDED' if state == GoalStatus.SUCCEEDED else state}", flush=True)
    ok = ok and finished and state == GoalStatus.SUCCEEDED
sys.exit(0 if ok else 1)
