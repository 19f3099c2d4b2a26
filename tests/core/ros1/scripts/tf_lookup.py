"""Real tf2_ros (run by /usr/bin/python3): look up TARGET -> SOURCE, print the translation."""

import sys

import rospy
import tf2_ros

rospy.init_node("tf_lookup", anonymous=True)
buf = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(buf)
t = buf.lookup_transform(sys.argv[1], sys.argv[2], rospy.Time(0), rospy.Duration(20.0))
tr = t.transform.translation
print(f"{t.header.frame_id} -> {t.child_frame_id}: {tr.x:.3f} {tr.y:.3f} {tr.z:.3f}", flush=True)
