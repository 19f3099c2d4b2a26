"""Contacts of a long body spinning in place next to a wall: the contact sub-steps count
the footprint's rotation as well as its translation, so a fast spin cannot sweep a corner
through the wall within one physics step (diff drive and holonomic planar move)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from roverlab.core import Context
from roverlab.description import load_robot
from roverlab.msgs import Twist
from roverlab.sim.app import Simulation
from roverlab.sim.collision import inner_radius
from roverlab.sim.dynamics import (
    DRIVE_DIFF,
    DRIVE_HOLONOMIC,
    S_CONTACT,
    S_CW,
    S_TH,
    S_TL,
    S_TR,
    S_X,
    S_Y,
    STATE_SIZE,
    advance,
)
from roverlab.sim.node import SpawnPose
from roverlab.world.yaml_world import world_from_dict

HALF_LENGTH, HALF_WIDTH = 0.4, 0.1  # a 0.8 m x 0.2 m bar: its corners 0.412 m out
BAR = np.array(
    [[-HALF_LENGTH, -HALF_WIDTH], [HALF_LENGTH, -HALF_WIDTH],
     [HALF_LENGTH, HALF_WIDTH], [-HALF_LENGTH, HALF_WIDTH]]
)  # fmt: skip
SEP = 0.2


def _swept_reach(footprint: np.ndarray, th0: float, th1: float) -> float:
    """How far in +y the footprint reaches while it turns about the origin from ``th0``
    to ``th1`` (the shorter way), sampled finely."""
    dth = (th1 - th0 + math.pi) % (2 * math.pi) - math.pi
    th = th0 + dth * np.linspace(0.0, 1.0, 257)[:, None]
    return float(np.max(np.sin(th) * footprint[:, 0] + np.cos(th) * footprint[:, 1]))


@pytest.mark.parametrize("kind", [DRIVE_DIFF, DRIVE_HOLONOMIC])
@pytest.mark.parametrize("wall_y", [0.3, 0.38, 0.405, 0.41])
@pytest.mark.parametrize("rate", [20.0, 40.0, -50.0])
def test_the_kernel_never_sweeps_a_spinning_bar_through_a_wall(
    kind: float, wall_y: float, rate: float
) -> None:
    """A long wall along y = wall_y, between the bar's half-width and its corners' reach:
    spinning in place, the bar stops at the wall; between any two physics steps its
    footprint never crosses the wall's line."""
    walls = np.array([[-3.0, wall_y, 3.0, wall_y]])
    st = np.zeros(STATE_SIZE)
    if kind == DRIVE_DIFF:
        st[S_TL], st[S_TR] = -0.5 * rate * SEP, 0.5 * rate * SEP
    else:
        st[S_CW] = rate
    params = np.array([SEP, 0.05, 0.0, 0.0, inner_radius(BAR), kind])
    near = np.zeros(1, dtype=np.int64)
    noise = np.zeros((4, 2))
    for _ in range(100):
        th0 = st[S_TH]
        advance(st, params, 0.01, BAR, walls, np.zeros((0, 3)), near, noise, 0, 1)
        assert (st[S_X], st[S_Y]) == (0.0, 0.0)  # a pure spin
        assert _swept_reach(BAR, th0, st[S_TH]) <= wall_y
    assert st[S_CONTACT] == 1.0  # it got stuck at the wall ...
    assert abs(st[S_TH]) < 0.5 * math.pi  # ... before the bar's end could pass it


@pytest.mark.parametrize("kind", [DRIVE_DIFF, DRIVE_HOLONOMIC])
def test_more_than_half_a_turn_per_step_turns_the_commanded_way(kind: float) -> None:
    """4 rad in one 0.1 s step: the sub-steps follow the turn (not its wrapped -2.28 rad),
    so the bar meets the wall turning counter-clockwise, as commanded."""
    walls = np.array([[-3.0, 0.41, 3.0, 0.41]])
    st = np.zeros(STATE_SIZE)
    if kind == DRIVE_DIFF:
        st[S_TL], st[S_TR] = -0.5 * 40.0 * SEP, 0.5 * 40.0 * SEP
    else:
        st[S_CW] = 40.0
    params = np.array([SEP, 0.05, 0.0, 0.0, inner_radius(BAR), kind])
    near = np.zeros(1, dtype=np.int64)
    advance(st, params, 0.1, BAR, walls, np.zeros((0, 3)), near, np.zeros((4, 2)), 0, 1)
    assert st[S_CONTACT] == 1.0
    assert 1.0 < st[S_TH] < 0.5 * math.pi
    assert _swept_reach(BAR, 0.0, st[S_TH]) <= 0.41


def _bar_robot(plugin: str) -> Any:
    """The bar as a URDF box body with a drive ``plugin``'s ``<gazebo>`` block."""
    joints = "".join(
        f'<link name="{side}_wheel"/><joint name="{side}_joint" type="continuous">'
        f'<parent link="base_link"/><child link="{side}_wheel"/></joint>'
        for side in ("left", "right")
    )
    return load_robot(
        '<robot name="bar"><link name="base_footprint"/><link name="base_link">'
        f'<collision><geometry><box size="{2 * HALF_LENGTH} {2 * HALF_WIDTH} 0.2"/>'
        "</geometry></collision></link>"
        '<joint name="base_joint" type="fixed"><parent link="base_footprint"/>'
        f'<child link="base_link"/><origin xyz="0 0 0.1"/></joint>{joints}'
        f"<gazebo>{plugin}</gazebo></robot>"
    )


DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
    "<leftJoint>left_joint</leftJoint><rightJoint>right_joint</rightJoint>"
    f"<wheelSeparation>{SEP}</wheelSeparation><wheelDiameter>0.1</wheelDiameter></plugin>"
)
PLANAR = '<plugin name="omni" filename="libgazebo_ros_planar_move.so"/>'


@pytest.mark.parametrize(
    ("plugin", "turn_rate", "physics_rate"),
    [(DIFF, 40.0, 100.0), (PLANAR, 10.0, 25.0)],  # planar move's guard: 10 rad/s
)
def test_a_bar_spun_next_to_a_wall_never_overlaps_it(
    plugin: str, turn_rate: float, physics_rate: float
) -> None:
    face_y = 0.41  # the bar's corners reach 0.412 m: a shallow cut of the corners' circle
    wall = {"points": [[-3, face_y + 0.05], [3, face_y + 0.05]], "thickness": 0.1}
    world = world_from_dict({"name": "wall", "walls": [wall]}, source=Path("wall.yaml"))
    ctx = Context()
    sim = Simulation(
        context=ctx, world=world, robot=_bar_robot(plugin), spawn=SpawnPose(0.0, 0.0, 0.0),
        parameters={"physics_rate": physics_rate, "wheel_slip": 0.0},
    )  # fmt: skip
    s = sim.simulator
    footprint = sim.config.footprint
    np.testing.assert_allclose(np.abs(footprint), np.abs(BAR), atol=1e-9)
    pub = ctx.create_node("driver").create_publisher(Twist, "/cmd_vel", 1)
    pub.publish(Twist(angular_z=turn_rate))
    for _ in range(50):
        th0 = s.yaw
        ctx.spin_for(1.0 / physics_rate)  # one physics step
        assert (s.x, s.y) == (0.0, 0.0)
        assert _swept_reach(footprint, th0, s.yaw) <= face_y
        assert not s.obstacles.hits(footprint, s.x, s.y, s.yaw)
    assert s.contact and 0.0 < s.yaw < 0.5 * math.pi  # stuck against the wall
