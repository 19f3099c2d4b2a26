"""Navigation fixtures: the 10x10 map of navigation2's tests, layered costmaps."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from roverlab.navigation.costmap import CostmapParams, LayeredCostmap, make_layered_costmap

STATIC = {"name": "static_layer", "type": "costmap_2d::StaticLayer"}
OBSTACLE = {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"}
INFLATION = {"name": "inflation_layer", "type": "costmap_2d::InflationLayer"}


def map_10x10() -> np.ndarray:
    """A 10x10 OccupancyGrid array (row = y): a wall along x = 5 from y = 0 to y = 6, an
    unknown cell at (8, 8), free elsewhere."""
    m = np.zeros((10, 10), dtype=np.int8)
    m[0:7, 5] = 100
    m[8, 8] = -1
    return m


def layered(
    values: dict[str, Any], grid: np.ndarray | None = None, res: float = 1.0
) -> LayeredCostmap:
    """A layered costmap of ``values`` fed with ``grid`` (default :func:`map_10x10`)."""
    params, _ = CostmapParams.from_ros(values)
    lc = make_layered_costmap(params)
    if grid is None:
        grid = map_10x10()
    for layer in lc.plugins:
        if layer.name == "static_layer":
            layer.incoming_map(grid, resolution=res, origin_x=0.0, origin_y=0.0)  # type: ignore[attr-defined]
    return lc


@pytest.fixture
def map10() -> np.ndarray:
    return map_10x10()
