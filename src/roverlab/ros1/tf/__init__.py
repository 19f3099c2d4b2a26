"""tf for ROS 1 scripts: ``tf.transformations`` (Euler angles and quaternions).

``tf.TransformListener`` / ``TransformBroadcaster`` are not provided: use tf2's Python
API in roverlab (:mod:`roverlab.tf`) from a node.
"""

from roverlab.ros1.tf import transformations

__all__ = ["transformations"]
