"""Longer closed loops in the bundled maze (slow)."""

from __future__ import annotations

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.controllers import DWAParams, DWAPlanner, TebParams, TebPlanner
from roverlab.navigation.costmap import footprint_from_radius
from roverlab.world import load_world
from tests.navigation.controllers.conftest import DWA, TEB
from tests.navigation.controllers.sim import RES, ROBOT_RADIUS, run

FOOT = footprint_from_radius(ROBOT_RADIUS)


def maze() -> tuple[np.ndarray, tuple[float, float]]:
    occ, origin = load_world("maze").occupancy(RES, 0.0, 2.0)
    return np.where(occ, 100, 0).astype(np.int8), origin


@pytest.mark.slow
@pytest.mark.parametrize("planner", ["dwa", "teb"])
@pytest.mark.parametrize("goal", [(3.2, 3.2, 1.0), (-3.3, -1.7, 1.0), (1.6, -3.2, -1.0)])
def test_maze_goals_reached_without_collision(
    planner: str, goal: tuple[float, float, float]
) -> None:
    grid, (ox, oy) = maze()
    ctrl = (
        DWAPlanner(DWAParams.from_ros(DWA)[0], footprint=FOOT)
        if planner == "dwa"
        else TebPlanner(TebParams.from_ros(TEB)[0], footprint=FOOT)
    )
    # the sim's grid starts at (0, 0): shift the maze's coordinates by its origin
    start = SE2(-ox, -oy, 0.0)
    target = SE2(goal[0] - ox, goal[1] - oy, goal[2])
    r = run(ctrl, grid, start, target, max_steps=4000)
    assert r.reached and not r.collided, (r.pose, r.steps, r.failures)
