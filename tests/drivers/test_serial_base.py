"""The ros_arduino_bridge base against an emulated board on a pty: odometry from ticks,
a board that goes silent, garbage, a missing port, seed 002's roborts_base mapping."""

from __future__ import annotations

import itertools
import logging
import math
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from roverlab.core import Context
from roverlab.drivers.errors import DriverError
from roverlab.drivers.serial_base import BaseController, BaseParams
from roverlab.drivers.serial_base.node import ArduinoBaseNode
from roverlab.launch import build_launch, load_launch
from roverlab.msgs import Twist
from roverlab.msgs import classes as mc
from tests.helpers.devices import ArduinoBaseEmulator

pytestmark = pytest.mark.timeout(120)

BASE = {
    "use_base_controller": True,
    "wheel_diameter": 0.1,
    "wheel_track": 0.3,
    "encoder_resolution": 3000,
    "base_controller_rate": 20.0,
    "accel_limit": 0.5,
}
TPM = 3000 / (0.1 * math.pi)  # ticks per metre


@pytest.fixture
def board() -> Iterator[ArduinoBaseEmulator]:
    dev = ArduinoBaseEmulator(seed=2)
    dev.start()
    yield dev
    dev.close()


def test_controller_ramp_and_timeout() -> None:
    params = BaseParams(
        wheel_diameter=0.1,
        wheel_track=0.3,
        encoder_resolution=3000,
        base_controller_rate=20.0,
        accel_limit=0.01,
    )
    c = BaseController(params, now_s=0.0)
    assert c.params.ticks_per_meter == pytest.approx(TPM)
    c.command(0.3, 0.0, now_s=0.0)  # int(0.3 * TPM / 30) = 95 ticks per frame
    sent = [c.update(0, 0, 0.05 * (i + 1))[1] for i in range(10)]
    step = 0.01 * TPM / 20  # max_accel: 4.77 ticks per frame per update
    assert sent[0] == int(step) and sent[-1] == 47  # still ramping after 10 updates
    assert all(b - a <= step + 1 for a, b in itertools.pairwise(sent))
    later = [c.update(0, 0, 1.0 + 0.05 * i)[1] for i in range(40)]
    assert later[-1] == 0  # no command for base_controller_timeout: ramped down to 0
    with pytest.raises(DriverError, match="not finite"):
        c.command(math.inf, 0.0, now_s=3.0)
    with pytest.raises(DriverError, match="wheel_track must be > 0"):
        BaseParams(wheel_diameter=0.1, wheel_track=0.0, encoder_resolution=10)


def run_base(
    contexts: list[Context], port: str, **extra: object
) -> tuple[Context, ArduinoBaseNode, list[mc.Odometry]]:
    ctx = Context(clock="wall")
    contexts.append(ctx)
    node = ArduinoBaseNode(
        ctx, boot_wait_s=0.5, parameter_overrides={"port": port, **BASE, **extra}
    )
    odoms: list[mc.Odometry] = []
    ctx.create_node("probe").create_subscription(mc.Odometry, "/odom", odoms.append, 100)
    return ctx, node, odoms


def drive(ctx: Context, twist: Twist, seconds: float) -> None:
    """Publish ``twist`` at 10 Hz for ``seconds`` (as ``rostopic pub -r 10``)."""
    node = ctx.nodes.get("/cmd") or ctx.create_node("cmd")
    pub = node.publishers[0] if node.publishers else node.create_publisher(mc.Twist, "/cmd_vel", 10)
    t = 0.0
    while t < seconds:
        pub.publish(twist)
        ctx.spin_for(0.1)
        t += 0.1


def test_odometry_from_ticks_within_one_percent(
    board: ArduinoBaseEmulator, contexts: list[Context]
) -> None:
    ctx, _node, odoms = run_base(contexts, board.port)
    ctx.spin_for(0.5)
    drive(ctx, Twist(linear_x=0.3), 3.0)
    drive(ctx, Twist(angular_z=1.0), 2.0)
    ctx.spin_for(1.5)  # the timeout stops the wheels
    deadline = time.monotonic() + 15.0  # a loaded machine: later
    while board.speed != (0, 0) and time.monotonic() < deadline:
        ctx.spin_for(0.2)
    ctx.spin_for(1.0)  # the counts after the stop come in
    assert board.commands[:3] == ["b", "u 20:12:0:50", "r"]
    assert any(c.startswith("m 95 95") for c in board.commands)
    left, right = math.floor(board.left), math.floor(board.right)
    last = odoms[-1]
    th = 2 * math.atan2(last.pose.pose.orientation.z, last.pose.pose.orientation.w)
    # ground truth from the board's counts: the straight leg, then the turn in place
    true_th = (right - left) / TPM / 0.3
    assert th == pytest.approx(true_th, rel=0.01)
    straight = 0.3 * 3.0
    dist = math.hypot(last.pose.pose.position.x, last.pose.pose.position.y)
    assert dist == pytest.approx(straight, rel=0.1)  # what the command asked, ramp aside
    travelled = sum(
        math.hypot(
            b.pose.pose.position.x - a.pose.pose.position.x,
            b.pose.pose.position.y - a.pose.pose.position.y,
        )
        for a, b in itertools.pairwise(odoms)
    )
    assert travelled == pytest.approx((left + right) / 2 / TPM, rel=0.01)
    assert last.child_frame_id == "base_link" and last.pose.covariance[35] == 0.2
    assert board.speed == (0, 0) and len(odoms) > 100
    ctx.shutdown()
    assert board.commands[-1] == "m 0 0"


