"""The explore stack's parameters for a robot: footprint, inflation, the planner's lethal cost."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from roverlab.autonomy.stack import footprint_params
from roverlab.description import find_package

# mybot's collision outline (robot_navigation's NanoRobot footprint)
MYBOT = np.array([[-0.125, -0.10], [-0.125, 0.10], [0.125, 0.10], [0.125, -0.10]])


def test_mybot_s_lethal_cost_is_explore_planner_params_yaml_s() -> None:
    param = find_package("robot_navigation") / "param" / "NanoRobot"
    planner = yaml.safe_load((param / "explore_planner_params.yaml").read_text())
    common = yaml.safe_load((param / "costmap_common_params.yaml").read_text())
    assert np.allclose(common["footprint"], MYBOT)
    assert footprint_params(MYBOT)["GlobalPlanner/lethal_cost"] == planner["GlobalPlanner"][
        "lethal_cost"
    ] == 173  # fmt: skip


def test_a_bigger_robot_gets_its_own_outline_inflation_and_lethal_cost() -> None:
    big = MYBOT * 2.0
    p = footprint_params(big)
    assert p["global_costmap/footprint"] == p["local_costmap/footprint"] == big.tolist()
    circumscribed = float(np.hypot(0.26, 0.21))  # padded by 0.01
    assert p["local_costmap/inflation_layer/inflation_radius"] == pytest.approx(circumscribed + 0.2)
    # inscribed 0.21, circumscribed 0.334: floor(252 * exp(-6 * 0.124)) + 2
    assert p["GlobalPlanner/lethal_cost"] == int(252 * np.exp(-6.0 * (circumscribed - 0.21))) + 2
