"""A real rospy listener (run by /usr/bin/python3): prints the first N messages, exits 0."""

import sys
import threading

import rospy
from std_msgs.msg import String

topic = sys.argv[1] if len(sys.argv) > 1 else "chatter"
count = int(sys.argv[2]) if len(sys.argv) > 2 else 3
done = threading.Event()
got = []


def on_msg(msg):
    got.append(msg.data)
    print(msg.data, flush=True)
    if len(got) >= count:
        done.set()


rospy.init_node("listener", anonymous=True)
rospy.Subscriber(topic, String, on_msg)
ok = done.wait(20.0)
rospy.signal_shutdown("done")
sys.exit(0 if ok else 1)
