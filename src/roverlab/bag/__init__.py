"""Recording and playing back topics (rosbag / ros2 bag)."""

from roverlab.bag.recorder import McapRecorder

__all__ = ["McapRecorder"]
