"""roslaunch XML: substitutions, args, params, includes, groups, and the seeds' files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from roverlab.core import Context
from roverlab.description import find_package
from roverlab.launch import LaunchError, build_launch, load_launch
from roverlab.tf import Buffer, TransformListener
from tests.helpers.nodes import run_main


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_args_params_groups_includes_and_substitutions(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROVER_TEST_ENV", "fromenv")
    _write(
        tmp_path,
        "inner.launch",
        """<launch>
  <arg name="speed" default="1.0"/>
  <node pkg="p" type="t" name="inner" args="--speed $(arg speed)">
    <param name="speed" value="$(arg speed)"/>
  </node>
</launch>""",
    )
    top = _write(
        tmp_path,
        "top.launch",
        """<launch>
  <arg name="robot" default="mybot"/>
  <arg name="use_x" default="true"/>
  <arg name="fixed" value="42"/>
  <param name="rate" value="10"/>
  <param name="ratio" value="0.5"/>
  <param name="flag" value="true"/>
  <param name="label" type="str" value="007"/>
  <param name="home" value="$(optenv NO_SUCH_VAR /tmp)"/>
  <param name="env" value="$(env ROVER_TEST_ENV)"/>
  <param name="sum" value="$(eval 2 * arg('fixed'))"/>
  <rosparam>
    amcl: {min_particles: 500, laser: {max_beams: 30}}
  </rosparam>
  <remap from="scan" to="base_scan"/>
  <group ns="robot1" if="$(arg use_x)">
    <node pkg="p" type="t" name="a_$(arg robot)">
      <remap from="odom" to="odom_fused"/>
      <rosparam param="list">[1, 2, 3]</rosparam>
    </node>
  </group>
  <node pkg="p" type="t" name="skipped" unless="$(arg use_x)"/>
  <include file="$(dirname)/inner.launch" ns="sub">
    <arg name="speed" value="0.3"/>
  </include>
</launch>""",
    )
    spec = load_launch(top, {"robot": "mycar"})
    assert spec.params["/rate"] == 10 and spec.params["/ratio"] == 0.5
    assert spec.params["/flag"] is True and spec.params["/label"] == "007"
    assert spec.params["/home"] == "/tmp" and spec.params["/env"] == "fromenv"
    assert spec.params["/sum"] == 84
    assert spec.params["/amcl/min_particles"] == 500
    assert spec.params["/amcl/laser/max_beams"] == 30
    names = [(n.namespace, n.name) for n in spec.nodes]
    assert names == [("/robot1", "a_mycar"), ("/sub", "inner")]
    a = spec.nodes[0]
    assert a.remaps == {"scan": "base_scan", "odom": "odom_fused"}
    assert a.params == {"list": [1, 2, 3]}
    inner = spec.nodes[1]
    assert inner.args == "--speed 0.3" and inner.params == {"speed": 0.3}
    assert [p.name for p in spec.files] == ["top.launch", "inner.launch"]


@pytest.mark.parametrize(
    ("body", "args", "needle"),
    [
        (
            "<launch><node pkg='p' type='t' name='x' args='$(arg nope)'/></launch>",
            {},
            "arg 'nope' is not set",
        ),
        ("<launch><bogus/></launch>", {}, "<bogus>: unknown launch element"),
        ("<launch><node pkg='p'", {}, "malformed XML"),
        ("<robot/>", {}, "root element must be <launch>"),
        ("<launch><arg name='a' value='1'/></launch>", {"a": "2"}, "fixed value"),
        ("<launch><include file='nowhere.launch'/></launch>", {}, "does not exist"),
        ("<launch><param name='x' value='$(find no_such_pkg)'/></launch>", {}, "no_such_pkg"),
        ("<launch><group if='maybe'/></launch>", {}, "if= needs true/false"),
    ],
)
def test_bad_launch_files_are_one_line(
    tmp_path: Path, body: str, args: dict[str, str], needle: str
) -> None:
    path = _write(tmp_path, "bad.launch", body)
    with pytest.raises(LaunchError) as info:
        load_launch(path, args)
    msg = str(info.value)
    assert "bad.launch" in msg and needle in msg and "\n" not in msg


def test_seed_000_mbot_launch_runs_the_simulation() -> None:
    ctx = Context()
    launch = build_launch(
        find_package("mbot_description") / "launch/mbot_laser_nav_gazebo.launch", context=ctx
    )
    assert [n.get_name() for n in launch.nodes] == [
        "joint_state_publisher",
        "robot_state_publisher",
        "gazebo",
    ]
    rsp = launch.nodes[1]
    assert rsp.get_parameter("publish_frequency").value == 50.0
    assert launch.warnings == []
    buf = Buffer()
    TransformListener(buf, ctx.create_node("listener"))
    ctx.spin_for(2.0)
    assert "/scan" in ctx.graph.topics and "/odom" in ctx.graph.topics
    from roverlab.core import Time

    tf, _ = buf.lookup_transform("odom", "laser_link", Time(0))
    assert tf.translation[2] > 0.1  # the laser sits on top of the robot


def test_two_launches_share_the_description_through_the_topic(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Seed 001: environment.launch sets robot_description; sensor.launch (started
    separately, as in the seed) runs robot_state_publisher without it."""
    monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", "0")  # its rviz node: the web dashboard
    ctx = Context()
    env = build_launch(find_package("mycar") / "launch/environment.launch", context=ctx)
    sensor = build_launch(find_package("mycar") / "launch/sensor.launch", context=ctx)
    rviz = [n for n in sensor.nodes if n.get_name() == "rviz"]
    assert rviz and not any("rviz" in w for w in sensor.warnings)
    buf = Buffer()
    TransformListener(buf, ctx.create_node("listener"))
    ctx.spin_for(1.0)
    from roverlab.core import Time

    # static_transform_publisher args="0 0 0 -1.57 0 -1.57 /support /support_depth"
    tf, _ = buf.lookup_transform("support", "support_depth", Time(0))
    assert tf.translation == pytest.approx((0.0, 0.0, 0.0))
    # robot_state_publisher (started once /robot_description arrived) links the laser
    tf2, _ = buf.lookup_transform("base_footprint", "laser", Time(0))
    assert tf2.translation[2] == pytest.approx(0.27, abs=1e-6)
    assert env.simulator is not None
    ctx.shutdown()  # stops the dashboard too


