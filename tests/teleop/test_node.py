"""The teleop nodes in one process: parameters, remapping, the main loop, the final zero."""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from typing import Any

import pytest

from roverlab.core import Context, ParameterError
from roverlab.msgs import Twist
from roverlab.teleop import (
    CTRL_C,
    HELP_TEXT,
    SMOOTH_HELP_TEXT,
    MbotTeleopNode,
    TeleopError,
    TeleopTwistKeyboardNode,
    TwistCommand,
    command_to_twist,
    vels,
)
from tests.teleop.twists import IQJJ_STOP_T, ZERO, Fields


class ListKeys:
    """A key source that replays keys, then reports end of input."""

    def __init__(self, keys: Iterable[str]) -> None:
        self.keys = list(keys)
        self.timeouts: list[float | None] = []

    def read_key(self, timeout_s: float | None = None) -> str:
        self.timeouts.append(timeout_s)
        if not self.keys:
            raise EOFError
        return self.keys.pop(0)


class Recorder:
    """Collects the Twists published on a topic of a context."""

    def __init__(self, ctx: Context, topic: str = "/cmd_vel") -> None:
        self.ctx = ctx
        self.msgs: list[Any] = []
        node = ctx.create_node("recorder")
        node.create_subscription(Twist, topic, self.msgs.append, 1000)

    def fields(self) -> list[Fields]:
        self.ctx.spin_for(0.0)
        out = []
        for m in self.msgs:
            assert m.angular.x == 0.0 and m.angular.y == 0.0
            out.append((m.linear.x, m.linear.y, m.linear.z, m.angular.z))
        return out


def test_keyboard_node_loop_publishes_each_key_then_zero() -> None:
    ctx = Context()
    rec = Recorder(ctx)
    node = TeleopTwistKeyboardNode(context=ctx, parameter_overrides={"speed": 0.4, "turn": 0.8})
    assert node.get_name() == "teleop_twist_keyboard"
    assert node.publisher.topic_name == "/cmd_vel"
    lines: list[str] = []
    keys = ListKeys(["i", "q", "J", "j", "k", "t", CTRL_C, "i"])
    node.run(keys, lines.append)
    assert rec.fields() == [
        *IQJJ_STOP_T,
        ZERO,  # the finally: after Ctrl-C (which itself publishes nothing)
    ]
    assert keys.keys == ["i"]  # nothing read after Ctrl-C
    assert keys.timeouts == [None] * 7  # getKey() blocks
    assert lines == [HELP_TEXT, vels(0.4, 0.8), "currently:\tspeed 0.44\tturn 0.88 "]


def test_defaults_and_parameters() -> None:
    ctx = Context()
    node = TeleopTwistKeyboardNode(context=ctx)
    assert node.get_parameter("speed").value == 0.3
    assert node.get_parameter("turn").value == 0.5
    assert node.get_parameter("repeat_rate").value == 0.0
    assert (node.logic.speed, node.logic.turn) == (0.3, 0.5)
    assert not node.has_parameter("scale_linear")


def test_end_of_input_and_errors_still_publish_zero() -> None:
    ctx = Context()
    rec = Recorder(ctx)
    node = TeleopTwistKeyboardNode(context=ctx, node_name="t1")
    node.run(ListKeys(["i"]), lambda _line: None)  # EOF after one key
    assert rec.fields() == [(0.3, 0.0, 0.0, 0.0), ZERO]

    class Broken:
        def read_key(self, timeout_s: float | None = None) -> str:
            raise RuntimeError("keyboard on fire")

    node2 = TeleopTwistKeyboardNode(context=ctx, node_name="t2")
    node2.handle_key("u")
    with pytest.raises(RuntimeError, match="on fire"):
        node2.run(Broken(), lambda _line: None)
    assert rec.fields()[-2:] == [(0.3, 0.0, 0.0, 0.5), ZERO]
    node2.stop()  # a second stop publishes nothing more
    assert len(rec.fields()) == 4


def test_smooth_node_ramps_and_maps_scale_parameters() -> None:
    ctx = Context()
    rec = Recorder(ctx)
    node = MbotTeleopNode(
        context=ctx, parameter_overrides={"scale_linear": 0.1, "scale_angular": 0.4}
    )
    assert node.get_name() == "mbot_teleop"
    assert (node.logic.speed, node.logic.turn) == (0.1, 0.4)
    lines: list[str] = []
    keys = ListKeys(["i", "", "", "", "", "", " ", "u", CTRL_C])
    node.run(keys, lines.append)
    lin = [f[0] for f in rec.fields()]
    assert lin == pytest.approx([0.02, 0.04, 0.06, 0.08, 0.1, 0.08, 0.0, 0.02, 0.0])
    assert rec.fields()[-2][3] == pytest.approx(0.1)  # 'u' turns left, ramped by 0.1
    assert set(keys.timeouts) == {0.1}
    assert lines[0] == SMOOTH_HELP_TEXT


