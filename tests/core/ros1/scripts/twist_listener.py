"""A real rospy subscriber (run by /usr/bin/python3): one line ``LINEAR_X ANGULAR_Z`` per
geometry_msgs/Twist on a topic (default cmd_vel). Prints ``ready`` once subscribed."""

import sys

import rospy
from geometry_msgs.msg import Twist

rospy.init_node("twist_listener", anonymous=True)
topic = sys.argv[1] if len(sys.argv) > 1 else "cmd_vel"
rospy.Subscriber(topic, Twist, lambda m: print(f"{m.linear.x:.2f} {m.angular.z:.2f}", flush=True))
print("ready", flush=True)
rospy.spin()
