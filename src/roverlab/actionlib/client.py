"""ActionClient and ClientGoalHandle: the client side of the ROS 1 actionlib protocol.

Each goal sent has a communication state machine driven by the server's ``status``
array and its ``result`` (actionlib's table: WAITING_FOR_GOAL_ACK, PENDING, ACTIVE,
WAITING_FOR_RESULT, WAITING_FOR_CANCEL_ACK, RECALLING, PREEMPTING, DONE). A goal the
server stops listing while it should know it is LOST.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, Final

from roverlab.actionlib.status import TERMINAL_STATES, GoalIDGenerator, GoalStatus, status_name
from roverlab.core import Node, Time
from roverlab.msgs import ActionType, get_action_type, get_factory

__all__ = ["ActionClient", "ClientGoalHandle", "CommState"]

GoalID = get_factory("actionlib_msgs/msg/GoalID")
GoalStatusMsg = get_factory("actionlib_msgs/msg/GoalStatus")
GoalStatusArray = get_factory("actionlib_msgs/msg/GoalStatusArray")


class CommState:
    """The client's view of a goal's communication with the server."""

    WAITING_FOR_GOAL_ACK: Final = 0
    PENDING: Final = 1
    ACTIVE: Final = 2
    WAITING_FOR_RESULT: Final = 3
    WAITING_FOR_CANCEL_ACK: Final = 4
    RECALLING: Final = 5
    PREEMPTING: Final = 6
    DONE: Final = 7

    NAMES: Final = (
        "WAITING_FOR_GOAL_ACK",
        "PENDING",
        "ACTIVE",
        "WAITING_FOR_RESULT",
        "WAITING_FOR_CANCEL_ACK",
        "RECALLING",
        "PREEMPTING",
        "DONE",
    )


_NO: Final = ()  # no transition
_BAD: Final = None  # an invalid transition (logged)
C, S = CommState, GoalStatus
# (comm state, server status) -> the comm states passed through, as actionlib's table
_TRANSITIONS: Final[dict[int, dict[int, tuple[int, ...] | None]]] = {
    C.WAITING_FOR_GOAL_ACK: {
        S.PENDING: (C.PENDING,),
        S.ACTIVE: (C.ACTIVE,),
        S.REJECTED: (C.PENDING, C.WAITING_FOR_RESULT),
        S.RECALLING: (C.PENDING, C.RECALLING),
        S.RECALLED: (C.PENDING, C.WAITING_FOR_RESULT),
        S.PREEMPTED: (C.ACTIVE, C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.SUCCEEDED: (C.ACTIVE, C.WAITING_FOR_RESULT),
        S.ABORTED: (C.ACTIVE, C.WAITING_FOR_RESULT),
        S.PREEMPTING: (C.ACTIVE, C.PREEMPTING),
    },
    C.PENDING: {
        S.PENDING: _NO,
        S.ACTIVE: (C.ACTIVE,),
        S.REJECTED: (C.WAITING_FOR_RESULT,),
        S.RECALLING: (C.RECALLING,),
        S.RECALLED: (C.RECALLING, C.WAITING_FOR_RESULT),
        S.PREEMPTED: (C.ACTIVE, C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.SUCCEEDED: (C.ACTIVE, C.WAITING_FOR_RESULT),
        S.ABORTED: (C.ACTIVE, C.WAITING_FOR_RESULT),
        S.PREEMPTING: (C.ACTIVE, C.PREEMPTING),
    },
    C.ACTIVE: {
        S.PENDING: _BAD,
        S.ACTIVE: _NO,
        S.REJECTED: _BAD,
        S.RECALLING: _BAD,
        S.RECALLED: _BAD,
        S.PREEMPTED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.SUCCEEDED: (C.WAITING_FOR_RESULT,),
        S.ABORTED: (C.WAITING_FOR_RESULT,),
        S.PREEMPTING: (C.PREEMPTING,),
    },
    C.WAITING_FOR_RESULT: {
        S.PENDING: _BAD,
        S.ACTIVE: _NO,
        S.REJECTED: _NO,
        S.RECALLING: _BAD,
        S.RECALLED: _NO,
        S.PREEMPTED: _NO,
        S.SUCCEEDED: _NO,
        S.ABORTED: _NO,
        S.PREEMPTING: _BAD,
    },
    C.WAITING_FOR_CANCEL_ACK: {
        S.PENDING: _NO,
        S.ACTIVE: _NO,
        S.REJECTED: (C.WAITING_FOR_RESULT,),
        S.RECALLING: (C.RECALLING,),
        S.RECALLED: (C.RECALLING, C.WAITING_FOR_RESULT),
        S.PREEMPTED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.SUCCEEDED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.ABORTED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.PREEMPTING: (C.PREEMPTING,),
    },
    C.RECALLING: {
        S.PENDING: _BAD,
        S.ACTIVE: _BAD,
        S.REJECTED: (C.WAITING_FOR_RESULT,),
        S.RECALLING: _NO,
        S.RECALLED: (C.WAITING_FOR_RESULT,),
        S.PREEMPTED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.SUCCEEDED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.ABORTED: (C.PREEMPTING, C.WAITING_FOR_RESULT),
        S.PREEMPTING: (C.PREEMPTING,),
    },
    C.PREEMPTING: {
        S.PENDING: _BAD,
        S.ACTIVE: _BAD,
        S.REJECTED: _BAD,
        S.RECALLING: _BAD,
        S.RECALLED: _BAD,
        S.PREEMPTED: (C.WAITING_FOR_RESULT,),
        S.SUCCEEDED: (C.WAITING_FOR_RESULT,),
        S.ABORTED: (C.WAITING_FOR_RESULT,),
        S.PREEMPTING: _NO,
    },
    C.DONE: {
        S.PENDING: _BAD,
        S.ACTIVE: _BAD,
        S.REJECTED: _NO,
        S.RECALLING: _BAD,
        S.RECALLED: _NO,
        S.PREEMPTED: _NO,
        S.SUCCEEDED: _NO,
        S.ABORTED: _NO,
        S.PREEMPTING: _BAD,
    },
}
del C, S

TransitionCallback = Callable[["ClientGoalHandle"], Any]
FeedbackCallback = Callable[["ClientGoalHandle", Any], Any]


class _CommStateMachine:
    """One sent goal's communication state, updated from status, result and feedback."""

    def __init__(
        self,
        client: ActionClient,
        action_goal: Any,
        transition_cb: TransitionCallback | None,
        feedback_cb: FeedbackCallback | None,
    ) -> None:
        self.client = client
        self.action_goal = action_goal
        self.goal_id = str(action_goal.goal_id.id)
        self.transition_cb = transition_cb
        self.feedback_cb = feedback_cb
        self.state = CommState.WAITING_FOR_GOAL_ACK
        self.latest_status = GoalStatusMsg(goal_id=action_goal.goal_id, status=GoalStatus.PENDING)
        self.latest_result: Any = None

    def transition_to(self, state: int) -> None:
        self.state = state
        if self.transition_cb is not None:
            self.transition_cb(ClientGoalHandle(self))

    def update_status(self, status_array: Any) -> None:
        if self.state == CommState.DONE:
            return
        status = next((s for s in status_array.status_list if s.goal_id.id == self.goal_id), None)
        if status is None:
            if self.state not in (
                CommState.WAITING_FOR_GOAL_ACK,
                CommState.WAITING_FOR_RESULT,
                CommState.DONE,
            ):
                self.latest_status = GoalStatusMsg(
                    goal_id=self.action_goal.goal_id, status=GoalStatus.LOST
                )
                self.transition_to(CommState.DONE)
            return
        self.latest_status = status
        steps = _TRANSITIONS[self.state].get(int(status.status), _BAD)
        if steps is _BAD:
            self.client.node.get_logger().error(
                f"Invalid goal status transition from {CommState.NAMES[self.state]} to "
                f"{status_name(int(status.status))} (goal {self.goal_id})"
            )
            return
        for state in steps:
            self.transition_to(state)

    def update_result(self, action_result: Any) -> None:
        if action_result.status.goal_id.id != self.goal_id or self.state == CommState.DONE:
            return
        self.latest_status = action_result.status
        self.latest_result = action_result
        self.update_status(GoalStatusArray(status_list=[action_result.status]))
        self.transition_to(CommState.DONE)

    def update_feedback(self, action_feedback: Any) -> None:
        if action_feedback.status.goal_id.id == self.goal_id and self.feedback_cb is not None:
            self.feedback_cb(ClientGoalHandle(self), action_feedback.feedback)


