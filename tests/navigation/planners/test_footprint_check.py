"""move_base's footprint check of the global plan (roverlab's addition): mybot's
NanoRobot costmap and global_planner, a table turned 0.3 rad whose corner leaves a gap
beside a wall (the office world's meeting table, where DWA wedged mybot at goal 21 of the
100-goal run), with a wide way round the table's other end."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import SE2
from roverlab.navigation.move_base.params import MoveBaseParams
from roverlab.navigation.planners.footprint_check import (
    colliding_poses,
    path_headings,
    plan_clear_of_footprint,
)
from tests.navigation.bench.test_doors import AXIS_X, STARTS, _door_grid
from tests.navigation.bench.test_nanorobot import RES, _global_costmap, _planner

START = SE2(3.7, 0.4, math.pi / 2)
GOAL = SE2(3.7, 2.7, math.pi / 2)


def _table_grid(gap: float, *, west_open: bool = True) -> tuple[np.ndarray, tuple[float, float]]:
    """4 x 3 m, walled, the east wall's face at x = 3.9 m; a 1.8 x 1.0 m table turned
    0.3 rad with its east corner ``gap`` m from that face. Returns the OccupancyGrid and
    the corner. ``west_open=False`` walls off the way round the table's west end."""
    nx, ny = 80, 60
    g = np.zeros((ny, nx), np.int8)
    g[0, :] = g[-1, :] = g[:, 0] = 100
    g[:, 78:] = 100
    c, s = math.cos(0.3), math.sin(0.3)
    corner = (3.9 - gap, 1.5)
    cx, cy = corner[0] - (0.9 * c + 0.5 * s), corner[1] - (0.9 * s - 0.5 * c)
    xs, ys = np.meshgrid((np.arange(nx) + 0.5) * RES, (np.arange(ny) + 0.5) * RES)
    u = (xs - cx) * c + (ys - cy) * s
    v = -(xs - cx) * s + (ys - cy) * c
    g[(np.abs(u) <= 0.925) & (np.abs(v) <= 0.525)] = 100
    if not west_open:
        g[:, :40][(ys[:, :40] > 1.2) & (ys[:, :40] < 1.5)] = 100
    return g, corner


def _length(path: np.ndarray) -> float:
    return float(np.hypot(*np.diff(path[:, :2], axis=0).T).sum())


def _distance_to(path: np.ndarray, point: tuple[float, float]) -> float:
    return float(np.hypot(path[:, 0] - point[0], path[:, 1] - point[1]).min())


@pytest.mark.parametrize("gap", [0.25, 0.29])
def test_plan_goes_round_a_gap_mybot_cannot_pass(gap: float) -> None:
    grid, corner = _table_grid(gap)
    # the gap is five free cells (0.25 m) at its narrowest: mybot's padded footprint is
    # 0.22 m wide and DWA needs it within 1.5 cm of the middle all the way through
    assert min(int((grid[r, 40:78] == 0).sum()) for r in range(20, 45)) == 5
    lc = _global_costmap(grid)
    plain = _planner().plan(START, GOAL, lc.costmap)
    assert _distance_to(plain, corner) < 0.2  # global_planner alone: through the gap
    path = plan_clear_of_footprint(_planner(), START, GOAL, lc.costmap, lc.footprint)
    assert _distance_to(path, corner) > 0.5
    assert _length(path) > 2.0 * _length(plain)  # round the table's west end
    assert path[0, :2] == pytest.approx([START.x, START.y], abs=RES)
    assert path[-1, :2] == pytest.approx([GOAL.x, GOAL.y])


@pytest.mark.parametrize(
    ("gap", "west_open"),
    [
        # six free cells and more: the plan may come at the gap slanting and off its
        # middle; mybot has room to line up there
        (0.31, True),
        (0.33, True),
        (0.4, True),
        # five, but no other way: the planner's own plan
        (0.27, False),
    ],
)
def test_plan_through_the_gap_is_kept(gap: float, west_open: bool) -> None:
    grid, corner = _table_grid(gap, west_open=west_open)
    lc = _global_costmap(grid)
    plain = _planner().plan(START, GOAL, lc.costmap)
    path = plan_clear_of_footprint(_planner(), START, GOAL, lc.costmap, lc.footprint)
    np.testing.assert_array_equal(path, plain)
    assert _distance_to(path, corner) < 0.2


def test_colliding_poses_in_a_wall_and_near_the_ends() -> None:
    grid = np.zeros((40, 40), np.int8)
    grid[19:21, :] = 100  # a wall across y = 0.95..1.05 m
    lc = _global_costmap(grid)
    path = np.column_stack([np.full(19, 1.0), np.linspace(0.1, 1.9, 19), np.zeros(19)])
    hits = colliding_poses(path, lc.costmap, lc.footprint)
    # the footprint's long side is 0.27 m along the path: every pose whose outline reaches
    # the wall's cells (y 0.95..1.05 m) from 0.135 m + a cell away
    near = np.abs(path[:, 1] - 1.0) <= 0.135 + RES + 1e-9
    np.testing.assert_array_equal(hits, near)
    # poses within the skip radius of the first and last points are not looked at
    assert not colliding_poses(path, lc.costmap, lc.footprint, skip_radius=1.0).any()
    # heading along the path: northwards here
    assert path_headings(path) == pytest.approx(np.full(19, math.pi / 2))


def test_move_base_parameter() -> None:
    assert MoveBaseParams().plan_footprint_check is True
    assert MoveBaseParams.from_ros({"plan_footprint_check": False})[0].plan_footprint_check is False


def test_plans_through_a_narrow_door_are_kept() -> None:
    """The held-out narrow_doors world's 0.35 m doors (seven cells): every plan of the
    door test is left as global_planner made it."""
    lc = _global_costmap(_door_grid())
    for sx, sy in STARTS:
        goal = SE2(AXIS_X + (0.5 if sx < AXIS_X else -0.5), 2.0, 0.0)
        start = SE2(sx, sy, 0.0)
        plain = _planner().plan(start, goal, lc.costmap)
        path = plan_clear_of_footprint(_planner(), start, goal, lc.costmap, lc.footprint)
        np.testing.assert_array_equal(path, plain)


def test_a_sensor_mark_in_the_gap_does_not_shut_it_with_the_walls_given() -> None:
    """move_base checks against the static layer's map: one laser mark on the jamb's side
    of a six-cell gap makes it five in the master costmap (the held-out narrow_doors run
    checking the master grid turned mybot back inside a door, 94 of 100), not in the walls."""
    grid, corner = _table_grid(0.31)
    assert int((grid[30, 40:78] == 0).sum()) == 6
    walls = _global_costmap(grid).costmap
    marked = grid.copy()
    marked[30, 72] = 100  # the first free cell east of the table at the narrowest
    lc = _global_costmap(marked)
    on_master = plan_clear_of_footprint(_planner(), START, GOAL, lc.costmap, lc.footprint)
    assert _distance_to(on_master, corner) > 0.5
    on_walls = plan_clear_of_footprint(
        _planner(), START, GOAL, lc.costmap, lc.footprint, walls=walls
    )
    assert _distance_to(on_walls, corner) < 0.2
