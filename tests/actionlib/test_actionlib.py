"""actionlib in one process: the protocol, the simple server and client, on sim time."""

from __future__ import annotations

import threading
import time
from typing import Any

import pytest

from roverlab.actionlib import (
    ActionClient,
    ActionServer,
    CommState,
    GoalStatus,
    ServerGoalHandle,
    SimpleActionClient,
    SimpleActionServer,
    SimpleGoalState,
    status_name,
)
from roverlab.core import Context, Time
from roverlab.msgs import get_factory

FIB = "actionlib_tutorials/FibonacciAction"
BUMPED = "This goal was canceled because another goal was received by the simple action server"


class FibServer:
    """A Fibonacci server in callback mode: one step per 0.1 s of sim time."""

    def __init__(self, ctx: Context, name: str = "fibonacci") -> None:
        self.node = ctx.create_node("fibonacci_server")
        self.server = SimpleActionServer(self.node, name, FIB)
        self.server.register_goal_callback(self._on_goal)
        self.server.register_preempt_callback(self._on_preempt)
        self.goal: Any = None
        self.seq: list[int] = []
        self.preempts = 0
        self.node.create_timer(0.1, self._step)

    def _on_goal(self) -> None:
        self.goal = self.server.accept_new_goal()
        self.seq = [0, 1]

    def _on_preempt(self) -> None:
        self.preempts += 1

    def _step(self) -> None:
        srv = self.server
        if not srv.is_active():
            return
        if srv.is_preempt_requested():
            srv.set_preempted({"sequence": self.seq}, "preempted at the user's request")
            return
        self.seq.append(self.seq[-1] + self.seq[-2])
        srv.publish_feedback({"sequence": self.seq})
        if len(self.seq) - 2 >= self.goal.order:
            srv.set_succeeded({"sequence": self.seq}, "the sequence is complete")


@pytest.fixture
def ctx() -> Context:
    return Context()


def _status_log(ctx: Context, topic: str = "/fibonacci/status") -> list[list[tuple[str, int]]]:
    seen: list[list[tuple[str, int]]] = []
    ctx.create_node("status_echo").create_subscription(
        "actionlib_msgs/GoalStatusArray",
        topic,
        lambda m: seen.append([(s.goal_id.id, int(s.status)) for s in m.status_list]),
        100,
    )
    return seen


def test_goal_feedback_result(ctx: Context) -> None:
    server = FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_server(timeout=5.0)
    events: list[Any] = []
    client.send_goal(
        {"order": 5},
        done_cb=lambda state, result: events.append(("done", state, list(result.sequence))),
        active_cb=lambda: events.append("active"),
        feedback_cb=lambda fb: events.append(("feedback", len(fb.sequence))),
    )
    assert client.simple_state == SimpleGoalState.PENDING
    t0 = ctx.now()
    assert client.wait_for_result(timeout=10.0)
    assert client.get_state() == GoalStatus.SUCCEEDED
    assert client.get_goal_status_text() == "the sequence is complete"
    assert list(client.get_result().sequence) == [0, 1, 1, 2, 3, 5, 8]
    assert events == [
        "active",
        *[("feedback", n) for n in range(3, 8)],
        ("done", GoalStatus.SUCCEEDED, [0, 1, 1, 2, 3, 5, 8]),
    ]
    # five steps of 0.1 s of sim time: the wait followed the clock, not the wall
    assert (ctx.now() - t0).seconds == pytest.approx(0.5, abs=0.11)
    assert server.preempts == 0


def test_preemption_by_a_second_goal(ctx: Context) -> None:
    server = FibServer(ctx)
    node = ctx.create_node("client")
    first = ActionClient(node, "fibonacci", FIB)  # keeps its own handle on goal 1
    second = SimpleActionClient(ctx.create_node("other_client"), "fibonacci", FIB)
    assert second.wait_for_server(5.0) and first.wait_for_server(5.0)
    transitions: list[int] = []
    gh = first.send_goal(
        {"order": 100}, transition_cb=lambda h: transitions.append(h.get_comm_state())
    )
    ctx.spin_for(0.35)
    assert gh.get_comm_state() == CommState.ACTIVE
    second.send_goal({"order": 2})
    assert second.wait_for_result(5.0) and second.get_state() == GoalStatus.SUCCEEDED
    ctx.spin_for(0.3)
    assert gh.get_comm_state() == CommState.DONE
    assert gh.get_goal_status() == GoalStatus.PREEMPTED
    assert gh.get_goal_status_text() == BUMPED
    assert transitions == [
        CommState.ACTIVE,
        CommState.PREEMPTING,
        CommState.WAITING_FOR_RESULT,
        CommState.DONE,
    ]
    assert server.preempts == 1


