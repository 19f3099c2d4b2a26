"""Nav2's BackUp, Spin and Wait and move_slow_and_clear as move_base recoveries, and the
rotate_recovery that cannot turn handing over to backing up (issue 28, "never wedged")."""

from __future__ import annotations

import math
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import Velocity2D
from roverlab.navigation.costmap import Costmap2D
from roverlab.navigation.move_base.behaviors import (
    BackUp,
    BehaviorParams,
    MoveSlowAndClear,
    MoveSlowAndClearParams,
    Spin,
    Wait,
)
from roverlab.navigation.move_base.params import MoveBaseParams
from roverlab.navigation.move_base.plugins import LocalPlannerLimits, make_recovery, rotate_fallback
from roverlab.navigation.move_base.recovering import Recovering
from roverlab.navigation.move_base.recovery import RotateRecovery

BODY = np.array([[-0.2, -0.15], [-0.2, 0.15], [0.2, 0.15], [0.2, -0.15]])
PADDED = BODY * np.array([[1.5, 1.6]])  # 0.1 m more a side
LIMITS = LocalPlannerLimits(3.2, 1.0, 0.4, 0.1)


def _grid(*lethal: tuple[float, float]) -> Costmap2D:
    """4 x 4 m at 0.05 m, origin (-2, -2), ``lethal`` points marked."""
    cm = Costmap2D(size_x=80, size_y=80, resolution=0.05, origin_x=-2.0, origin_y=-2.0)
    for x, y in lethal:
        cm.costs[int((y + 2) / 0.05), int((x + 2) / 0.05)] = 254
    return cm


def _drive(rec: Any, pose: SE2, cm: Costmap2D, dt: float = 0.05) -> tuple[SE2, list[Velocity2D]]:
    cmds: list[Velocity2D] = []
    now = 0.0
    rec.start(pose, now)
    for _ in range(2000):
        cmd = rec.step(pose, cm, now)
        if cmd is None:
            break
        cmds.append(cmd)
        th = pose.theta + cmd.wz * dt
        pose = SE2(pose.x + cmd.vx * dt * math.cos(pose.theta),
                   pose.y + cmd.vx * dt * math.sin(pose.theta), th)  # fmt: skip
        now += dt
    return pose, cmds


def test_back_up_spin_and_wait_do_their_distance_and_stop_before_a_collision() -> None:
    back = BackUp("back_up", BehaviorParams(backup_dist=0.3, backup_speed=0.1), footprint=BODY)
    end, cmds = _drive(back, SE2(0.0, 0.0, 0.0), _grid())
    assert back.finished and back.blocked is None
    assert end.x == pytest.approx(-0.3, abs=0.006) and {c.vx for c in cmds} == {-0.1}
    # a wall 0.15 m behind the body: Nav2 looks simulate_ahead_time ahead (2 s: 0.2 m),
    # so it refuses at once; looking 0.5 s (0.05 m) ahead it backs up to the wall, not in
    wall = _grid(*((-0.36, y / 20) for y in range(-5, 6)))
    end, cmds = _drive(back, SE2(0.0, 0.0, 0.0), wall)
    assert back.blocked and "collision ahead" in back.blocked and not cmds
    near = BackUp("b", BehaviorParams(backup_dist=0.3, backup_speed=0.1, simulate_ahead_time=0.5),
                  footprint=BODY)  # fmt: skip
    end, _ = _drive(near, SE2(0.0, 0.0, 0.0), wall)
    assert not near.finished and near.blocked and -0.15 < end.x < -0.08
    spin = Spin("spin", BehaviorParams(spin_dist=-1.57), footprint=BODY)
    end, cmds = _drive(spin, SE2(0.0, 0.0, 0.5), _grid())
    assert spin.finished and end.theta == pytest.approx(0.5 - 1.57, abs=0.06)
    assert all(-1.0 <= c.wz <= -0.4 for c in cmds)
    # a post 0.23 m off the body's side: turning sweeps a corner (0.25 m) through it
    end, cmds = _drive(spin, SE2(0.0, 0.0, 0.0), _grid((0.0, 0.24)))
    assert spin.blocked and not cmds
    wait = Wait("wait", BehaviorParams(wait_duration=0.5), footprint=BODY)
    _, cmds = _drive(wait, SE2(), _grid())
    assert wait.finished and 10 <= len(cmds) <= 11 and set(cmds) == {Velocity2D()}  # 0.5 s


