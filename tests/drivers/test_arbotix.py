"""arbotix diff_controller on a fake base, and seed 004's urdlee package."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from roverlab.core import Context, Time
from roverlab.description import find_package
from roverlab.drivers.arbotix import DiffController, DiffControllerParams, parse_controllers
from roverlab.drivers.errors import DriverError
from roverlab.drivers.odometry import EncoderOdometry, wheel_setpoints
from roverlab.launch import LaunchError, build_launch, load_launch
from roverlab.launch.xml import _flatten
from roverlab.msgs import Twist
from roverlab.msgs import classes as mc
from roverlab.tf import Buffer, TransformListener

URDLEE = find_package("urdlee")


def seed_controllers() -> list[DiffControllerParams]:
    data = yaml.safe_load((URDLEE / "config/control.yaml").read_text())
    diffs, notes = parse_controllers(_flatten(data))
    assert notes == []
    return diffs


def test_control_yaml_parameters() -> None:
    (p,) = seed_controllers()
    assert (p.name, p.base_frame_id, p.odom_frame_id) == (
        "base_controller",
        "base_footprint",
        "odom",
    )
    assert (p.base_width, p.ticks_meter, p.accel_limit, p.rate, p.timeout) == (
        0.2,
        2000,
        1.0,
        10,
        1,
    )
    assert (p.Kp, p.Kd, p.Ki, p.Ko) == (12, 12, 0, 50)
    assert p.max_accel == 200  # int(1.0 * 2000 / 10) ticks per frame per update


def test_bad_controller_parameters() -> None:
    with pytest.raises(DriverError, match="base_width is required"):
        parse_controllers({"controllers/b/type": "diff_controller", "controllers/b/ticks_meter": 1})
    with pytest.raises(DriverError, match="ticks_meter must be a number"):
        parse_controllers(
            {
                "controllers/b/type": "diff_controller",
                "controllers/b/ticks_meter": "x",
                "controllers/b/base_width": 0.2,
            }
        )
    with pytest.raises(DriverError, match="rate must be > 0"):
        DiffControllerParams(name="b", ticks_meter=100, base_width=0.2, rate=0)
    diffs, notes = parse_controllers({"controllers/arm/type": "follow_controller"})
    assert diffs == [] and "follow_controller" in notes[0]


def test_setpoints_truncate_like_arbotix() -> None:
    # (0.2 -/+ 0.5 * 0.2 / 2) * 2000 / 30 = 10.0 and 16.67 -> 10, 16 ticks per frame
    assert wheel_setpoints(0.2, 0.5, wheel_track_m=0.2, ticks_per_meter=2000) == (10, 16)
    with pytest.raises(DriverError, match="not finite"):
        wheel_setpoints(math.nan, 0.0, wheel_track_m=0.2, ticks_per_meter=2000)


def test_odometry_from_ticks_straight_and_turning() -> None:
    odo = EncoderOdometry(ticks_per_meter=1000, wheel_track_m=0.5)
    odo.update(0, 0, 0.1)
    s = odo.update(1000, 1000, 1.0)
    assert (s.x, s.y, s.th, s.vx) == pytest.approx((1.0, 0.0, 0.0, 1.0))
    odo.reset()
    odo.update(0, 0, 0.1)
    quarter = 0.25 * math.pi / 2  # each wheel travels track / 2 * angle
    s = odo.update(-round(quarter * 1000), round(quarter * 1000), 1.0)
    assert s.th == pytest.approx(math.pi / 2, abs=2e-3) and abs(s.x) < 1e-9


def test_ramp_is_bounded_by_max_accel_and_timeout_stops() -> None:
    p = DiffControllerParams(name="b", ticks_meter=2000, base_width=0.2, accel_limit=0.03)
    assert p.max_accel == 6  # ticks per frame per update = 0.09 m/s of wheel speed
    c = DiffController(p, now_s=0.0)
    c.command(0.5, 0.0, now_s=0.0)
    speeds = []
    t = 0.0
    while t < 3.0:
        t = round(t + 0.11, 2)
        if c.due(t):
            c.update(t)
            speeds.append(c.wheel_speeds_mps()[0])
            if t < 0.9:
                c.command(0.5, 0.0, now_s=t)
    steps = [b - a for a, b in zip([0.0, *speeds], speeds, strict=False)]
    assert max(abs(s) for s in steps) <= 6 * 30 / 2000 + 1e-12
    assert max(speeds) == pytest.approx(0.495)  # int(0.5 * 2000 / 30) = 33 ticks per frame
    assert speeds[-1] == 0.0  # the timeout (1 s after the last command) ramped it down


def test_launch_seed_004_drives_odometry(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROVERLAB_DASHBOARD_PORT", "0")
    ctx = Context()
    launch = build_launch(load_launch(URDLEE / "launch/car_ee.launch"), context=ctx)
    names = {n.get_name() for n in launch.nodes}
    assert {"arbotix", "rviz", "robot_state_publisher", "joint_state_publisher_gui"} <= names
    assert launch.warnings == []
    node = ctx.create_node("driver")
    pub = node.create_publisher(mc.Twist, "/cmd_vel", 10)
    odoms: list[mc.Odometry] = []
    node.create_subscription(mc.Odometry, "/odom", odoms.append, 10)
    node.create_timer(0.1, lambda: pub.publish(Twist(linear_x=0.2, angular_z=0.5)))
    buf = Buffer()
    TransformListener(buf, node)
    ctx.spin_for(5.0)
    # arbotix's truncation: wheels at 10 and 16 ticks per frame -> 0.195 m/s, 0.45 rad/s
    last = odoms[-1]
    assert last.header.frame_id == "odom" and last.child_frame_id == "base_footprint"
    assert last.twist.twist.linear.x == pytest.approx(0.195, abs=3e-3)
    assert last.twist.twist.angular.z == pytest.approx(0.45, abs=0.03)
    # with accel_limit 1.0 the ramp (200 ticks per frame per update) reaches it at once
    assert odoms[1].twist.twist.linear.x == pytest.approx(0.195, abs=3e-3)
    # the poses lie on a circle of radius v / w through the start: the chord to the
    # start is 2 r sin(th / 2) (arbotix's step, rotated by -dth, turns the circle a bit)
    x, y = last.pose.pose.position.x, last.pose.pose.position.y
    th = 2 * math.atan2(last.pose.pose.orientation.z, last.pose.pose.orientation.w)
    r = 0.195 / 0.45
    assert math.hypot(x, y) == pytest.approx(2 * r * math.sin(th / 2), abs=0.01)
    assert th == pytest.approx(
        0.45 * (odoms[-1].header.stamp.sec - 0.11 + odoms[-1].header.stamp.nanosec * 1e-9), abs=0.06
    )
    tf, _ = buf.lookup_transform("odom", "laser", Time(0))
    assert tf.translation[0] == pytest.approx(x, abs=1e-6)
    assert tf.translation[2] == pytest.approx(0.015 + 0.04 + 0.04 + 0.075 + 0.075 + 0.025)
    ctx.shutdown()


def test_nan_command_is_ignored_and_sim_false_is_skipped(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    launch_file = tmp_path / "a.launch"
    launch_file.write_text(
        f"""<launch>
  <arg name="sim" default="true"/>
  <node name="arbotix" pkg="arbotix_python" type="arbotix_driver">
    <rosparam file="{URDLEE}/config/control.yaml" command="load"/>
    <param name="sim" value="$(arg sim)"/>
  </node>