def test_cancel(ctx: Context) -> None:
    FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    status = _status_log(ctx)
    assert client.wait_for_server(5.0)
    client.send_goal({"order": 100})
    ctx.spin_for(0.25)
    assert client.get_state() == GoalStatus.ACTIVE
    client.cancel_goal()
    assert client.wait_for_result(5.0)
    assert client.get_state() == GoalStatus.PREEMPTED
    assert client.get_goal_status_text() == "preempted at the user's request"
    assert len(client.get_result().sequence) >= 3  # the result sent with the preemption
    ctx.spin_for(0.05)  # the status array published with the result
    states = [st for arr in status for _, st in arr]
    # the status topic showed the goal ACTIVE, PREEMPTING while the cancel was pending,
    # then PREEMPTED; terminal goals stay listed for status_list_timeout (5 s)
    assert states.index(GoalStatus.ACTIVE) < states.index(GoalStatus.PREEMPTED)
    assert GoalStatus.PREEMPTING in states
    ctx.spin_for(6.0)
    assert status[-1] == []


def test_wait_for_result_timeout_and_cancel_all(ctx: Context) -> None:
    FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_result(1.0) is False  # no goal yet: an error is logged
    assert client.get_state() == GoalStatus.LOST
    assert client.wait_for_server(5.0)
    client.send_goal({"order": 1000})
    t0 = ctx.now()
    assert client.wait_for_result(2.0) is False
    assert (ctx.now() - t0).seconds == pytest.approx(2.0, abs=0.01)
    assert client.get_state() == GoalStatus.ACTIVE
    client.cancel_all_goals()
    assert client.wait_for_result(2.0) and client.get_state() == GoalStatus.PREEMPTED


def test_send_goal_and_wait(ctx: Context) -> None:
    FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_server(5.0)
    assert client.send_goal_and_wait({"order": 3}) == GoalStatus.SUCCEEDED
    state = client.send_goal_and_wait({"order": 1000}, execute_timeout=1.0, preempt_timeout=1.0)
    assert state == GoalStatus.PREEMPTED


def test_reject_recall_and_cancel_before_the_goal(ctx: Context) -> None:
    node = ctx.create_node("server")
    decisions: dict[int, str] = {}

    def on_goal(gh: ServerGoalHandle) -> None:
        order = int(gh.get_goal().order)
        if decisions.get(order) == "reject":
            gh.set_rejected(None, "orders above 90 are refused")
        elif decisions.get(order) == "hold":
            pass  # stays PENDING until canceled
        else:
            gh.set_accepted()
            gh.set_succeeded({"sequence": [order]})

    def on_cancel(gh: ServerGoalHandle) -> None:
        gh.set_canceled(None, "recalled before it started")

    server = ActionServer(node, "fibonacci", FIB, on_goal, on_cancel)
    decisions.update({99: "reject", 7: "hold"})
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_server(5.0)
    client.send_goal({"order": 99})
    assert client.wait_for_result(2.0) and client.get_state() == GoalStatus.REJECTED
    assert client.get_goal_status_text() == "orders above 90 are refused"
    client.send_goal({"order": 7})
    ctx.spin_for(0.3)
    assert client.get_state() == GoalStatus.PENDING
    client.cancel_goal()
    assert client.wait_for_result(2.0) and client.get_state() == GoalStatus.RECALLED
    # a cancel that arrives before its goal recalls the goal when it comes
    GoalID = get_factory("actionlib_msgs/msg/GoalID")
    raw = ctx.create_node("raw")
    cancel_pub = raw.create_publisher(GoalID, "/fibonacci/cancel", 10)
    goal_pub = raw.create_publisher(server.spec.ActionGoal, "/fibonacci/goal", 10)
    results: list[Any] = []
    raw.create_subscription(server.spec.ActionResult, "/fibonacci/result", results.append, 10)
    cancel_pub.publish(GoalID(id="early-goal"))
    ctx.spin_for(0.1)
    goal_pub.publish(server.spec.ActionGoal(goal_id_id="early-goal", goal_order=1))
    ctx.spin_for(0.1)
    assert [(r.status.goal_id.id, int(r.status.status)) for r in results] == [
        ("early-goal", GoalStatus.RECALLED)
    ]