def test_recovery_behaviors_list_takes_them_with_their_parameters() -> None:
    p, _ = MoveBaseParams.from_ros(
        {"recovery_behaviors": [
            {"name": "back", "type": "nav2_behaviors/BackUp"},
            {"name": "slow", "type": "move_slow_and_clear/MoveSlowAndClear"},
        ]}
    )  # fmt: skip
    made = {
        r.name: make_recovery(
            r.name, r.type, values, default_reset_distance=3.0, limits=LIMITS,
            trajectory_planner={}, footprint=PADDED, body_footprint=BODY,
        )
        for r, values in zip(
            p.recoveries,
            ({"backup_dist": 0.4, "backup_sped": 1.0}, {"limited_distance": 0.5}),
            strict=True,
        )
    }  # fmt: skip
    back, warnings = made["back"]
    assert isinstance(back, BackUp) and back.params.backup_dist == 0.4
    assert np.array_equal(back.footprint, BODY)  # the body is checked, not the padding
    assert warnings == ("back: unknown parameter 'backup_sped' (did you mean backup_speed?) "
                        "is ignored",)  # fmt: skip
    slow, _ = made["slow"]
    assert isinstance(slow, MoveSlowAndClear) and slow.params.limited_distance == 0.5


def test_move_slow_and_clear_caps_speeds_until_the_robot_has_moved() -> None:
    msc = MoveSlowAndClear("slow", MoveSlowAndClearParams(limited_distance=0.3))
    fast = Velocity2D(0.5, 0.0, 1.0)
    assert msc.limit(fast, SE2()) == fast  # not engaged
    msc.engage(SE2(1.0, 1.0, 0.0))
    assert msc.limit(fast, SE2(1.1, 1.0, 0.0)) == Velocity2D(0.25, 0.0, 0.45)
    assert msc.limit(fast, SE2(1.31, 1.0, 0.0)) == fast and not msc.limiting


def test_rotate_recovery_that_cannot_turn_hands_over_to_backing_up() -> None:
    """The wedge: a post inside the padded footprint's reach, the body clear of it. ROS's
    rotate_recovery logs "can't rotate in place" and move_base goes on to abort; here the
    robot backs away (its body checked) and the recovery ends once it has."""
    cm = _grid((0.32, 0.2))  # 0.12 m from the body's front-left corner
    pose = [SE2(0.0, 0.0, 0.0)]
    published: list[Any] = []
    local = SimpleNamespace(get_robot_pose=lambda: pose[0], costmap=cm)
    log = SimpleNamespace(error=published.append, info=published.append)
    node: Any = SimpleNamespace(
        local_costmap=local, get_logger=lambda: log,
        cmd_pub=SimpleNamespace(publish=published.append),
        publish_zero_velocity=lambda: published.append("stop"),
        params=SimpleNamespace(recovery_behavior_enabled=True),
        recoveries=[RotateRecovery("rotate_recovery", footprint=PADDED)], recovery_index=0,
    )  # fmt: skip
    fallback = rotate_fallback(LIMITS, PADDED, BODY)
    assert fallback.params.backup_dist == pytest.approx(0.38 - 0.15, abs=0.02)
    runner = Recovering(node, fallback)
    runner.clear_step(0.0)
    assert any("can't rotate in place" in str(m) for m in published)
    assert runner.running is fallback
    for k in range(1, 200):
        twists = [m for m in published if hasattr(m, "linear")]
        if twists:
            pose[0] = SE2(pose[0].x + twists[-1].linear.x * 0.05, 0.0, 0.0)
        published.clear()
        runner.clear_step(k * 0.05)
        if runner.running is None:
            break
    assert runner.running is None and node.recovery_index == 1 and fallback.finished
    assert pose[0].x == pytest.approx(-fallback.params.backup_dist, abs=0.01)
    again = RotateRecovery("rotate_recovery", footprint=PADDED)
    again.start(pose[0])
    assert again.step(pose[0], cm) is not None  # now it can turn
