"""explore_lite's frontier search (pure)."""

from __future__ import annotations

import numpy as np
import pytest

from roverlab.navigation.errors import NavigationParamsError
from roverlab.navigation.explore import FrontierSearch, occupancy_to_costs


def _room(open_right: bool = True, door_top: bool = False) -> np.ndarray:
    """A 2 m x 2 m known room (0.1 m cells) in an unknown 6 m x 4 m grid: walls on its
    left, top and bottom; its right side opens onto the unknown."""
    g = np.full((40, 60), -1, np.int8)
    g[10:30, 10:30] = 0
    g[10:30, 10] = 100
    g[10, 10:30] = 100
    g[29, 10:30] = 100
    if not open_right:
        g[10:30, 29] = 100
    if door_top:
        g[29, 18:24] = 0
    return g


def test_translation_table() -> None:
    data = np.array([-1, 0, 1, 50, 98, 99, 100], np.int8)
    assert occupancy_to_costs(data).tolist() == [255, 0, 1, 127, 252, 253, 254]


def test_the_open_side_is_one_frontier() -> None:
    (f,) = FrontierSearch().search(
        occupancy_to_costs(_room()), resolution=0.1, origin=(0.0, 0.0), robot=(2.0, 2.0, 0.0)
    )
    assert f.size == 18  # the unknown column next to the free cells of rows 11..28
    assert f.centroid == pytest.approx((3.05, 2.0))
    assert f.middle[0] == pytest.approx(3.05) and abs(f.middle[1] - 2.0) <= 0.1
    assert f.min_distance == pytest.approx(1.05, abs=0.05)
    assert f.points.shape == (18, 2)
    assert f.cost == pytest.approx(1e-3 * f.min_distance * 0.1 - 1.0 * 18 * 0.1)


def test_closed_rooms_have_no_frontier_and_small_ones_are_dropped() -> None:
    fs = FrontierSearch()
    closed = occupancy_to_costs(_room(open_right=False))
    assert fs.search(closed, resolution=0.1, origin=(0.0, 0.0), robot=(2.0, 2.0, 0.0)) == []
    door = occupancy_to_costs(_room(open_right=False, door_top=True))
    (f,) = fs.search(door, resolution=0.1, origin=(0.0, 0.0), robot=(2.0, 2.0, 0.0))
    assert f.size == 6
    big_only = FrontierSearch(min_frontier_size=1.0)
    assert big_only.search(door, resolution=0.1, origin=(0.0, 0.0), robot=(2.0, 2.0, 0.0)) == []


def test_cost_orders_near_and_big_first() -> None:
    g = _room(door_top=True)  # a 6-cell door at the top, the 18-cell open right side
    costs = occupancy_to_costs(g)
    gain = FrontierSearch().search(costs, resolution=0.1, origin=(0.0, 0.0), robot=(2.1, 2.7, 0.0))
    assert [f.size for f in gain] == [18, 6]  # gain dominates: the bigger first
    near = FrontierSearch(potential_scale=100.0, gain_scale=0.0).search(
        costs, resolution=0.1, origin=(0.0, 0.0), robot=(2.1, 2.7, 0.0)
    )
    assert [f.size for f in near] == [6, 18]  # distance dominates: the door is nearer
    turn = FrontierSearch(orientation_scale=10.0, gain_scale=0.0).search(
        costs, resolution=0.1, origin=(0.0, 0.0), robot=(2.1, 2.7, 0.0)
    )
    assert [f.size for f in turn] == [18, 6]  # facing +x: the right side needs no turn


def test_robot_off_the_grid_or_in_unknown_space() -> None:
    costs = occupancy_to_costs(_room())
    fs = FrontierSearch()
    assert fs.search(costs, resolution=0.1, origin=(0.0, 0.0), robot=(-1.0, 2.0, 0.0)) == []
    # from unknown space the search starts at the nearest free cell
    (f,) = fs.search(costs, resolution=0.1, origin=(0.0, 0.0), robot=(0.5, 0.5, 0.0))
    assert f.size == 18
    with pytest.raises(NavigationParamsError, match="gain_scale"):
        FrontierSearch(gain_scale=-1.0)
