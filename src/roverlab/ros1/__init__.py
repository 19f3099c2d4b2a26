"""ROS 1 (rospy) scripts without ROS: ``roverlab run SCRIPT.py`` runs them unchanged.

* :mod:`roverlab.ros1.importer`: ``import rospy``, ``import actionlib``, ``import roslib``,
  ``from tf.transformations import ...``, ``from geometry_msgs.msg import Twist``,
  ``from std_srvs.srv import Empty``, ``from move_base_msgs.msg import MoveBaseAction``
  (and a user's own message packages on the package path) resolve to roverlab;
* :mod:`roverlab.ros1.rospy`: rospy's API on roverlab's runtime;
* :mod:`roverlab.ros1.actionlib`: actionlib with rospy's signatures;
* :mod:`roverlab.ros1.messages`: message and service classes with genpy's constructors;
* :mod:`roverlab.ros1.runner`: runs a script (what ``roverlab run`` does).
"""

from roverlab.ros1.importer import install, uninstall
from roverlab.ros1.runner import run_script

__all__ = ["install", "run_script", "uninstall"]
