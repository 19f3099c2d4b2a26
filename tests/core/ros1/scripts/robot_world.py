"""A stand-in ROS 1 robot of real nodes (run by /usr/bin/python3 with Debian's rospy): sets
/robot_description (a base and a lidar on a fixed joint, for the real robot_state_publisher),
publishes a latched 8 x 6 m walled /map, /odom -> base_link and map -> odom on /tf, and a
360-beam /scan of the room's walls from the robot's pose, at 10 Hz. Prints READY."""

import math

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import OccupancyGrid
from sensor_msgs.msg import LaserScan

URDF = """<robot name="box_bot">
  <link name="base_link"><visual><geometry><box size="0.5 0.4 0.2"/></geometry>
    <material name="blue"><color rgba="0.1 0.3 0.9 1"/></material></visual></link>
  <link name="laser"><visual><geometry><cylinder radius="0.06" length="0.08"/></geometry>
    </visual></link>
  <joint name="laser_joint" type="fixed"><parent link="base_link"/><child link="laser"/>
    <origin xyz="0.15 0 0.15"/></joint>
</robot>"""
RES, W, H = 0.05, 160, 120  # 8 x 6 m, origin (-4, -3)

rospy.init_node("robot_world")
rospy.set_param("/robot_description", URDF)
grid = OccupancyGrid()
grid.header.frame_id = "map"
grid.info.resolution, grid.info.width, grid.info.height = RES, W, H
grid.info.origin.position.x, grid.info.origin.position.y = -4.0, -3.0
grid.info.origin.orientation.w = 1.0
cells = [0] * (W * H)
for r in range(H):
    for c in range(W):
        if r < 2 or c < 2 or r >= H - 2 or c >= W - 2 or (50 <= c < 60 and 40 <= r < 80):
            cells[r * W + c] = 100
grid.data = cells
map_pub = rospy.Publisher("/map", OccupancyGrid, queue_size=1, latch=True)
scan_pub = rospy.Publisher("/scan", LaserScan, queue_size=5)
tf_pub = tf2_ros.TransformBroadcaster()
grid.header.stamp = rospy.Time.now()
map_pub.publish(grid)
print("READY", flush=True)


def tf(parent, child, x, y, stamp):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id, t.header.stamp = parent, child, stamp
    t.transform.translation.x, t.transform.translation.y = x, y
    t.transform.rotation.w = 1.0
    return t


def wall_range(x, y, a):
    """Distance from (x, y) along angle a to the room's walls (inner faces at +-3.9, +-2.9)."""
    best = 10.0
    dx, dy = math.cos(a), math.sin(a)
    for bound, d, p in ((3.9, dx, x), (-3.9, dx, x), (2.9, dy, y), (-2.9, dy, y)):
        if abs(d) > 1e-9 and (bound - p) / d > 0:
            best = min(best, (bound - p) / d)
    return best


rate = rospy.Rate(10)
while not rospy.is_shutdown():
    now = rospy.Time.now()
    x = 1.5 + 0.5 * math.sin(now.to_sec() / 3.0)
    tf_pub.sendTransform([tf("map", "odom", 0.2, 0.0, now), tf("odom", "base_link", x, 0.0, now)])
    scan = LaserScan()
    scan.header.frame_id, scan.header.stamp = "laser", now
    scan.angle_min, scan.angle_max = -math.pi, math.pi
    scan.angle_increment = 2 * math.pi / 360
    scan.range_min, scan.range_max = 0.1, 10.0
    lx = 0.2 + x + 0.15
    scan.ranges = [
        wall_range(lx, 0.0, scan.angle_min + i * scan.angle_increment) for i in range(360)
    ]
    scan_pub.publish(scan)
    rate.sleep()
