"""A ROS 1 book-style package's launch files: xacro command spellings, state_publisher,
clear_params, rosparam load ns, tf/tf2_ros static_transform_publisher forms, joysticks
refused, the Gazebo world's and robot's warnings."""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import pytest

from roverlab.core import Context, Time
from roverlab.launch import LaunchError, build_launch, load_launch
from roverlab.launch.xml import _xacro_argv
from roverlab.tf import Buffer, TransformListener

PKGS = Path(__file__).resolve().parents[1] / "ros1_packages"
LAUNCH = PKGS / "book_robot_description" / "launch"


@pytest.fixture(autouse=True)
def _packages(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PKGS))


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        ("xacro f.xacro", ["f.xacro"]),
        ("xacro.py --inorder f.xacro a:=1", ["--inorder", "f.xacro", "a:=1"]),
        ("/opt/ros/kinetic/share/xacro/xacro.py f.xacro", ["f.xacro"]),
        ("python /x/xacro.py f.xacro", ["f.xacro"]),
        ("rosrun xacro xacro --inorder f.xacro", ["--inorder", "f.xacro"]),
        ("cat f.urdf", None),
    ],
)
def test_xacro_command_spellings(command: str, expected: list[str] | None) -> None:
    assert _xacro_argv(command.split()) == expected


def test_display_launch_xacro_py_state_publisher_clear_params_rosparam_ns() -> None:
    spec = load_launch(LAUNCH / "display_robot_rviz.launch")
    assert "kinect_link" in spec.params["/robot_description"]
    rsp = next(n for n in spec.nodes if n.name == "robot_state_publisher")
    assert rsp.type == "state_publisher" and rsp.clear_params
    assert rsp.params["settings/publish_rate"] == 25.0
    ctx = Context()
    try:
        started = build_launch(spec, context=ctx)
        names = {n.get_name() for n in started.nodes}
        assert {"robot_state_publisher", "joint_state_publisher"} <= names
    finally:
        ctx.shutdown()


def test_gazebo_launch_static_tfs_joystick_refused_and_world_warnings() -> None:
    ctx = Context(clock="sim")
    try:
        started = build_launch(LAUNCH / "robot_laser_gazebo.launch", context=ctx)
        buf = Buffer()
        TransformListener(buf, ctx.create_node("listener"))
        ctx.spin_for(0.5)
        tf, _ = buf.lookup_transform("map", "odom", Time(0))  # leading slashes dropped
        assert tf.translation == pytest.approx((0.0, 0.0, 0.0))
        cam, _ = buf.lookup_transform("base_link", "camera_mount", Time(0))
        assert cam.translation == pytest.approx((0.1, 0.0, 0.3))
        assert cam.rotation == pytest.approx((0.0, 0.0, 0.7071068, 0.7071068))
    finally:
        ctx.shutdown()
    joy = [w for w in started.warnings if "no joystick here" in w]
    assert len(joy) == 2 and "joy/joy_node" in joy[0] and "teleop_twist_joy" in joy[1]
    assert started.simulator is not None
    xacro = PKGS / "book_robot_description" / "urdf" / "robot_with_laser.urdf.xacro"
    assert started.robot_warnings  # named by the file robot_description's xacro read
    assert all(w.startswith(f"{xacro}: ") for w in started.robot_warnings)
    assert (
        started.world_warnings
        == [w for w in started.world_warnings if w.startswith("2 models skipped: hydrant_0")]
        and len(started.world_warnings) == 1
    )


ROBOT = """<robot name="box" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="side" value="0.4"/>
  <link name="base_link"><collision><geometry><box size="${side} ${side} 0.2"/></geometry>
  </collision></link>
  <gazebo reference="base_link"><mu1>0.2</mu1></gazebo>
</robot>"""


@pytest.mark.parametrize("how", ["xacro", "textfile", "value"])
def test_the_spawned_robots_notes_name_the_file_its_parameter_read(
    tmp_path: Path, how: str
) -> None:
    """A robot spawned from ``-param robot_description`` is named in its notes (and
    warnings) by the file the parameter was read from, else by the launch's element:
    never ``<string>``."""
    robot = tmp_path / "box.urdf.xacro"
    robot.write_text(ROBOT)
    urdf = tmp_path / "box.urdf"
    urdf.write_text(ROBOT.replace("${side}", "0.4"))
    param = {
        "xacro": f"command=\"$(find xacro)/xacro --inorder '{robot}'\"",
        "textfile": f'textfile="{urdf}"',
        "value": f"value={quoteattr(urdf.read_text())}",
    }[how]
    path = tmp_path / "box.launch"
    path.write_text(
        '<launch><include file="$(find gazebo_ros)/launch/empty_world.launch"/>'
        f'<param name="robot_description" {param}/>'
        '<node name="spawn" pkg="gazebo_ros" type="spawn_model" '
        'args="-urdf -model box -param robot_description"/></launch>'
    )
    ctx = Context(clock="sim")
    try:
        started = build_launch(path, context=ctx)
    finally:
        ctx.shutdown()
    (note,) = [n for n in started.notes if "mu1" in n]
    source = {"xacro": str(robot), "textfile": str(urdf)}.get(
        how, f'{path}: <param name="robot_description">'
    )
    assert note.startswith(f"{source}: <gazebo reference> settings not simulated"), note
    assert "<string>" not in note


def test_tf_static_transform_publisher_needs_its_period(tmp_path: Path) -> None:
    bad = tmp_path / "bad.launch"
    bad.write_text(
        '<launch><node pkg="tf" type="static_transform_publisher" name="s" '
        'args="0 0 0 0 0 0 map odom"/></launch>'
    )
    ctx = Context()
    try:
        with pytest.raises(LaunchError, match="period_in_ms"):
            build_launch(bad, context=ctx)
    finally:
        ctx.shutdown()