def test_smooth_node_defaults_and_speed_alias() -> None:
    ctx = Context()
    node = MbotTeleopNode(context=ctx)
    assert (node.logic.speed, node.logic.turn) == (0.2, 1.0)
    assert node.get_parameter("scale_linear").value == 0.2
    alias = MbotTeleopNode(
        context=ctx, node_name="m2", parameter_overrides={"speed": 0.3, "turn": 0.5}
    )
    assert (alias.logic.speed, alias.logic.turn) == (0.3, 0.5)
    both = MbotTeleopNode(
        context=ctx, node_name="m3", parameter_overrides={"speed": 0.3, "scale_linear": 0.15}
    )
    assert both.logic.speed == 0.15  # the launch file's name wins


@pytest.mark.parametrize(
    ("overrides", "match"),
    [
        ({"speed": "abc"}, "speed"),
        ({"speed": math.nan}, "speed"),
        ({"turn": math.inf}, "turn"),
        ({"speed": -0.2}, "minimum"),
        ({"repeat_rate": math.nan}, "repeat_rate"),
        ({"sped": 0.2}, "did you mean 'speed'"),
        ({"scale_linear": 0.2}, "scale_linear"),  # only mbot_teleop has it
    ],
)
def test_bad_parameters_are_rejected(overrides: dict[str, Any], match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        TeleopTwistKeyboardNode(context=Context(), parameter_overrides=overrides)


def test_parameters_from_launch_file_strings() -> None:
    node = TeleopTwistKeyboardNode(context=Context(), parameter_overrides={"speed": "0.25"})
    assert node.logic.speed == 0.25


def test_remapping_namespace_and_topic() -> None:
    ctx = Context()
    remapped = TeleopTwistKeyboardNode(
        context=ctx, node_name="a", remappings={"cmd_vel": "/robot1/cmd_vel"}
    )
    assert remapped.publisher.topic_name == "/robot1/cmd_vel"
    ns = TeleopTwistKeyboardNode(context=ctx, node_name="b", namespace="/robot2")
    assert ns.publisher.topic_name == "/robot2/cmd_vel"
    other = TeleopTwistKeyboardNode(context=ctx, node_name="c", topic="/mobile_base/cmd_vel")
    assert other.publisher.topic_name == "/mobile_base/cmd_vel"


def test_repeat_rate_republishes_the_last_twist_after_the_first_key() -> None:
    ctx = Context()  # sim time: the timer fires deterministically
    rec = Recorder(ctx)
    node = TeleopTwistKeyboardNode(context=ctx, parameter_overrides={"repeat_rate": 10.0})
    ctx.spin_for(0.55)
    assert rec.fields() == []  # nothing before the first key
    node.handle_key("l")
    ctx.spin_for(0.5)
    assert rec.fields() == [(0.0, 0.0, 0.0, -0.5)] * 6  # the key, then 5 repeats at 10 Hz
    node.stop()
    ctx.spin_for(0.5)
    assert rec.fields()[-1] == ZERO and len(rec.fields()) == 7


def test_no_repeat_by_default() -> None:
    ctx = Context()
    rec = Recorder(ctx)
    node = TeleopTwistKeyboardNode(context=ctx)
    node.handle_key("i")
    ctx.spin_for(2.0)
    assert rec.fields() == [(0.3, 0.0, 0.0, 0.0)]


def test_stop_from_another_thread_waits_for_the_spinning_executor() -> None:
    ctx = Context(clock="wall")
    got: list[Any] = []
    ctx.create_node("rx").create_subscription(Twist, "/cmd_vel", got.append, 10)
    node = TeleopTwistKeyboardNode(context=ctx)
    ctx.spin_in_thread()
    try:
        node.handle_key("i")
        node.stop()
        deadline = time.monotonic() + 2.0
        while len(got) < 2 and time.monotonic() < deadline:
            time.sleep(0.01)
        assert [m.linear.x for m in got] == [0.3, 0.0]
    finally:
        ctx.shutdown()


def test_command_to_twist_refuses_non_finite() -> None:
    msg = command_to_twist(TwistCommand(0.1, -0.2, 0.3, 0.4))
    assert (msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.z) == (0.1, -0.2, 0.3, 0.4)
    with pytest.raises(TeleopError, match="non-finite"):
        command_to_twist(TwistCommand(linear_x=math.nan))
    with pytest.raises(TeleopError, match="non-finite"):
        command_to_twist(TwistCommand(angular_z=-math.inf))
