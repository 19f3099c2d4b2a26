"""SimpleActionClient: one goal at a time, with done / active / feedback callbacks (ROS 1).

Waiting calls (:meth:`SimpleActionClient.wait_for_server`, :meth:`wait_for_result`,
:meth:`send_goal_and_wait`) take their timeout in seconds of the node's clock (sim time in a
simulation), as rospy's ``Duration`` timeouts do; 0 or None waits forever. They are for
threads other than the executor's (a script's main thread); with nothing spinning they spin
the executor themselves; inside a callback they raise instead of deadlocking.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Final

from roverlab.actionlib.client import ActionClient, ClientGoalHandle, CommState
from roverlab.actionlib.status import GoalStatus
from roverlab.core import Node, Time

__all__ = ["SimpleActionClient", "SimpleGoalState"]


class SimpleGoalState:
    PENDING: Final = 0
    ACTIVE: Final = 1
    DONE: Final = 2

    NAMES: Final = ("PENDING", "ACTIVE", "DONE")


class SimpleActionClient:
    """actionlib's SimpleActionClient on ``node`` for action ``name``.

    Args:
        node: the node that owns the action's topics.
        name: the action's namespace (``move_base``).
        action_type: an :class:`~roverlab.msgs.ActionType` or its name
            (``"move_base_msgs/MoveBaseAction"``).
    """

    def __init__(self, node: Node, name: str, action_type: Any) -> None:
        self.node = node
        self.action_client = ActionClient(node, name, action_type)
        self.spec = self.action_client.spec
        self.simple_state = SimpleGoalState.DONE
        self.gh: ClientGoalHandle | None = None
        self._done_cb: Callable[[int, Any], Any] | None = None
        self._active_cb: Callable[[], Any] | None = None
        self._feedback_cb: Callable[[Any], Any] | None = None

    # ----------------------------------------------------------------- server
    def wait_for_server(self, timeout: float | None = None) -> bool:
        """Wait up to ``timeout`` s (0/None: forever) for the server; True if it is there."""
        return self.action_client.wait_for_server(timeout)

    # ----------------------------------------------------------------- goals
    def send_goal(
        self,
        goal: Any,
        done_cb: Callable[[int, Any], Any] | None = None,
        active_cb: Callable[[], Any] | None = None,
        feedback_cb: Callable[[Any], Any] | None = None,
    ) -> None:
        """Send ``goal``, dropping any goal tracked before. ``done_cb(state, result)``,
        ``active_cb()`` and ``feedback_cb(feedback)`` run on the executor thread."""
        self.stop_tracking_goal()
        self._done_cb, self._active_cb, self._feedback_cb = done_cb, active_cb, feedback_cb
        with self.action_client.lock:
            self.simple_state = SimpleGoalState.PENDING
            self.gh = self.action_client.send_goal(goal, self._on_transition, self._on_feedback)

    def send_goal_and_wait(
        self, goal: Any, execute_timeout: float = 0.0, preempt_timeout: float = 0.0
    ) -> int:
        """Send ``goal`` and wait for the result; after ``execute_timeout`` s cancel it and
        wait ``preempt_timeout`` s more. Returns the final state (:meth:`get_state`)."""
        self.send_goal(goal)
        if not self.wait_for_result(execute_timeout):
            self.node.get_logger().debug("Canceling goal")
            self.cancel_goal()
            if self.wait_for_result(preempt_timeout):
                self.node.get_logger().debug("Preempt finished within specified timeout")
            else:
                self.node.get_logger().debug("Preempt didn't finish specified timeout")
        return self.get_state()

    def wait_for_result(self, timeout: float | None = 0.0) -> bool:
        """Wait up to ``timeout`` s (0/None: forever) for the goal to finish; True if done."""
        if self.gh is None:
            self.node.get_logger().error("Called wait_for_result when no goal exists")
            return False
        self.node.context.wait_for(
            lambda: self.simple_state == SimpleGoalState.DONE, timeout or None
        )
        return self.simple_state == SimpleGoalState.DONE

    def get_result(self) -> Any:
        """The result of the current goal (``...Result``), or None."""
        if self.gh is None:
            self.node.get_logger().error("Called get_result when no goal is running")
            return None
        return self.gh.get_result()

    def get_state(self) -> int:
        """The goal's state as a ``GoalStatus`` value (RECALLING reads PENDING, PREEMPTING
        reads ACTIVE); LOST without a goal."""
        if self.gh is None:
            return GoalStatus.LOST
        status = self.gh.get_goal_status()
        if status == GoalStatus.RECALLING:
            return GoalStatus.PENDING
        if status == GoalStatus.PREEMPTING:
            return GoalStatus.ACTIVE
        return status

    def get_goal_status_text(self) -> str:
        if self.gh is None:
            self.node.get_logger().error("Called get_goal_status_text when no goal is running")
            return "ERROR: Called get_goal_status_text when no goal is running"
        return self.gh.get_goal_status_text()

    def cancel_all_goals(self) -> None:
        self.action_client.cancel_all_goals()

    def cancel_goals_at_and_before_time(self, time: Time) -> None:
        self.action_client.cancel_goals_at_and_before_time(time)

    def cancel_goal(self) -> None:
        """Cancel the goal this client tracks (if any)."""
        if self.gh is not None:
            self.gh.cancel()

    def stop_tracking_goal(self) -> None:
        if self.gh is not None:
            self.action_client.stop_tracking(self.gh)
        self.gh = None

    # ----------------------------------------------------------------- callbacks
    def _set_simple_state(self, state: int) -> None:
        self.simple_state = state

    def _on_transition(self, gh: ClientGoalHandle) -> None:
        if gh != self.gh:
            self.node.get_logger().error(
                "Got a transition callback on a goal handle we're not tracking"
            )
            return
        comm = gh.get_comm_state()
        err = self.node.get_logger().error
        if comm in (CommState.ACTIVE, CommState.PREEMPTING):
            if self.simple_state == SimpleGoalState.PENDING:
                self._set_simple_state(SimpleGoalState.ACTIVE)
                if self._active_cb is not None:
                    self._active_cb()
            elif self.simple_state == SimpleGoalState.DONE:
                err(f"In {CommState.NAMES[comm]} but simple client is in DONE")
        elif comm == CommState.RECALLING:
            if self.simple_state != SimpleGoalState.PENDING:
                state = SimpleGoalState.NAMES[self.simple_state]
                err(f"In RECALLING but simple client is in {state}")
        elif comm == CommState.DONE:
            if self.simple_state in (SimpleGoalState.PENDING, SimpleGoalState.ACTIVE):
                self._set_simple_state(SimpleGoalState.DONE)
                if self._done_cb is not None:
                    self._done_cb(gh.get_goal_status(), gh.get_result())
            else:
                err("SimpleActionClient received DONE twice")

    def _on_feedback(self, gh: ClientGoalHandle, feedback: Any) -> None:
        if gh != self.gh:
            return
        if self._feedback_cb is not None:
            self._feedback_cb(feedback)
