#!/usr/bin/env python
# A ROS 1 book-style cv_bridge round trip: bgr8 image in, mono8 and rgb8 out.
import numpy as np
import rospy
from cv_bridge import CvBridge, CvBridgeError

rospy.init_node("image_flip")
bridge = CvBridge()
bgr = np.zeros((4, 6, 3), dtype=np.uint8)
bgr[:, :, 2] = 200  # red in BGR order
msg = bridge.cv2_to_imgmsg(bgr, "bgr8")
rgb = bridge.imgmsg_to_cv2(msg, "rgb8")
mono = bridge.imgmsg_to_cv2(msg, "mono8")
try:
    bridge.imgmsg_to_cv2(msg, "32FC1")
    failed = False
except CvBridgeError:
    failed = True
print("%s %d %d %d %s" % (msg.encoding, rgb[0, 0, 0], rgb[0, 0, 2], mono[0, 0], failed))
