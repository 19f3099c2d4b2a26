"""ROS 1 actionlib on roverlab's topics: goals, cancels, status, feedback and results.

The wire protocol is actionlib's, so ``roverlab topic echo /move_base/status`` shows what
``rostopic echo`` shows: for action ``NAME`` of type ``pkg/Name``,

==================  ==========================================  =========================
topic               type                                        from
==================  ==========================================  =========================
``NAME/goal``       ``pkg/NameActionGoal`` (header, goal_id,    client
                    goal)
``NAME/cancel``     ``actionlib_msgs/GoalID``                   client
``NAME/status``     ``actionlib_msgs/GoalStatusArray``          server (latched, 5 Hz)
``NAME/feedback``   ``pkg/NameActionFeedback``                  server
``NAME/result``     ``pkg/NameActionResult``                    server
==================  ==========================================  =========================

Servers: :class:`ActionServer` (goal handles) and :class:`SimpleActionServer` (one goal at a
time). Clients: :class:`ActionClient` and :class:`SimpleActionClient`. Every class takes the
:class:`~roverlab.core.Node` it works on as its first argument; ``roverlab run`` gives rospy
scripts the ROS 1 signatures (``actionlib.SimpleActionClient("move_base", MoveBaseAction)``).
"""

from roverlab.actionlib.client import ActionClient, ClientGoalHandle, CommState
from roverlab.actionlib.server import ActionServer, ServerGoalHandle
from roverlab.actionlib.simple_client import SimpleActionClient, SimpleGoalState
from roverlab.actionlib.simple_server import SimpleActionServer
from roverlab.actionlib.status import (
    STATUS_NAMES,
    TERMINAL_STATES,
    ActionError,
    GoalIDGenerator,
    GoalStatus,
    status_name,
)

__all__ = [
    "STATUS_NAMES",
    "TERMINAL_STATES",
    "ActionClient",
    "ActionError",
    "ActionServer",
    "ClientGoalHandle",
    "CommState",
    "GoalIDGenerator",
    "GoalStatus",
    "ServerGoalHandle",
    "SimpleActionClient",
    "SimpleActionServer",
    "SimpleGoalState",
    "status_name",
]