class ClientGoalHandle:
    """The client's handle on one sent goal (ROS 1 ``ClientGoalHandle``)."""

    def __init__(self, machine: _CommStateMachine) -> None:
        self._m = machine

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ClientGoalHandle) and other._m is self._m

    def __hash__(self) -> int:
        return id(self._m)

    @property
    def goal_id(self) -> str:
        return self._m.goal_id

    def cancel(self) -> None:
        """Ask the server to cancel this goal (WAITING_FOR_CANCEL_ACK)."""
        client = self._m.client
        with client.lock:
            client.send_cancel(GoalID(stamp=Time(0).to_msg(), id=self._m.goal_id))
            self._m.transition_to(CommState.WAITING_FOR_CANCEL_ACK)

    def get_comm_state(self) -> int:
        return self._m.state

    def get_goal_status(self) -> int:
        return int(self._m.latest_status.status)

    def get_goal_status_text(self) -> str:
        return str(self._m.latest_status.text)

    def get_result(self) -> Any:
        """The result (``...Result`` message), or None before one arrived."""
        res = self._m.latest_result
        return None if res is None else res.result

    def get_terminal_state(self) -> int:
        status = self.get_goal_status()
        if self._m.state != CommState.DONE:
            self._m.client.node.get_logger().warning(
                f"Asking for the terminal state when we're in {CommState.NAMES[self._m.state]}"
            )
        return status if status in TERMINAL_STATES else GoalStatus.LOST


