"""A real rospy service (run by /usr/bin/python3): std_srvs/SetBool on a name; the answer
echoes the request; a request of data=false fails (raises), as a server's error."""

import sys

import rospy
from std_srvs.srv import SetBool, SetBoolResponse


def handle(req):
    if not req.data:
        raise rospy.ServiceException("refusing false")
    return SetBoolResponse(success=True, message="rospy got true")


rospy.init_node("set_bool_server", anonymous=True)
rospy.Service(sys.argv[1] if len(sys.argv) > 1 else "set_bool", SetBool, handle)
print("ready", flush=True)
rospy.spin()
