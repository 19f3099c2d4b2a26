"""teb_local_planner with roverlab's ``backwards_init_when_stuck``: a robot in a pocket it
cannot turn in, whose plan leads back out, reverses out instead of standing."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import TebParams, TebPlanner, Velocity2D
from roverlab.navigation.costmap import Costmap2D, pad_footprint
from roverlab.navigation.errors import NavigationParamsError, NoValidControlError
from tests.navigation.controllers.test_teb import _BODY, _jackal

PADDED = pad_footprint(_BODY, 0.1)  # BARN's costmap footprint: 0.62 x 0.53 m


def _pocket() -> Costmap2D:
    """A 0.66 m wide pocket open to the west, its end 0.4 m ahead of a robot at (2, 2.5)
    facing east: the padded footprint fits, but turning in place puts a corner (0.41 m
    from the centre) on a side wall."""
    cm = Costmap2D(size_x=100, size_y=100, resolution=0.05)  # 5 x 5 m
    for ix in range(32, 50):  # x 1.6 .. 2.5
        cm.costs[42, ix] = cm.costs[57, ix] = 254  # walls at y 2.1-2.15 and 2.85-2.9
    cm.costs[42:58, 48:50] = 254  # the end, x 2.4 .. 2.5
    return cm


def _blocked(cm: Costmap2D, x: float, y: float, th: float) -> bool:
    c, s = math.cos(th), math.sin(th)
    edge = np.linspace(0.0, 1.0, 20)[:, None]
    corners = PADDED @ np.array([[c, s], [-s, c]]) + [x, y]
    pts = np.vstack(
        [a + edge * (b - a) for a, b in zip(corners, np.roll(corners, -1, 0), strict=True)]
    )
    ij = np.floor(pts / cm.resolution).astype(int)
    return bool((cm.costs[ij[:, 1], ij[:, 0]] == 254).any())


WEST_PLAN = np.column_stack([np.linspace(2.0, 0.0, 41), np.full(41, 2.5), np.full(41, math.pi)])


def test_without_the_addition_teb_stands_in_the_pocket() -> None:
    """TEB's own behaviour: the band turns in place, every band is "not feasible", the
    command is zero and move_base waits out its controller_patience."""
    params = replace(_jackal(), controller_frequency=20.0, backwards_init_when_stuck=0.0)
    teb, cm = TebPlanner(params, footprint=PADDED), _pocket()
    assert not _blocked(cm, 2.0, 2.5, 0.0) and _blocked(cm, 2.0, 2.5, math.pi / 4)
    for _ in range(40):
        with pytest.raises(NoValidControlError, match="not feasible"):
            teb.compute_velocity(SE2(2.0, 2.5, 0.0), Velocity2D(), WEST_PLAN, cm)


def test_backwards_init_when_stuck_backs_out_of_the_pocket() -> None:
    """After ``backwards_init_when_stuck`` s of infeasible bands (20 cycles at 20 Hz) the
    band is initialised backwards (the 21st cycle); the robot reverses out along its plan,
    its padded footprint never on a wall, until it is out."""
    params = replace(_jackal(), controller_frequency=20.0, backwards_init_when_stuck=1.0)
    teb, cm = TebPlanner(params, footprint=PADDED), _pocket()
    x, y, th = 2.0, 2.5, 0.0
    for _ in range(20):
        with pytest.raises(NoValidControlError, match="not feasible"):
            teb.compute_velocity(SE2(x, y, th), Velocity2D(), WEST_PLAN, cm)
    cmd = teb.compute_velocity(SE2(x, y, th), Velocity2D(), WEST_PLAN, cm)
    assert -params.max_vel_x_backwards - 1e-9 <= cmd.vx < -0.05
    dt = 1.0 / params.controller_frequency
    for _ in range(200):
        x += cmd.vx * math.cos(th) * dt
        y += cmd.vx * math.sin(th) * dt
        th += cmd.wz * dt
        assert not _blocked(cm, x, y, th), (x, y, th)
        if x < 1.0:
            break
        cmd = teb.compute_velocity(SE2(x, y, th), Velocity2D(cmd.vx, 0.0, cmd.wz), WEST_PLAN, cm)
    assert x < 1.0, (x, y, th)  # out of the pocket (its mouth is at x 1.6)


def test_backwards_init_when_stuck_refuses_a_negative_or_non_finite_time() -> None:
    for bad in (-1.0, float("nan"), "soon"):
        with pytest.raises(NavigationParamsError, match="backwards_init_when_stuck"):
            TebParams.from_ros({"backwards_init_when_stuck": bad})