class ActionClient:
    """An actionlib client on ``node`` for action ``name`` (ROS 1 ``ActionClient``).

    Args:
        node: the node that owns the topics.
        name: the action's namespace (``move_base``).
        action_type: an :class:`~roverlab.msgs.ActionType` or its name.
    """

    def __init__(self, node: Node, name: str, action_type: Any) -> None:
        self.node = node
        self.spec: ActionType = get_action_type(action_type)
        self.name = node.resolve_topic_name(name)
        self.lock = threading.RLock()
        self.last_status: Any = None
        self._machines: list[_CommStateMachine] = []
        self._ids = GoalIDGenerator(node.get_fully_qualified_name())
        ns = self.name
        self._goal_pub = node.create_publisher(self.spec.ActionGoal, f"{ns}/goal", 10)
        self._cancel_pub = node.create_publisher(GoalID, f"{ns}/cancel", 10)
        self._subs = [
            node.create_subscription(GoalStatusArray, f"{ns}/status", self._on_status, 10),
            node.create_subscription(self.spec.ActionResult, f"{ns}/result", self._on_result, 50),
            node.create_subscription(
                self.spec.ActionFeedback, f"{ns}/feedback", self._on_feedback, 50
            ),
        ]

    # ----------------------------------------------------------------- sending
    def send_goal(
        self,
        goal: Any,
        transition_cb: TransitionCallback | None = None,
        feedback_cb: FeedbackCallback | None = None,
    ) -> ClientGoalHandle:
        """Send ``goal`` (a ``...Goal`` message or a dict of its fields)."""
        if isinstance(goal, dict):
            goal = self.spec.Goal.from_dict(goal)
        elif not isinstance(goal, self.spec.Goal.cls):
            raise TypeError(f"expected a {self.spec.Goal.typename}, got {type(goal).__name__}")
        now = self.node.get_clock().now()
        action_goal = self.spec.ActionGoal(
            goal_id=GoalID(stamp=now.to_msg(), id=self._ids.generate(now.seconds)), goal=goal
        )
        action_goal.header.stamp = now.to_msg()
        with self.lock:
            machine = _CommStateMachine(self, action_goal, transition_cb, feedback_cb)
            self._machines.append(machine)
        self._goal_pub.publish(action_goal)
        return ClientGoalHandle(machine)

    def send_cancel(self, cancel: Any) -> None:
        self._cancel_pub.publish(cancel)

    def cancel_all_goals(self) -> None:
        """Cancel every goal of the server (id empty, stamp zero)."""
        self.send_cancel(GoalID(stamp=Time(0).to_msg(), id=""))

    def cancel_goals_at_and_before_time(self, time: Time) -> None:
        """Cancel every goal of the server stamped at or before ``time``."""
        self.send_cancel(GoalID(stamp=time.to_msg(), id=""))

    def stop_tracking(self, handle: ClientGoalHandle) -> None:
        with self.lock:
            if handle._m in self._machines:
                self._machines.remove(handle._m)

    # ----------------------------------------------------------------- server
    def server_is_ready(self) -> bool:
        """A status array came from the server and the server listens to goals and
        cancels (here or in another process)."""
        return (
            self.last_status is not None
            and self._goal_pub.has_listeners
            and self._cancel_pub.has_listeners
        )

    def wait_for_server(self, timeout: float | None = None) -> bool:
        """Wait up to ``timeout`` s of clock time (None or 0: forever) for the server."""
        return self.node.context.wait_for(self.server_is_ready, timeout or None)

    # ----------------------------------------------------------------- incoming
    def _on_status(self, msg: Any) -> None:
        with self.lock:
            self.last_status = msg
            for m in list(self._machines):
                m.update_status(msg)
            self._forget_done()

    def _on_result(self, msg: Any) -> None:
        with self.lock:
            for m in list(self._machines):
                m.update_result(msg)
            self._forget_done()

    def _on_feedback(self, msg: Any) -> None:
        with self.lock:
            for m in list(self._machines):
                m.update_feedback(msg)

    def _forget_done(self) -> None:
        self._machines = [m for m in self._machines if m.state != CommState.DONE]

    def destroy(self) -> None:
        for sub in self._subs:
            sub.destroy()
        self._goal_pub.destroy()
        self._cancel_pub.destroy()
