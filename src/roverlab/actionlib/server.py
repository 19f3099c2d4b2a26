"""ActionServer and ServerGoalHandle: the server side of the ROS 1 actionlib protocol.

The server subscribes to ``NAME/goal`` (``...ActionGoal``) and ``NAME/cancel``
(``actionlib_msgs/GoalID``) and publishes ``NAME/status`` (``actionlib_msgs/GoalStatusArray``,
latched, every ``1/status_frequency`` s and on every change), ``NAME/feedback`` and
``NAME/result``. Each goal has a status tracker; the user's goal callback gets a
:class:`ServerGoalHandle` and moves it through actionlib's server state machine
(PENDING -> ACTIVE -> SUCCEEDED / ABORTED / PREEMPTED, PENDING -> REJECTED / RECALLED, with
RECALLING / PREEMPTING while a cancel is pending). A goal that reached a terminal state
stays in the status list for ``status_list_timeout`` seconds.

Every method is safe to call from any thread (one lock per server); callbacks run on the
executor thread, under that lock, as in rospy.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from roverlab.actionlib.status import GoalIDGenerator, GoalStatus, status_name
from roverlab.core import Node, QoSProfile, Time
from roverlab.msgs import ActionType, get_action_type, get_factory

__all__ = ["ActionServer", "ServerGoalHandle"]

GoalID = get_factory("actionlib_msgs/msg/GoalID")
GoalStatusMsg = get_factory("actionlib_msgs/msg/GoalStatus")
_Header = get_factory("std_msgs/msg/Header")
_GoalIDCls = GoalID.cls
_GoalStatusCls = GoalStatusMsg.cls
GoalStatusArray = get_factory("actionlib_msgs/msg/GoalStatusArray")

_LATCHED = QoSProfile(depth=1, durability="transient_local")
_ZERO = Time(0)


class _StatusTracker:
    """One goal of the status list: its ``actionlib_msgs/GoalStatus`` and, when it came
    with one, its ``ActionGoal`` message."""

    __slots__ = ("action_goal", "destruction_ns", "status")

    def __init__(self, status: Any, action_goal: Any = None) -> None:
        self.status = status
        self.action_goal = action_goal
        self.destruction_ns = 0  # set once the goal is finished: the list's timeout runs


class ServerGoalHandle:
    """The server's handle on one goal (ROS 1 ``ServerGoalHandle``)."""

    def __init__(self, tracker: _StatusTracker, server: ActionServer) -> None:
        self._tracker = tracker
        self._server = server

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ServerGoalHandle) and other._tracker is self._tracker

    def __hash__(self) -> int:
        return id(self._tracker)

    def get_goal(self) -> Any:
        """The goal (``...Goal`` message), or None for a handle without one."""
        ag = self._tracker.action_goal
        return None if ag is None else ag.goal

    def get_goal_id(self) -> Any:
        return self._tracker.status.goal_id

    def get_goal_status(self) -> Any:
        return self._tracker.status

    # ----------------------------------------------------------------- transitions
    def _move(self, allowed: dict[int, int], text: str, result: Any, what: str) -> bool:
        server = self._server
        with server.lock:
            status = self._tracker.status
            new = allowed.get(int(status.status))
            if new is None:
                server.node.get_logger().error(
                    f"to {what}, the goal must be in "
                    f"{' or '.join(status_name(s) for s in allowed)}; it is "
                    f"{status_name(int(status.status))} (goal {status.goal_id.id})"
                )
                return False
            status.status = new
            status.text = text
            if new in _RESULT_STATES:
                self._tracker.destruction_ns = server.node.get_clock().now_ns()
                server._publish_result(status, result)
            else:
                server.publish_status()
            return True

    def set_accepted(self, text: str = "") -> bool:
        """PENDING -> ACTIVE (RECALLING -> PREEMPTING)."""
        return self._move(
            {GoalStatus.PENDING: GoalStatus.ACTIVE, GoalStatus.RECALLING: GoalStatus.PREEMPTING},
            text,
            None,
            "accept it",
        )

    def set_rejected(self, result: Any = None, text: str = "") -> bool:
        """PENDING / RECALLING -> REJECTED, with a result."""
        return self._move(
            {GoalStatus.PENDING: GoalStatus.REJECTED, GoalStatus.RECALLING: GoalStatus.REJECTED},
            text,
            result,
            "reject it",
        )

    def set_canceled(self, result: Any = None, text: str = "") -> bool:
        """PENDING / RECALLING -> RECALLED; ACTIVE / PREEMPTING -> PREEMPTED."""
        return self._move(
            {
                GoalStatus.PENDING: GoalStatus.RECALLED,
                GoalStatus.RECALLING: GoalStatus.RECALLED,
                GoalStatus.ACTIVE: GoalStatus.PREEMPTED,
                GoalStatus.PREEMPTING: GoalStatus.PREEMPTED,
            },
            text,
            result,
            "cancel it",
        )

    def set_aborted(self, result: Any = None, text: str = "") -> bool:
        """ACTIVE / PREEMPTING -> ABORTED."""
        return self._move(
            {GoalStatus.ACTIVE: GoalStatus.ABORTED, GoalStatus.PREEMPTING: GoalStatus.ABORTED},
            text,
            result,
            "abort it",
        )

    def set_succeeded(self, result: Any = None, text: str = "") -> bool:
        """ACTIVE / PREEMPTING -> SUCCEEDED."""
        return self._move(
            {
                GoalStatus.ACTIVE: GoalStatus.SUCCEEDED,
                GoalStatus.PREEMPTING: GoalStatus.SUCCEEDED,
            },
            text,
            result,
            "succeed",
        )

    def set_cancel_requested(self) -> bool:
        """PENDING -> RECALLING, ACTIVE -> PREEMPTING; True if the goal moved."""
        server = self._server
        with server.lock:
            status = self._tracker.status
            new = {
                GoalStatus.PENDING: GoalStatus.RECALLING,
                GoalStatus.ACTIVE: GoalStatus.PREEMPTING,
            }.get(int(status.status))
            if new is None:
                return False
            status.status = new
            server.publish_status()
            return True

    def publish_feedback(self, feedback: Any) -> None:
        self._server._publish_feedback(self._tracker.status, feedback)