</launch>"""
    )
    ctx = Context()
    skipped = build_launch(load_launch(launch_file, {"sim": "false"}), context=ctx)
    assert skipped.nodes == [] and "only sim: true" in skipped.warnings[0]
    launch = build_launch(load_launch(launch_file, {"sim": "true"}), context=ctx)
    node = ctx.create_node("driver")
    pub = node.create_publisher(mc.Twist, "/cmd_vel", 10)
    odoms: list[mc.Odometry] = []
    node.create_subscription(mc.Odometry, "/odom", odoms.append, 10)
    ctx.spin_for(0.5)
    pub.publish(Twist(linear_x=0.2))
    ctx.spin_for(0.5)
    pub.publish(Twist(linear_x=math.nan))
    ctx.spin_for(0.5)
    assert launch.nodes[0].get_name() == "arbotix"
    assert odoms[-1].twist.twist.linear.x == pytest.approx(0.195, abs=3e-3)
    assert all(math.isfinite(o.pose.pose.position.x) for o in odoms)
    ctx.shutdown()


def test_missing_required_parameter_names_the_file(tmp_path: Path) -> None:
    cfg = tmp_path / "control.yaml"
    cfg.write_text("controllers: {b: {type: diff_controller, ticks_meter: 100}}\n")
    launch_file = tmp_path / "a.launch"
    launch_file.write_text(
        f"""<launch><node name="arbotix" pkg="arbotix_python" type="arbotix_driver">
  <rosparam file="{cfg}" command="load"/><param name="sim" value="true"/>
</node></launch>"""
    )
    with pytest.raises(LaunchError, match=r"a\.launch.*base_width is required"):
        build_launch(load_launch(launch_file), context=Context())
