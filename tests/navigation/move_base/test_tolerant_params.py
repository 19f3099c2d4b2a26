"""Parameter files written for ROS 1 load: unknown names are warned about by name and
ignored (as ROS ignores them), the obstacle layer's own names are honoured wherever they
are set (issue 28, item 6)."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import pytest
import yaml

from roverlab.core import Context
from roverlab.navigation.costmap import CostmapParams, ObstacleLayerParams
from roverlab.navigation.move_base.node import MoveBase
from roverlab.navigation.params import flatten_ros

BARN_PARAMS = Path(__file__).resolve().parents[4] / "shared" / "data" / "barn" / "params"

# a ROS 1 book's fake-robot costmap_common_params.yaml: pre-Hydro, the obstacle layer's
# height filter in the costmap namespace
BOOK_COMMON = {
    "obstacle_range": 2.5, "raytrace_range": 3.0, "robot_radius": 0.2,
    "inflation_radius": 0.3, "max_obstacle_height": 0.6, "min_obstacle_height": 0.05,
    "observation_sources": "scan",
    "scan": {"data_type": "LaserScan", "topic": "/scan", "marking": True, "clearing": True,
             "expected_update_rate": 0},
}  # fmt: skip


def _obstacle(p: CostmapParams) -> ObstacleLayerParams:
    (layer,) = [s.params for s in p.plugins if isinstance(s.params, ObstacleLayerParams)]
    return layer


def test_obstacle_layer_heights_and_ranges_are_honoured_where_ros_users_set_them() -> None:
    p, warnings = CostmapParams.from_ros(BOOK_COMMON, name="global_costmap")
    src = _obstacle(p).observation_sources[0]
    assert (src.min_obstacle_height, src.max_obstacle_height) == (0.05, 0.6)
    assert (src.obstacle_range, src.raytrace_range) == (2.5, 3.0)
    assert not any("unknown" in w for w in warnings), warnings
    # plugins style: the layer's value, then the costmap's top level, then the source's own
    layer = {"name": "obstacle_layer", "type": "costmap_2d::ObstacleLayer"}
    p, warnings = CostmapParams.from_ros(
        {"plugins": [layer], "min_obstacle_height": 0.1,
         "obstacle_layer": {"observation_sources": "a b", "transform_tolerance": 0.4,
                            "max_obstacle_height": 1.5, "obstacle_range": 4.0,
                            "a": {"data_type": "LaserScan"},
                            "b": {"data_type": "LaserScan", "min_obstacle_height": -1.0,
                                  "raytrace_range": 6.0, "meter_scoring": True}}},
    )  # fmt: skip
    ol = _obstacle(p)
    a, b = ol.observation_sources
    assert ol.transform_tolerance == 0.4 and ol.max_obstacle_height == 1.5
    assert (a.min_obstacle_height, a.max_obstacle_height, a.obstacle_range) == (0.1, 1.5, 4.0)
    assert (b.min_obstacle_height, b.raytrace_range, a.raytrace_range) == (-1.0, 6.0, 3.0)
    assert any("costmap/obstacle_layer/b: unknown parameter 'meter_scoring'" in w for w in warnings)


def _barn_overrides() -> dict[str, Any]:
    if not BARN_PARAMS.is_dir():
        pytest.skip(f"BARN's parameter files are not at {BARN_PARAMS}")
    common = yaml.safe_load((BARN_PARAMS / "costmap_common_params.yaml").read_text())
    out: dict[str, Any] = {}
    for ns in ("global_costmap", "local_costmap"):
        out.update(flatten_ros(common, ns + "/"))
        out.update(flatten_ros(yaml.safe_load((BARN_PARAMS / f"{ns}_params.yaml").read_text())))
    out.update(
        flatten_ros(yaml.safe_load((BARN_PARAMS / "base_local_planner_params.yaml").read_text()))
    )
    return out


def test_barn_and_book_parameter_files_start_move_base(caplog: pytest.LogCaptureFixture) -> None:
    """BARN's files (``meter_scoring`` in the costmap namespace) and the book's
    (``min_obstacle_height`` there) were refused; now move_base starts and names what it
    ignores, once each."""
    ctx = Context()
    try:
        with caplog.at_level(logging.WARNING):
            mb = MoveBase(ctx, parameter_overrides=_barn_overrides())
        text = caplog.text
        assert text.count("global_costmap: unknown parameter 'meter_scoring'") == 1
        assert text.count("local_costmap: unknown parameter 'meter_scoring'") == 1
        assert "base_local_planner: parameter heading_scoring_timestep has no effect" in text
        scan = _obstacle(mb.local_costmap.params).observation_sources[0]
        assert (scan.min_obstacle_height, scan.max_obstacle_height) == (-2.0, 2.0)
        ctrl: Any = mb.controller
        assert (ctrl.params.escape_vel, ctrl.params.escape_reset_dist) == (-0.5, 0.1)
        assert ctrl.params.heading_lookahead == 0.325 and "heading_lookahead" not in text
        book = {f"{ns}/{k}": v for ns in ("global_costmap", "local_costmap")
                for k, v in flatten_ros(BOOK_COMMON).items()}  # fmt: skip
        book["global_costmap/global_frame"] = "odom"
        book2 = MoveBase(ctx, node_name="move_base_book", parameter_overrides=book)
        src = _obstacle(book2.global_costmap.params).observation_sources[0]
        assert src.min_obstacle_height == 0.05
    finally:
        ctx.shutdown()
