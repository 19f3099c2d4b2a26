"""A rospy script for `roverlab run`: reads /greeting from the parameter server, sets /answer."""

import rospy

rospy.init_node("params_rw")
print("greeting:", rospy.get_param("/greeting"), flush=True)
rospy.set_param("/answer", 42)
