"""Names, remapping, parameters and graph errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from roverlab.core import (
    Context,
    InvalidTopicNameError,
    ParameterError,
    TopicTypeError,
    load_parameter_file,
    parameters_for_node,
)
from roverlab.core.errors import GraphError
from roverlab.core.graph import resolve_name
from roverlab.msgs import String, Twist


@pytest.mark.parametrize(
    ("name", "ns", "node", "expected"),
    [
        ("/scan", "/", "n", "/scan"),
        ("scan", "/", "n", "/scan"),
        ("scan", "/robot1", "n", "/robot1/scan"),
        ("~/status", "/robot1", "amcl", "/robot1/amcl/status"),
        ("~status", "/", "amcl", "/amcl/status"),
        ("move_base_simple/goal", "/", "n", "/move_base_simple/goal"),
    ],
)
def test_resolve_name(name: str, ns: str, node: str, expected: str) -> None:
    assert resolve_name(name, ns, node) == expected


@pytest.mark.parametrize("bad", ["", "/a//b", "/a/", "/a b", "/1abc", "/a-b"])
def test_invalid_topic_names(bad: str) -> None:
    with pytest.raises(InvalidTopicNameError):
        resolve_name(bad)


def test_remapping_renames_topics() -> None:
    ctx = Context(publish_clock=False)
    gm = ctx.create_node("slam_gmapping", remappings={"scan": "/base_scan"})
    got: list[str] = []
    gm.create_subscription(String, "scan", lambda m: got.append(m.data), 10)
    pub = ctx.create_node("laser").create_publisher(String, "/base_scan", 10)
    pub.publish(String(data="hit"))
    ctx.spin_for(0.01)
    assert got == ["hit"]
    assert "/base_scan" in ctx.graph.topics and "/scan" not in ctx.graph.topics


def test_topic_type_mismatch_is_one_clear_error() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    node.create_publisher(Twist, "/cmd_vel", 10)
    with pytest.raises(TopicTypeError, match=r"'/cmd_vel' carries geometry_msgs/msg/Twist"):
        node.create_subscription(String, "/cmd_vel", lambda m: None, 10)


def test_ros1_type_names_are_accepted() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    pub = node.create_publisher("geometry_msgs/Twist", "/cmd_vel", 10)
    got: list[float] = []
    node.create_subscription(Twist, "/cmd_vel", lambda m: got.append(m.linear.x), 10)
    pub.publish(Twist(linear={"x": 0.3}))
    ctx.spin_for(0.01)
    assert got == [0.3]


def test_duplicate_node_name_is_refused() -> None:
    ctx = Context(publish_clock=False)
    ctx.create_node("amcl")
    with pytest.raises(GraphError, match="already exists"):
        ctx.create_node("amcl")


def test_parameters_typed_and_validated() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("gm", parameter_overrides={"particles": 30, "maxUrange": 4})
    assert node.declare_parameter("particles", 80).value == 30
    # an int override for a double parameter is converted, as ROS 1 launch files expect
    p = node.declare_parameter("maxUrange", 80.0)
    assert p.value == 4.0 and isinstance(p.value, float)
    assert node.declare_parameter("odom_frame", "odom").value == "odom"
    node.set_parameter("particles", 40)
    assert node.get_parameter("particles").value == 40
    with pytest.raises(ParameterError, match="'particles' is of type integer"):
        node.set_parameter("particles", "many")
    with pytest.raises(
        ParameterError, match=r"has no parameter 'particle'.*did you mean 'particles'"
    ):
        node.get_parameter("particle")
    # strings from launch files are parsed
    node.set_parameter("maxUrange", "5.5")
    assert node.get_parameter("maxUrange").value == 5.5


def test_mistyped_override_fails_at_declaration() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("gm", parameter_overrides={"particles": "lots"})
    with pytest.raises(ParameterError, match=r"node 'gm'.*particles"):
        node.declare_parameter("particles", 30)


def test_unknown_override_is_reported_when_spinning() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("gm", parameter_overrides={"partciles": 30})
    node.declare_parameter("particles", 30)
    with pytest.raises(ParameterError, match=r"no parameter 'partciles'.*'particles'"):
        ctx.spin_for(0.1)


def test_set_callback_can_reject() -> None:
    from roverlab.core import SetParametersResult

    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    node.declare_parameter("speed", 0.5)
    node.add_on_set_parameters_callback(
        lambda ps: SetParametersResult(all(p.value <= 1.0 for p in ps), "too fast")
    )
    assert node.set_parameter("speed", 0.8).successful
    result = node.set_parameter("speed", 3.0)
    assert not result.successful and result.reason == "too fast"
    assert node.get_parameter("speed").value == 0.8


def test_parameter_file_ros2_and_ros1_layouts(tmp_path: Path) -> None:
    ros2 = tmp_path / "gm.yaml"
    ros2.write_text(
        "/**:\n  ros__parameters:\n    use_sim_time: true\n"
        "slam_gmapping:\n  ros__parameters:\n    particles: 30\n    scan:\n      topic: /scan\n"
    )
    files = load_parameter_file(ros2)
    params = parameters_for_node(files, "slam_gmapping")
    assert params == {"use_sim_time": True, "particles": 30, "scan.topic": "/scan"}
    ros1 = tmp_path / "amcl.yaml"
    ros1.write_text("min_particles: 500\nodom_model_type: diff\n")
    assert parameters_for_node(load_parameter_file(ros1), "amcl") == {
        "min_particles": 500,
        "odom_model_type": "diff",
    }


def test_malformed_parameter_file_names_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("a: 1\nb: [1, 2\n")
    with pytest.raises(ParameterError, match=r"bad\.yaml: malformed YAML \(line \d+\)"):
        load_parameter_file(bad)
    with pytest.raises(ParameterError, match="cannot read"):
        load_parameter_file(tmp_path / "missing.yaml")


def test_destroyed_publisher_subscription_and_timer_stop_working() -> None:
    ctx = Context(publish_clock=False)
    node = ctx.create_node("n")
    pub = node.create_publisher(String, "/chatter", 10)
    got: list[str] = []
    ticks: list[int] = []
    sub = node.create_subscription(String, "/chatter", lambda m: got.append(m.data), 10)
    timer = node.create_timer(0.1, lambda: ticks.append(1))
    pub.publish(String(data="a"))
    ctx.spin_for(0.25)
    assert got == ["a"] and len(ticks) == 2
    sub.destroy()
    timer.destroy()
    pub.destroy()
    # a topic with neither publishers nor subscriptions leaves the graph
    assert pub not in node.publishers and "/chatter" not in ctx.graph.topics
    ctx.create_node("m").create_publisher(String, "/chatter", 10).publish(String(data="b"))
    ctx.spin_for(0.5)
    assert got == ["a"] and len(ticks) == 2