def test_cli_launch_with_args_and_record(tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "l.mcap"
    r = subprocess.run(
        [sys.executable, "-m", "roverlab.cli", "launch", "bingda_tutorials",
         "simulation_robot.launch", "laser_visual:=true", "--rate", "max",
         "--duration", "3", "--no-expose", "--record", str(out)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "started 2 nodes: /robot_state_publisher, /gazebo" in r.stderr
    with AnyReader([out]) as reader:
        topics = {c.topic for c in reader.connections}
    assert {"/scan", "/imu", "/odom", "/image_raw", "/tf", "/robot_description"} <= topics
    # a bad launch file in this process (stderr captured at the file descriptor): a second
    # process would only pay the import again
    capfd.readouterr()
    assert run_main(["launch", "mycar", "nothing.launch", "--no-expose"]) == 2
    err = capfd.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "not found in package mycar" in err, err


def test_map_server_node_from_a_launch_file(tmp_path: Path) -> None:
    import numpy as np

    from roverlab.maps import save_map

    grid = np.full((20, 30), -1, dtype=np.int8)
    grid[5:15, 5:25] = 0
    grid[10, 5:25] = 100
    save_map(tmp_path / "room", grid, resolution=0.1, origin=(-1.0, -2.0, 0.0))
    launch_file = _write(
        tmp_path,
        "nav.launch",
        f"""<launch>
  <arg name="map_file" default="{tmp_path}/room.yaml"/>
  <node pkg="map_server" name="map_server" type="map_server" args="$(arg map_file)">
    <param name="frame_id" value="map"/>
  </node>
</launch>""",
    )
    ctx = Context()
    build_launch(launch_file, context=ctx)
    got: list[object] = []
    ctx.create_node("late").create_subscription("nav_msgs/msg/OccupancyGrid", "/map", got.append, 1)
    ctx.spin_for(0.1)
    assert len(got) == 1
    m = got[0]
    assert (m.info.width, m.info.height) == (30, 20)  # type: ignore[attr-defined]
    assert m.info.origin.position.x == pytest.approx(-1.0)  # type: ignore[attr-defined]
