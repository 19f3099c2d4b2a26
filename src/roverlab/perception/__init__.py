"""Perception: detectors over camera images (pure algorithms + their ROS-named nodes).

* :mod:`roverlab.perception.face_detector`: the ROS people stack's ``face_detector``
  (OpenCV Haar cascades; RGB-only, or RGB-D where a depth image gives faces a size and a
  3-D position).
"""

from __future__ import annotations

from roverlab.perception.errors import PerceptionError

__all__ = ["PerceptionError"]
