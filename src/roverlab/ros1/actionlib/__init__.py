"""actionlib for ROS 1 scripts: the classes of :mod:`roverlab.actionlib` with rospy's
signatures (no node argument: the script's ``rospy.init_node`` node) and Duration
timeouts in ROS time. Waits end (False) when the node shuts down, as in rospy."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from roverlab import actionlib as _core
from roverlab.actionlib import CommState, SimpleGoalState, status_name
from roverlab.ros1.messages import message_class
from roverlab.ros1.rospy.rostime import Duration
from roverlab.ros1.rospy.runtime import RUNTIME

__all__ = [
    "ActionClient",
    "ActionServer",
    "CommState",
    "GoalStatus",
    "SimpleActionClient",
    "SimpleActionServer",
    "SimpleGoalState",
    "TerminalState",
    "get_name_of_constant",
]

#: ``actionlib_msgs/GoalStatus`` with its constants (``GoalStatus.SUCCEEDED``).
GoalStatus = message_class("actionlib_msgs/msg/GoalStatus")


class TerminalState:
    RECALLED = _core.GoalStatus.RECALLED
    REJECTED = _core.GoalStatus.REJECTED
    PREEMPTED = _core.GoalStatus.PREEMPTED
    ABORTED = _core.GoalStatus.ABORTED
    SUCCEEDED = _core.GoalStatus.SUCCEEDED
    LOST = _core.GoalStatus.LOST


def get_name_of_constant(cls: Any, value: int) -> str:
    if cls is GoalStatus or cls is TerminalState:
        return status_name(value)
    for k, v in vars(cls).items():
        if isinstance(v, int) and v == value:
            return k
    return f"NO_SUCH_STATE_{value}"


def _seconds(timeout: Any) -> float | None:
    if timeout is None:
        return None
    s = float(timeout.to_sec()) if hasattr(timeout, "to_sec") else float(timeout)
    return s if s > 0 else None


def _wait(condition: Callable[[], bool], timeout: Any) -> bool:
    """Wait in ROS time until ``condition`` or the node's shutdown."""
    context = RUNTIME.require_context()

    def done() -> bool:
        RUNTIME.hold_during_hooks()
        return condition() or RUNTIME.shutdown_flag

    context.wait_for(done, _seconds(timeout))
    return condition()


class SimpleActionClient(_core.SimpleActionClient):
    """``SimpleActionClient("move_base", MoveBaseAction)``."""

    def __init__(self, ns: str, ActionSpec: Any) -> None:
        super().__init__(RUNTIME.require_node(), ns, ActionSpec)

    def wait_for_server(self, timeout: Any = Duration()) -> bool:  # noqa: B008
        return _wait(self.action_client.server_is_ready, timeout)

    def wait_for_result(self, timeout: Any = Duration()) -> bool:  # noqa: B008
        if self.gh is None:
            self.node.get_logger().error("Called wait_for_result when no goal exists")
            return False
        return _wait(lambda: self.simple_state == SimpleGoalState.DONE, timeout)

    def send_goal_and_wait(
        self,
        goal: Any,
        execute_timeout: Any = Duration(),  # noqa: B008
        preempt_timeout: Any = Duration(),  # noqa: B008
    ) -> int:
        self.send_goal(goal)
        if not self.wait_for_result(execute_timeout):
            self.cancel_goal()
            self.wait_for_result(preempt_timeout)
        return self.get_state()


class ActionClient(_core.ActionClient):
    """``ActionClient("move_base", MoveBaseAction)``."""

    def __init__(self, ns: str, ActionSpec: Any) -> None:
        super().__init__(RUNTIME.require_node(), ns, ActionSpec)

    def wait_for_server(self, timeout: Any = Duration()) -> bool:  # noqa: B008
        return _wait(self.server_is_ready, timeout)


class SimpleActionServer(_core.SimpleActionServer):
    """``SimpleActionServer(name, ActionSpec, execute_cb=None, auto_start=True)``."""

    def __init__(
        self,
        name: str,
        ActionSpec: Any,
        execute_cb: Callable[[Any], Any] | None = None,
        auto_start: bool = True,
    ) -> None:
        super().__init__(
            RUNTIME.require_node(), name, ActionSpec, execute_cb, auto_start=auto_start
        )


class ActionServer(_core.ActionServer):
    """``ActionServer(ns, ActionSpec, goal_cb, cancel_cb=nop_cb, auto_start=True)``."""

    def __init__(
        self,
        ns: str,
        ActionSpec: Any,
        goal_cb: Callable[[Any], Any],
        cancel_cb: Callable[[Any], Any] | None = None,
        auto_start: bool = True,
    ) -> None:
        super().__init__(
            RUNTIME.require_node(), ns, ActionSpec, goal_cb, cancel_cb, auto_start=auto_start
        )
