"""The rosbags message classes of :mod:`roverlab.msgs`, under their ROS short names.

Use these for type annotations and ``isinstance`` narrowing that mypy understands::

    from roverlab.msgs import classes as mc

    def on_scan(scan: mc.LaserScan) -> None: ...

To build messages use the factories of :mod:`roverlab.msgs` (``msgs.LaserScan(...)``), which
fill defaults; these classes need every field. Where two packages share a short name the ROS 2
one is kept: ``GoalStatus``/``GoalStatusArray`` are ``action_msgs`` (not ``actionlib_msgs``),
``KeyValue`` is ``diagnostic_msgs``, ``Time``/``Duration`` are ``builtin_interfaces``.
"""

from __future__ import annotations

from rosbags.typesys.stores import ros2_jazzy as _j

# builtin_interfaces
Time = _j.builtin_interfaces__msg__Time
Duration = _j.builtin_interfaces__msg__Duration

# std_msgs
Header = _j.std_msgs__msg__Header
String = _j.std_msgs__msg__String
Bool = _j.std_msgs__msg__Bool
Byte = _j.std_msgs__msg__Byte
Char = _j.std_msgs__msg__Char
Empty = _j.std_msgs__msg__Empty
ColorRGBA = _j.std_msgs__msg__ColorRGBA
Float32 = _j.std_msgs__msg__Float32
Float64 = _j.std_msgs__msg__Float64
Int8 = _j.std_msgs__msg__Int8
Int16 = _j.std_msgs__msg__Int16
Int32 = _j.std_msgs__msg__Int32
Int64 = _j.std_msgs__msg__Int64
UInt8 = _j.std_msgs__msg__UInt8
UInt16 = _j.std_msgs__msg__UInt16
UInt32 = _j.std_msgs__msg__UInt32
UInt64 = _j.std_msgs__msg__UInt64
Float32MultiArray = _j.std_msgs__msg__Float32MultiArray
Float64MultiArray = _j.std_msgs__msg__Float64MultiArray
MultiArrayLayout = _j.std_msgs__msg__MultiArrayLayout
MultiArrayDimension = _j.std_msgs__msg__MultiArrayDimension

# geometry_msgs
Point = _j.geometry_msgs__msg__Point
Point32 = _j.geometry_msgs__msg__Point32
PointStamped = _j.geometry_msgs__msg__PointStamped
Quaternion = _j.geometry_msgs__msg__Quaternion
QuaternionStamped = _j.geometry_msgs__msg__QuaternionStamped
Vector3 = _j.geometry_msgs__msg__Vector3
Vector3Stamped = _j.geometry_msgs__msg__Vector3Stamped
Pose = _j.geometry_msgs__msg__Pose
Pose2D = _j.geometry_msgs__msg__Pose2D
PoseStamped = _j.geometry_msgs__msg__PoseStamped
PoseWithCovariance = _j.geometry_msgs__msg__PoseWithCovariance
PoseWithCovarianceStamped = _j.geometry_msgs__msg__PoseWithCovarianceStamped
PoseArray = _j.geometry_msgs__msg__PoseArray
Twist = _j.geometry_msgs__msg__Twist
TwistStamped = _j.geometry_msgs__msg__TwistStamped
TwistWithCovariance = _j.geometry_msgs__msg__TwistWithCovariance
TwistWithCovarianceStamped = _j.geometry_msgs__msg__TwistWithCovarianceStamped
Accel = _j.geometry_msgs__msg__Accel
AccelStamped = _j.geometry_msgs__msg__AccelStamped
AccelWithCovariance = _j.geometry_msgs__msg__AccelWithCovariance
AccelWithCovarianceStamped = _j.geometry_msgs__msg__AccelWithCovarianceStamped
Wrench = _j.geometry_msgs__msg__Wrench
WrenchStamped = _j.geometry_msgs__msg__WrenchStamped
Transform = _j.geometry_msgs__msg__Transform
TransformStamped = _j.geometry_msgs__msg__TransformStamped
Polygon = _j.geometry_msgs__msg__Polygon
PolygonStamped = _j.geometry_msgs__msg__PolygonStamped

# sensor_msgs
LaserScan = _j.sensor_msgs__msg__LaserScan
Imu = _j.sensor_msgs__msg__Imu
Image = _j.sensor_msgs__msg__Image
CompressedImage = _j.sensor_msgs__msg__CompressedImage
CameraInfo = _j.sensor_msgs__msg__CameraInfo
RegionOfInterest = _j.sensor_msgs__msg__RegionOfInterest
PointCloud2 = _j.sensor_msgs__msg__PointCloud2
PointField = _j.sensor_msgs__msg__PointField
JointState = _j.sensor_msgs__msg__JointState
Range = _j.sensor_msgs__msg__Range
NavSatFix = _j.sensor_msgs__msg__NavSatFix
NavSatStatus = _j.sensor_msgs__msg__NavSatStatus
Joy = _j.sensor_msgs__msg__Joy
BatteryState = _j.sensor_msgs__msg__BatteryState
MagneticField = _j.sensor_msgs__msg__MagneticField
Temperature = _j.sensor_msgs__msg__Temperature

# nav_msgs
Odometry = _j.nav_msgs__msg__Odometry
OccupancyGrid = _j.nav_msgs__msg__OccupancyGrid
MapMetaData = _j.nav_msgs__msg__MapMetaData
Path = _j.nav_msgs__msg__Path
GridCells = _j.nav_msgs__msg__GridCells

# tf2_msgs
TFMessage = _j.tf2_msgs__msg__TFMessage

# rosgraph_msgs
Clock = _j.rosgraph_msgs__msg__Clock

# visualization_msgs
Marker = _j.visualization_msgs__msg__Marker
MarkerArray = _j.visualization_msgs__msg__MarkerArray

# action_msgs
GoalInfo = _j.action_msgs__msg__GoalInfo
GoalStatus = _j.action_msgs__msg__GoalStatus
GoalStatusArray = _j.action_msgs__msg__GoalStatusArray

# unique_identifier_msgs
UUID = _j.unique_identifier_msgs__msg__UUID

# diagnostic_msgs
DiagnosticArray = _j.diagnostic_msgs__msg__DiagnosticArray
DiagnosticStatus = _j.diagnostic_msgs__msg__DiagnosticStatus
KeyValue = _j.diagnostic_msgs__msg__KeyValue

# rcl_interfaces
Log = _j.rcl_interfaces__msg__Log
