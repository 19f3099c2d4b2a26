"""Recording and playing back topics (rosbag / ros2 bag)."""

from roverlab.bag.recorder import BagError, McapRecorder

__all__ = ["BagError", "McapRecorder"]
