"""A real rospy talker (run by /usr/bin/python3): std_msgs/String on a topic until killed."""

import sys

import rospy
from std_msgs.msg import String

topic = sys.argv[1] if len(sys.argv) > 1 else "chatter"
rospy.init_node("talker", anonymous=True)
pub = rospy.Publisher(topic, String, queue_size=10)
rate = rospy.Rate(20)
n = 0
while not rospy.is_shutdown():
    pub.publish(String(data=f"hello {n}"))
    if n % 10 == 0:
        rospy.loginfo("talker said hello %d", n)
    n += 1
    rate.sleep()
