"""SimpleActionServer: one goal at a time, a new goal preempts the current one (ROS 1).

Two ways to use it, as in actionlib:

* an **execute callback** ``execute_cb(goal)``: it runs in a thread of its own (ROS 1 does
  the same), loops until done, checks :meth:`is_preempt_requested` and ends the goal with
  :meth:`set_succeeded`, :meth:`set_aborted` or :meth:`set_preempted`. A callback that
  returns without doing so aborts the goal; one that raises aborts it with the error.
  Suits scripts; its waits follow the node's clock.
* **goal and preempt callbacks** (:meth:`register_goal_callback`,
  :meth:`register_preempt_callback`) on the executor thread, with :meth:`accept_new_goal`
  and the ``set_*`` calls from timers: no thread, deterministic; what roverlab's own nodes
  (move_base, explore) use.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from roverlab.actionlib.server import ActionServer, ServerGoalHandle
from roverlab.actionlib.status import GoalStatus
from roverlab.core import Node, Time

__all__ = ["SimpleActionServer"]

_BUMPED = "This goal was canceled because another goal was received by the simple action server"
_ACCEPTED = "This goal has been accepted by the simple action server"
_NOT_TERMINATED = (
    "This goal was aborted by the simple action server. The user should have set a "
    "terminal status on this goal and did not"
)


class SimpleActionServer:
    """actionlib's SimpleActionServer on ``node``.

    Args:
        node: the node that owns the action's topics.
        name: the action's namespace (``move_base``).
        action_type: an :class:`~roverlab.msgs.ActionType` or its name.
        execute_cb: ``execute_cb(goal)``, run in the server's thread for each accepted goal.
        auto_start: start at once (else call :meth:`start`).
        **server_kwargs: ``status_frequency``, ``status_list_timeout`` of
            :class:`~roverlab.actionlib.ActionServer`.
    """

    def __init__(
        self,
        node: Node,
        name: str,
        action_type: Any,
        execute_cb: Callable[[Any], Any] | None = None,
        *,
        auto_start: bool = True,
        **server_kwargs: Any,
    ) -> None:
        self.node = node
        self.execute_callback = execute_cb
        self.goal_callback: Callable[[], Any] | None = None
        self.preempt_callback: Callable[[], Any] | None = None
        self._current: ServerGoalHandle | None = None
        self._next: ServerGoalHandle | None = None
        self._new_goal = False
        self._preempt_request = False
        self._new_goal_preempt_request = False
        self._terminate = False
        self._thread: threading.Thread | None = None
        self.action_server = ActionServer(
            node,
            name,
            action_type,
            self._on_goal,
            self._on_preempt,
            auto_start=False,
            **server_kwargs,
        )
        # one lock for the server and this: the execute thread waits on it for goals
        self.lock = self.action_server.lock
        self._condition = threading.Condition(self.lock)
        if auto_start:
            self.start()

    @property
    def spec(self) -> Any:
        return self.action_server.spec

    # ----------------------------------------------------------------- lifecycle
    def start(self) -> None:
        """Start the action server (and the execute thread when there is an execute_cb)."""
        if self.execute_callback is not None and self._thread is None:
            self._thread = threading.Thread(
                target=self._execute_loop,
                name=f"actionlib-{self.action_server.name}",
                daemon=True,
            )
            self._thread.start()
        self.action_server.start()

    def shutdown(self) -> None:
        """Stop the execute thread (after the running callback returns) and the server."""
        with self._condition:
            self._terminate = True
            self._condition.notify_all()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5)
        self.action_server.stop()

    # ----------------------------------------------------------------- user API
    def register_goal_callback(self, cb: Callable[[], Any]) -> None:
        if self.execute_callback is not None:
            self.node.get_logger().warning(
                "a goal callback is ignored when the server has an execute callback"
            )
            return
        self.goal_callback = cb

    def register_preempt_callback(self, cb: Callable[[], Any]) -> None:
        self.preempt_callback = cb

    def accept_new_goal(self) -> Any:
        """Make the newest goal the current one (ACTIVE) and return it; the current goal,
        if still active, is preempted. None (and an error logged) without a new goal."""
        with self.lock:
            if not self._new_goal or self._next is None:
                self.node.get_logger().error(
                    "Attempting to accept the next goal when a new goal is not available"
                )
                return None
            if self.is_active() and self._current is not None and self._current != self._next:
                self._current.set_canceled(None, _BUMPED)
            self._current = self._next
            self._new_goal = False
            self._preempt_request = self._new_goal_preempt_request
            self._new_goal_preempt_request = False
            self._current.set_accepted(_ACCEPTED)
            return self._current.get_goal()

    def is_new_goal_available(self) -> bool:
        return self._new_goal

    def is_preempt_requested(self) -> bool:
        return self._preempt_request

    def is_active(self) -> bool:
        current = self._current
        if current is None:
            return False
        return int(current.get_goal_status().status) in (GoalStatus.ACTIVE, GoalStatus.PREEMPTING)

    def current_goal_id(self) -> str:
        return "" if self._current is None else str(self._current.get_goal_id().id)

    def set_succeeded(self, result: Any = None, text: str = "") -> None:
        with self.lock:
            if self._current is not None:
                self._current.set_succeeded(self._result(result), text)

    def set_aborted(self, result: Any = None, text: str = "") -> None:
        with self.lock:
            if self._current is not None:
                self._current.set_aborted(self._result(result), text)

    def set_preempted(self, result: Any = None, text: str = "") -> None:
        with self.lock:
            if self._current is not None:
                self._current.set_canceled(self._result(result), text)

    def publish_feedback(self, feedback: Any) -> None:
        with self.lock:
            if self._current is not None:
                self._current.publish_feedback(feedback)

    def get_default_result(self) -> Any:
        return self.spec.Result()

    def _result(self, result: Any) -> Any:
        return self.get_default_result() if result is None else result

    # ----------------------------------------------------------------- server callbacks
    def _on_goal(self, goal: ServerGoalHandle) -> None:
        with self._condition:
            stamp = Time.from_msg(goal.get_goal_id().stamp)
            cur, nxt = self._current, self._next
            newer_than_current = cur is None or stamp >= Time.from_msg(cur.get_goal_id().stamp)
            newer_than_next = nxt is None or stamp >= Time.from_msg(nxt.get_goal_id().stamp)
            if not (newer_than_current and newer_than_next):
                goal.set_canceled(None, _BUMPED)
                return
            if nxt is not None and (cur is None or nxt != cur):
                nxt.set_canceled(None, _BUMPED)
            self._next = goal
            self._new_goal = True
            self._new_goal_preempt_request = False
            if self.is_active():
                self._preempt_request = True
                if self.preempt_callback is not None:
                    self.preempt_callback()
            if self.goal_callback is not None:
                self.goal_callback()
            self._condition.notify_all()

    def _on_preempt(self, preempt: ServerGoalHandle) -> None:
        with self.lock:
            if preempt == self._current:
                self._preempt_request = True
                if self.preempt_callback is not None:
                    self.preempt_callback()
            elif preempt == self._next:
                self._new_goal_preempt_request = True

    # ----------------------------------------------------------------- execute thread
    def _execute_loop(self) -> None:
        assert self.execute_callback is not None
        log = self.node.get_logger()
        while True:
            with self._condition:
                while not self._terminate and not self._new_goal:
                    self._condition.wait(0.1)
                if self._terminate:
                    return
                if self.is_active():
                    log.error("Should never reach this code with an active goal")
                    return
                goal = self.accept_new_goal()
            if goal is None:
                continue
            try:
                self.execute_callback(goal)
            except Exception as err:  # the user's bug aborts the goal, not the server
                log.error(f"Exception in your execute callback: {type(err).__name__}: {err}")
                self.set_aborted(None, f"Exception in execute callback: {err}")
                continue
            if self.is_active():
                log.warning(
                    "Your executeCallback did not set the goal to a terminal status. "
                    "The goal is aborted."
                )
                self.set_aborted(None, _NOT_TERMINATED)
