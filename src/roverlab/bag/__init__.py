"""Recording, playing, converting and repairing bags (rosbag / ros2 bag): ROS 1 ``.bag``,
MCAP and ROS 2 bag folders, the format chosen by the file's extension."""

from roverlab.bag.errors import BagError
from roverlab.bag.recorder import BagRecorder

__all__ = ["BagError", "BagRecorder"]