_RESULT_STATES = frozenset(
    {
        GoalStatus.REJECTED,
        GoalStatus.RECALLED,
        GoalStatus.PREEMPTED,
        GoalStatus.ABORTED,
        GoalStatus.SUCCEEDED,
    }
)

GoalCallback = Callable[[ServerGoalHandle], Any]


class ActionServer:
    """An actionlib server on ``node`` for action ``name`` (ROS 1 ``ActionServer``).

    Args:
        node: the node that owns the topics.
        name: the action's namespace (``move_base`` -> ``move_base/goal``, ...), resolved
            like a topic name.
        action_type: an :class:`~roverlab.msgs.ActionType` or its name
            (``"move_base_msgs/MoveBaseAction"``).
        goal_cb: called with a :class:`ServerGoalHandle` for each new goal.
        cancel_cb: called with the handle of each goal a cancel request reaches.
        auto_start: start at once (else call :meth:`start`).
        status_frequency: Hz of the ``status`` topic; default: the node's
            ``actionlib_status_frequency`` parameter (5.0, as actionlib).
        status_list_timeout: seconds a finished goal stays in the status list.
    """

    def __init__(
        self,
        node: Node,
        name: str,
        action_type: Any,
        goal_cb: GoalCallback,
        cancel_cb: GoalCallback | None = None,
        *,
        auto_start: bool = True,
        status_frequency: float | None = None,
        status_list_timeout: float = 5.0,
    ) -> None:
        self.node = node
        self.spec: ActionType = get_action_type(action_type)
        self.name = node.resolve_topic_name(name)
        self.goal_callback = goal_cb
        self.cancel_callback = cancel_cb
        self.lock = threading.RLock()
        self.status_list: list[_StatusTracker] = []
        self.started = False
        self._last_cancel = _ZERO
        self._ids = GoalIDGenerator(node.get_fully_qualified_name())
        if status_frequency is None:
            param = "actionlib_status_frequency"
            if not node.has_parameter(param):
                node.declare_parameter(param, 5.0)
            status_frequency = float(node.get_parameter_value(param))
        self.status_frequency = status_frequency
        self.status_list_timeout_ns = round(status_list_timeout * 1e9)
        self._subs: list[Any] = []
        self._pubs: list[Any] = []
        self._timer: Any = None
        if auto_start:
            self.start()

    # ----------------------------------------------------------------- lifecycle
    def start(self) -> None:
        """Create the topics, start the status timer and publish the status once."""
        with self.lock:
            if self.started:
                return
            node, ns = self.node, self.name
            self._status_pub = node.create_publisher(GoalStatusArray, f"{ns}/status", _LATCHED)
            self._result_pub = node.create_publisher(self.spec.ActionResult, f"{ns}/result", 50)
            self._feedback_pub = node.create_publisher(
                self.spec.ActionFeedback, f"{ns}/feedback", 50
            )
            self._pubs = [self._status_pub, self._result_pub, self._feedback_pub]
            self._subs = [
                node.create_subscription(self.spec.ActionGoal, f"{ns}/goal", self._on_goal, 50),
                node.create_subscription(GoalID, f"{ns}/cancel", self._on_cancel, 50),
            ]
            if self.status_frequency > 0:
                self._timer = node.create_timer(1.0 / self.status_frequency, self._status_tick)
            self.started = True
            self.publish_status()

    def stop(self) -> None:
        """Stop serving: the topics and the timer are destroyed."""
        with self.lock:
            if not self.started:
                return
            self.started = False
            if self._timer is not None:
                self._timer.destroy()
            for sub in self._subs:
                sub.destroy()
            for pub in self._pubs:
                pub.destroy()

    # ----------------------------------------------------------------- publishing
    def _now(self) -> Time:
        return self.node.get_clock().now()

    def publish_status(self) -> None:
        """Publish the status list now (dropping goals finished longer than the timeout)."""
        with self.lock:
            if not self.started:
                return
            now = self._now().nanoseconds
            timeout = self.status_list_timeout_ns
            self.status_list = [
                st
                for st in self.status_list
                if not (st.destruction_ns and st.destruction_ns + timeout < now)
            ]
            msg = GoalStatusArray(status_list=[_copy_status(st.status) for st in self.status_list])
            msg.header.stamp = Time(now).to_msg()
            self._status_pub.publish(msg)

    def _status_tick(self) -> None:
        self.publish_status()

    def _publish_result(self, status: Any, result: Any) -> None:
        with self.lock:
            msg = self.spec.ActionResult()
            msg.header.stamp = self._now().to_msg()
            msg.status = _copy_status(status)
            if result is not None:
                msg.result = _as_message(result, self.spec.Result)
            if self.started:
                self._result_pub.publish(msg)
            self.publish_status()

    def _publish_feedback(self, status: Any, feedback: Any) -> None:
        with self.lock:
            # the rosbags class directly (a move_base cycle sends one): the fields the
            # factory's defaults and three assignments would give, without the defaults
            msg = self.spec.ActionFeedback.cls(
                header=_Header.cls(stamp=self._now().to_msg(), frame_id=""),
                status=_copy_status(status),
                feedback=_as_message(feedback, self.spec.Feedback),
            )
            if self.started:
                self._feedback_pub.publish(msg)

    # ----------------------------------------------------------------- incoming
    def _on_goal(self, action_goal: Any) -> None:
        with self.lock:
            if not self.started:
                return
            goal_id = action_goal.goal_id
            for st in self.status_list:
                if st.status.goal_id.id == goal_id.id:
                    # a cancel may have come first: the goal is recalled at once
                    if st.status.status == GoalStatus.RECALLING:
                        st.status.status = GoalStatus.RECALLED
                        st.destruction_ns = self._now().nanoseconds
                        self._publish_result(st.status, None)
                    return
            now = self._now()
            stamp = Time.from_msg(goal_id.stamp)
            gid = GoalID(
                stamp=goal_id.stamp if stamp.nanoseconds else now.to_msg(),
                id=goal_id.id or self._ids.generate(now.seconds),
            )
            tracker = _StatusTracker(
                GoalStatusMsg(goal_id=gid, status=GoalStatus.PENDING), action_goal
            )
            self.status_list.append(tracker)
            handle = ServerGoalHandle(tracker, self)
            if stamp.nanoseconds and stamp <= self._last_cancel:
                handle.set_canceled(
                    None,
                    "This goal handle was canceled by the action server because its "
                    "timestamp is before the timestamp of the last cancel request",
                )
                return
            self.goal_callback(handle)

    def _on_cancel(self, cancel: Any) -> None:
        with self.lock:
            if not self.started:
                return
            stamp = Time.from_msg(cancel.stamp)
            everything = cancel.id == "" and stamp.nanoseconds == 0
            found = False
            for st in list(self.status_list):
                goal_stamp = Time.from_msg(st.status.goal_id.stamp)
                this_one = cancel.id == st.status.goal_id.id
                before = stamp.nanoseconds != 0 and goal_stamp <= stamp
                if everything or this_one or before:
                    found = found or this_one
                    handle = ServerGoalHandle(st, self)
                    if handle.set_cancel_requested() and self.cancel_callback is not None:
                        self.cancel_callback(handle)
            if cancel.id != "" and not found:
                # the goal has not arrived yet: remember to recall it when it does
                tracker = _StatusTracker(
                    GoalStatusMsg(
                        goal_id=GoalID(stamp=cancel.stamp, id=cancel.id),
                        status=GoalStatus.RECALLING,
                    )
                )
                tracker.destruction_ns = self._now().nanoseconds
                self.status_list.append(tracker)
            if stamp > self._last_cancel:
                self._last_cancel = stamp


def _copy_status(status: Any) -> Any:
    """A snapshot of a tracker's status (messages are passed by reference in process).

    Built with the rosbags classes directly: the tracker's fields were checked when it
    was made, so the factory's checks would only repeat them (this runs for every
    feedback and every status entry of every status message).
    """
    gid = status.goal_id
    return _GoalStatusCls(
        goal_id=_GoalIDCls(stamp=gid.stamp, id=str(gid.id)),
        status=int(status.status),
        text=str(status.text),
    )


def _as_message(value: Any, factory: Any) -> Any:
    if isinstance(value, factory.cls):
        return value
    if isinstance(value, dict):
        return factory.from_dict(value)
    raise TypeError(f"expected {factory.typename}, got {type(value).__name__}")
