#!/usr/bin/env python
import rospy
from geometry_msgs.msg import Twist

rospy.init_node('py2_teleop')
print "Reading from the keyboard and publishing to Twist!"
