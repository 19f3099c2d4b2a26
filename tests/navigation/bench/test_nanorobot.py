"""robot_navigation's NanoRobot parameters (what ``nav bench`` runs mybot with) on the
places where the held-out worlds wedged it: global_planner keeps plans in the middle of a
gap, and the footprint is mybot's collision outline."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import yaml

from roverlab.description import find_package
from roverlab.geometry import SE2
from roverlab.navigation.costmap import CostmapParams, LayeredCostmap, make_layered_costmap
from roverlab.navigation.planners.global_planner import GlobalPlanner, GlobalPlannerParams

RES = 0.05
PARAMS = find_package("robot_navigation") / "param" / "NanoRobot"


def _yaml(name: str) -> dict[str, Any]:
    data = yaml.safe_load((PARAMS / f"{name}.yaml").read_text())
    assert isinstance(data, dict)
    return data


def _global_costmap(grid: np.ndarray) -> LayeredCostmap:
    """NanoRobot's global costmap (footprint, padding, inflation) over ``grid``
    (OccupancyGrid values, origin 0, 0), its obstacle layer left out."""
    common = _yaml("costmap_common_params")
    values = {k: v for k, v in common.items() if k != "obstacle_layer"}
    values.update(_yaml("global_costmap_params")["global_costmap"])
    values["plugins"] = [p for p in values["plugins"] if p["name"] != "obstacle_layer"]
    params, _ = CostmapParams.from_ros(values)
    lc = make_layered_costmap(params)
    lc.plugin("static_layer").incoming_map(  # type: ignore[attr-defined]
        grid, resolution=RES, origin_x=0.0, origin_y=0.0
    )
    lc.update_map(0.0, 0.0, 0.0)
    return lc


def _gap_world() -> tuple[np.ndarray, tuple[float, float], float]:
    """3 x 2 m: a wall along the floor (y < 0.05), one above the 1.1 m line, and a post of
    radius 0.257 m between them whose lowest point is 0.60 m up: the 0.55 m gap of the
    held-out cluttered world where DWA wedged mybot (goal 4, seed 0), the only way past.
    Returns the grid, the post's centre and radius."""
    n_x, n_y = round(3.0 / RES), round(2.0 / RES)
    g = np.zeros((n_y, n_x), np.int8)
    g[:1, :] = 100
    g[22:, :] = 100
    centre, r = (1.5, 0.861), 0.257
    ys, xs = np.mgrid[0:n_y, 0:n_x]
    g[np.hypot((xs + 0.5) * RES - centre[0], (ys + 0.5) * RES - centre[1]) <= r] = 100
    return g, centre, r


def _planner(**overrides: Any) -> GlobalPlanner:
    values = dict(_yaml("global_planner_params")["GlobalPlanner"], **overrides)
    params, _ = GlobalPlannerParams.from_ros(values)
    return GlobalPlanner(params)


def _clearance_under_post(path: np.ndarray, centre: tuple[float, float], r: float) -> float:
    """Smallest distance from the path's points under the post to its surface."""
    below = path[np.abs(path[:, 0] - centre[0]) <= r]
    assert len(below) > 0
    return float((np.hypot(below[:, 0] - centre[0], below[:, 1] - centre[1]) - r).min())


def test_global_plan_keeps_to_the_middle_of_a_gap() -> None:
    grid, centre, r = _gap_world()
    lc = _global_costmap(grid)
    start, goal = SE2(2.8, 0.55, math.pi), SE2(0.2, 0.45, math.pi)
    path = _planner().plan(start, goal, lc.costmap)
    gap_mid = (0.05 + centre[1] - r) / 2  # 0.327 m
    under = path[np.abs(path[:, 0] - centre[0]) <= 0.1]
    assert np.abs(under[:, 1] - gap_mid).max() < 0.05
    # the padded footprint's half width (0.11 m) + a cell stays clear of the post
    assert _clearance_under_post(path, centre, r) > 0.16
    # ROS's defaults (3.0 / 50) cost every inflated cell 252: the plan hugs the post, the
    # padded footprint's side within a cell of it (what wedged DWA)
    hugging = _planner(cost_factor=3.0, neutral_cost=50).plan(start, goal, lc.costmap)
    assert _clearance_under_post(hugging, centre, r) < 0.16


def test_footprint_is_mybots_collision_outline_padded() -> None:
    common = _yaml("costmap_common_params")
    fp = np.asarray(common["footprint"], dtype=float)
    # mybot's URDF: body +-0.125 m long (the wheels and caster reach it), wheels' outer
    # faces at +-0.10 m
    assert fp.min(axis=0) == pytest.approx([-0.125, -0.10])
    assert fp.max(axis=0) == pytest.approx([0.125, 0.10])
    assert 0.0 < common["footprint_padding"] <= 0.02