def test_a_goal_the_server_forgets_is_lost(ctx: Context) -> None:
    node = ctx.create_node("server")
    server = ActionServer(node, "fibonacci", FIB, lambda gh: gh.set_accepted())
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_server(5.0)
    client.send_goal({"order": 1})
    ctx.spin_for(0.3)
    assert client.get_state() == GoalStatus.ACTIVE
    server.status_list.clear()  # the server restarted, say
    assert client.wait_for_result(2.0) and client.get_state() == GoalStatus.LOST


def test_execute_callback_runs_in_its_own_thread() -> None:
    ctx = Context(clock="wall")
    node = ctx.create_node("server")
    threads: list[str] = []

    def execute(goal: Any) -> None:
        threads.append(threading.current_thread().name)
        seq = [0, 1]
        for _ in range(int(goal.order)):
            if server.is_preempt_requested():
                server.set_preempted()
                return
            seq.append(seq[-1] + seq[-2])
            server.publish_feedback({"sequence": seq})
            time.sleep(0.01)
        if goal.order == 13:
            raise ValueError("unlucky")
        if goal.order != 4:  # 4 forgets to end its goal
            server.set_succeeded({"sequence": seq})

    server = SimpleActionServer(node, "fib", FIB, execute)
    client = SimpleActionClient(ctx.create_node("client"), "fib", FIB)
    ctx.spin_in_thread()
    try:
        assert client.wait_for_server(5.0)
        client.send_goal({"order": 6})
        assert client.wait_for_result(5.0) and client.get_state() == GoalStatus.SUCCEEDED
        assert list(client.get_result().sequence)[-1] == 13
        client.send_goal({"order": 13})
        assert client.wait_for_result(5.0) and client.get_state() == GoalStatus.ABORTED
        assert client.get_goal_status_text() == "Exception in execute callback: unlucky"
        client.send_goal({"order": 4})
        assert client.wait_for_result(5.0) and client.get_state() == GoalStatus.ABORTED
        assert "did not" in client.get_goal_status_text()
        client.send_goal({"order": 100000})
        time.sleep(0.05)
        client.cancel_goal()
        assert client.wait_for_result(5.0) and client.get_state() == GoalStatus.PREEMPTED
    finally:
        server.shutdown()
        ctx.shutdown()
    assert set(threads) == {"actionlib-/fib"}


def test_blocking_inside_a_callback_is_an_error(ctx: Context) -> None:
    FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    errors: list[str] = []

    def done(state: int, result: Any) -> None:
        try:
            client.wait_for_result(1.0)
        except RuntimeError as err:
            errors.append(str(err))

    assert client.wait_for_server(5.0)
    client.send_goal({"order": 1}, done_cb=done)
    ctx.spin_for(1.0)
    assert errors and "would stop the executor" in errors[0]


def test_goal_ids_and_status_names(ctx: Context) -> None:
    FibServer(ctx)
    client = ActionClient(ctx.create_node("patrol"), "fibonacci", FIB)
    assert client.wait_for_server(5.0)
    ctx.spin_for(1.5)
    gh = client.send_goal({"order": 1})
    assert gh.goal_id == "/patrol-1-1.500"  # actionlib's <caller>-<n>-<stamp>
    assert client.send_goal({"order": 1}).goal_id.startswith("/patrol-2-")
    assert [status_name(s) for s in range(10)] == [
        "PENDING",
        "ACTIVE",
        "PREEMPTED",
        "SUCCEEDED",
        "ABORTED",
        "REJECTED",
        "PREEMPTING",
        "RECALLING",
        "RECALLED",
        "LOST",
    ]
    assert status_name(42) == "NO_SUCH_STATE_42"
    assert Time(0) < ctx.now()