def test_board_goes_silent_then_answers(
    board: ArduinoBaseEmulator, caplog: pytest.LogCaptureFixture, contexts: list[Context]
) -> None:
    caplog.set_level(logging.INFO, logger="roverlab")
    ctx, _node, odoms = run_base(contexts, board.port)
    drive(ctx, Twist(linear_x=0.2), 1.0)
    board.silent = True
    ctx.spin_for(3.0)
    frozen = len(odoms)
    ctx.spin_for(1.0)
    assert len(odoms) == frozen
    errors = [
        r.getMessage()
        for r in caplog.records
        if r.levelname == "ERROR" and r.getMessage().startswith(f"{board.port}:")
    ]
    assert errors[0] == (
        f"{board.port}: the board stopped answering (nothing for 1 s); retrying every 1 s"
    )
    board.silent = False
    x_before = odoms[-1].pose.pose.position.x
    drive(ctx, Twist(linear_x=0.2), 2.5)
    assert [r.getMessage() for r in caplog.records if "answers again" in r.getMessage()] == [
        f"{board.port}: the board answers again"
    ]
    assert odoms[-1].pose.pose.position.x > x_before + 0.2  # the pose was kept and grows
    ctx.shutdown()


def test_garbage_answers_are_skipped(board: ArduinoBaseEmulator, contexts: list[Context]) -> None:
    board.garbage_every = 4
    ctx, node, odoms = run_base(contexts, board.port)
    drive(ctx, Twist(linear_x=0.3), 3.0)
    ctx.spin_for(1.5)
    assert node.bad_answers > 5 and board.garbage_sent > 0
    dist = odoms[-1].pose.pose.position.x
    left, right = math.floor(board.left), math.floor(board.right)
    assert dist == pytest.approx((left + right) / 2 / TPM, rel=0.01)
    assert all(math.isfinite(o.pose.pose.position.x) for o in odoms)
    ctx.shutdown()


def test_missing_port_and_roborts_base_mapping(
    tmp_path: Path,
    caplog: pytest.LogCaptureFixture,
    board: ArduinoBaseEmulator,
    contexts: list[Context],
) -> None:
    ctx, _node, _odoms = run_base(contexts, "/dev/ttyACM_roverlab_none")
    ctx.spin_for(2.5)
    errors = [
        r.getMessage()
        for r in caplog.records
        if r.levelname == "ERROR" and "roverlab_none" in r.getMessage()
    ]
    assert len(errors) == 1 and "cannot open the serial port" in errors[0]
    ctx.shutdown()
    yaml_file = tmp_path / "roborts_base_parameter.yaml"
    yaml_file.write_text(
        f"port: {board.port}\nwheel_diameter: 0.1\nwheel_track: 0.3\n"
        "encoder_resolution: 3000\nbase_controller_rate: 20.0\n"
    )
    launch_file = tmp_path / "base.launch"
    launch_file.write_text(
        f"""<launch>
  <rosparam command="load" file="{yaml_file}"/>
  <node pkg="roborts_base" type="roborts_base_node" name="roborts_base_node" respawn="true"/>
</launch>"""
    )
    ctx = Context(clock="wall")
    contexts.append(ctx)
    launch = build_launch(load_launch(launch_file), context=ctx)
    assert launch.warnings == [] and launch.nodes[0].get_name() == "roborts_base_node"
    odoms2: list[mc.Odometry] = []
    ctx.create_node("probe").create_subscription(mc.Odometry, "/odom", odoms2.append, 10)
    drive(ctx, Twist(linear_x=0.2), 1.5)
    assert odoms2 and odoms2[-1].twist.twist.linear.x > 0.1
    ctx.shutdown()
