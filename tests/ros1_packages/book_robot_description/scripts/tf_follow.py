#!/usr/bin/env python
# -*- coding: utf-8 -*-
# A ROS 1 book-style tf script: broadcast a frame, listen for it, publish a Marker there.
import math

import rospy
import tf
from tf.transformations import euler_from_quaternion, quaternion_from_euler
from visualization_msgs.msg import Marker

if __name__ == "__main__":
    rospy.init_node("tf_follow")
    broadcaster = tf.TransformBroadcaster()
    listener = tf.TransformListener()
    marker_pub = rospy.Publisher("visualization_marker", Marker, queue_size=10)
    q = quaternion_from_euler(0, 0, math.pi / 2)
    rate = rospy.Rate(20.0)
    trans = rot = None
    for _ in range(40):
        broadcaster.sendTransform((1.0, 2.0, 0.0), q, rospy.Time.now(), "/carrot", "/world")
        try:
            listener.waitForTransform("/world", "/carrot", rospy.Time(0), rospy.Duration(0.1))
            (trans, rot) = listener.lookupTransform("/world", "/carrot", rospy.Time(0))
            break
        except (
            tf.LookupException,
            tf.ConnectivityException,
            tf.ExtrapolationException,
            tf.Exception,
        ):
            rate.sleep()
    marker = Marker()
    marker.header.frame_id = "world"
    marker.type = Marker.SPHERE
    marker.pose.position.x, marker.pose.position.y = trans[0], trans[1]
    marker.scale.x = marker.scale.y = marker.scale.z = 0.2
    marker.color.a = 1.0
    marker_pub.publish(marker)
    yaw = euler_from_quaternion(rot)[2]
    print("carrot at %.2f %.2f yaw %.2f" % (trans[0], trans[1], yaw))
