"""The rospy side of benchmarks/ros1_wire.py (run by Debian's /usr/bin/python3, not the venv).

ros1_wire_rospy.py flood TOPIC N     publish N 720-beam LaserScans as fast as rospy can
                                     (each publish serialises the message, as rospy does)
ros1_wire_rospy.py count TOPIC N     count LaserScans; print JSON {count, seconds}
ros1_wire_rospy.py count_any TOPIC N count messages as rospy.AnyMsg (no decoding): a
                                     receiver cheap enough that the sender sets the pace
ros1_wire_rospy.py echo IN OUT       republish every LaserScan of IN on OUT
ros1_wire_rospy.py ping OUT IN N     round trips OUT -> IN; print JSON {rtt_ms: [...]}
"""

import json
import sys
import threading
import time

import rospy
from sensor_msgs.msg import LaserScan


def scan(seq):
    msg = LaserScan()
    msg.header.seq = seq
    msg.header.frame_id = "laser"
    msg.angle_min, msg.angle_max = -3.14159, 3.14159
    msg.angle_increment = 6.28318 / 720
    msg.range_min, msg.range_max = 0.1, 30.0
    msg.ranges = [1.0 + 0.001 * i for i in range(720)]
    msg.intensities = [0.0] * 720
    return msg


def wait_connected(pub):
    while pub.get_num_connections() == 0 and not rospy.is_shutdown():
        time.sleep(0.01)
    time.sleep(0.3)


def main():
    mode = sys.argv[1]
    rospy.init_node(f"bench_{mode}", anonymous=True, disable_signals=True)
    if mode == "flood":
        topic, n = sys.argv[2], int(sys.argv[3])
        pub = rospy.Publisher(topic, LaserScan, queue_size=n)
        msg = scan(0)
        wait_connected(pub)
        t0 = time.perf_counter()
        for _ in range(n):
            pub.publish(msg)
        print(json.dumps({"sent": n, "seconds": time.perf_counter() - t0}), flush=True)
        time.sleep(2.0)
    elif mode in ("count", "count_any"):
        topic, n = sys.argv[2], int(sys.argv[3])
        times = []
        done = threading.Event()

        def on_scan(_msg):
            times.append(time.perf_counter())
            if len(times) >= n:
                done.set()

        kind = LaserScan if mode == "count" else rospy.AnyMsg
        rospy.Subscriber(topic, kind, on_scan, queue_size=None)
        print("ready", flush=True)
        while not done.wait(0.2):
            if times and time.perf_counter() - times[-1] > 2.0:
                break
        secs = times[-1] - times[0] if len(times) > 1 else 0.0
        print(json.dumps({"count": len(times), "seconds": secs}), flush=True)
    elif mode == "echo":
        pub = rospy.Publisher(sys.argv[3], LaserScan, queue_size=10, tcp_nodelay=True)
        rospy.Subscriber(sys.argv[2], LaserScan, pub.publish, queue_size=10, tcp_nodelay=True)
        print("ready", flush=True)
        rospy.spin()
    elif mode == "ping":
        out, inp, n = sys.argv[2], sys.argv[3], int(sys.argv[4])
        got = threading.Event()
        rospy.Subscriber(inp, LaserScan, lambda _m: got.set(), queue_size=10, tcp_nodelay=True)
        pub = rospy.Publisher(out, LaserScan, queue_size=10, tcp_nodelay=True)
        wait_connected(pub)
        msg = scan(0)
        # wait until the echo's publisher is connected back to us
        while not got.is_set():
            pub.publish(msg)
            got.wait(0.1)
        rtts = []
        for _ in range(n):
            got.clear()
            t0 = time.perf_counter()
            pub.publish(msg)
            if got.wait(2.0):
                rtts.append((time.perf_counter() - t0) * 1000.0)
        print(json.dumps({"rtt_ms": rtts}), flush=True)
    rospy.signal_shutdown("done")


if __name__ == "__main__":
    main()