def test_seeded_runs_are_identical() -> None:
    def run() -> list[Any]:
        ctx = Context()
        FibServer(ctx)
        status = _status_log(ctx)
        client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
        client.wait_for_server(5.0)
        client.send_goal({"order": 8})
        client.wait_for_result(5.0)
        client.send_goal({"order": 100})
        ctx.spin_for(0.2)
        client.cancel_goal()
        client.wait_for_result(5.0)
        return [status, ctx.now()]

    assert run() == run()


def test_feedback_and_status_copies_match_the_factory_built_messages(ctx: Context) -> None:
    """The server builds feedback and status snapshots with the rosbags classes directly:
    the same bytes (and field types) as the factory-built messages they replaced."""
    from roverlab.actionlib import server as srv
    from roverlab.msgs.cdr import serialize

    fib = FibServer(ctx)
    client = SimpleActionClient(ctx.create_node("client"), "fibonacci", FIB)
    assert client.wait_for_server(timeout=5.0)
    seen: list[tuple[Any, int]] = []
    ctx.create_node("fb_echo").create_subscription(
        "actionlib_tutorials/FibonacciActionFeedback",
        "/fibonacci/feedback",
        lambda m: seen.append((m, ctx.executor.now_ns)),
        100,
    )
    client.send_goal({"order": 3})
    assert client.wait_for_result(timeout=10.0)
    assert len(seen) == 3
    spec = fib.server.spec
    for msg, now_ns in seen:
        plain = spec.ActionFeedback()
        plain.header.stamp = Time(now_ns).to_msg()
        plain.status = srv.GoalStatusMsg(
            goal_id=srv.GoalID(stamp=msg.status.goal_id.stamp, id=msg.status.goal_id.id),
            status=int(msg.status.status),
            text=str(msg.status.text),
        )
        plain.feedback = spec.Feedback.from_dict({"sequence": list(msg.feedback.sequence)})
        assert serialize(msg) == serialize(plain)
        assert type(msg.status.status) is int and type(msg.header.frame_id) is str
    tracker = srv.GoalStatusMsg(
        goal_id=srv.GoalID(stamp=Time(7).to_msg(), id="g"), status=GoalStatus.ACTIVE, text="t"
    )
    copy = srv._copy_status(tracker)
    assert copy == tracker and copy is not tracker and copy.goal_id is not tracker.goal_id


def test_a_feedback_message_is_sent_as_given_and_a_dict_through_from_dict() -> None:
    """A feedback message of the action's type (move_base builds its MoveBaseFeedback each
    cycle) is sent as it is: the same message as ``from_dict`` makes of the dict, the
    value kept, not copied; dicts go through ``from_dict`` with its checks."""
    from roverlab.actionlib import server as srv
    from roverlab.msgs import get_factory
    from roverlab.msgs.cdr import serialize

    feedback = get_factory("move_base_msgs/msg/MoveBaseFeedback")
    pose = get_factory("geometry_msgs/msg/PoseStamped")(
        header={"frame_id": "map", "stamp": {"sec": 3}}, pose={"position": {"x": 1.5}}
    )
    given = feedback.cls(base_position=pose)
    fast = srv._as_message(given, feedback)
    plain = feedback.from_dict({"base_position": pose})
    assert type(fast) is type(plain) and serialize(fast) == serialize(plain)
    assert fast is given and fast.base_position is pose
    nested = srv._as_message({"base_position": {"pose": {"position": {"y": 2.0}}}}, feedback)
    assert nested.base_position.pose.position.y == 2.0
    with pytest.raises(Exception, match="base_positon"):
        srv._as_message({"base_positon": pose}, feedback)
    with pytest.raises(Exception):  # noqa: B017 - a Twist is no PoseStamped: from_dict refuses
        srv._as_message({"base_position": get_factory("geometry_msgs/msg/Twist")()}, feedback)
