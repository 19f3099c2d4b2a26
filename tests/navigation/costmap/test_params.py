"""Costmap parameters in both ROS spellings, and their errors."""

from __future__ import annotations

import pytest

from roverlab.navigation.costmap import (
    CostmapParams,
    InflationLayerParams,
    ObstacleLayerParams,
    StaticLayerParams,
)
from roverlab.navigation.errors import NavigationParamsError
from tests.navigation.conftest import INFLATION, OBSTACLE, STATIC

SCAN = {"sensor_frame": "base_laser_link", "data_type": "LaserScan", "topic": "scan",
        "marking": True, "clearing": True}  # fmt: skip


def test_pre_hydro_and_plugins_spellings_give_the_same_costmap() -> None:
    old, warnings = CostmapParams.from_ros(
        {
            "global_frame": "map", "robot_base_frame": "base_footprint", "static_map": True,
            "map_type": "costmap", "obstacle_range": 3.0, "raytrace_range": 3.5,
            "inflation_radius": 0.4, "cost_scaling_factor": 4.0,
            "footprint": [[-0.1, -0.1], [-0.1, 0.1], [0.1, 0.1], [0.1, -0.1]],
            "observation_sources": "scan", "scan": SCAN,
        }
    )  # fmt: skip
    assert any("pre-Hydro" in w for w in warnings)
    new, new_warnings = CostmapParams.from_ros(
        {
            "global_frame": "map", "robot_base_frame": "base_footprint",
            "footprint": "[[-0.1, -0.1], [-0.1, 0.1], [0.1, 0.1], [0.1, -0.1]]",
            "plugins": [STATIC, OBSTACLE, INFLATION],
            "obstacle_layer": {"obstacle_range": 3.0, "raytrace_range": 3.5,
                               "observation_sources": "scan", "scan": SCAN},
            "inflation_layer": {"inflation_radius": 0.4, "cost_scaling_factor": 4.0},
        }
    )  # fmt: skip
    assert new_warnings == ()
    assert old == new
    obstacle = new.plugins[1].params
    assert isinstance(obstacle, ObstacleLayerParams)
    src = obstacle.observation_sources[0]
    assert (src.name, src.obstacle_range, src.raytrace_range, src.data_type) == (
        "scan", 3.0, 3.5, "LaserScan",
    )  # fmt: skip
    assert new.plugins[2].params == InflationLayerParams(
        inflation_radius=0.4, cost_scaling_factor=4.0
    )


def test_flat_launch_names_and_parent_parameters_override_layers() -> None:
    # rosparam load flattens with "/"; ROS 2 files with "."; top-level names win (copyParent)
    p, _ = CostmapParams.from_ros(
        {
            "plugins": [STATIC, INFLATION],
            "inflation_layer/inflation_radius": 0.2,
            "inflation_radius": 0.7,
            "static_layer.map_topic": "/slam_map",
            "track_unknown_space": True,
        }
    )
    assert p.plugins[1].params == InflationLayerParams(inflation_radius=0.7)
    static = p.plugins[0].params
    assert isinstance(static, StaticLayerParams)
    assert static.map_topic == "/slam_map" and static.track_unknown_space


def test_pre_hydro_without_static_map_and_voxel_layer() -> None:
    p, warnings = CostmapParams.from_ros(
        {"map_type": "voxel", "z_voxels": 10, "rolling_window": True, "width": 3, "height": 3}
    )
    assert [s.type for s in p.plugins] == ["costmap_2d::VoxelLayer", "costmap_2d::InflationLayer"]
    assert any("VoxelLayer runs as a 2-D obstacle layer" in w for w in warnings)
    assert p.size_cells == (60, 60)


def test_unknown_names_are_warned_about_by_name_and_ignored() -> None:
    p, warnings = CostmapParams.from_ros(
        {
            "plugins": [STATIC, INFLATION],
            "inflation_radiuss": 0.3,
            "static_layer": {"lethal_cost_threshhold": 3},
            "inflation_layer": {"inflation_radius": 0.4},
        }
    )
    assert p.plugins[1].params == InflationLayerParams(inflation_radius=0.4)
    assert "costmap: unknown parameter 'inflation_radiuss' is ignored" in warnings
    assert (
        "costmap/static_layer: unknown parameter 'lethal_cost_threshhold' (did you mean "
        "lethal_cost_threshold?) is ignored" in warnings
    )


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"resolution": 0.0}, "resolution must be > 0"),
        (
            {"plugins": [{"name": "x", "type": "social_navigation_layers::ProxemicLayer"}]},
            "unknown costmap plugin type",
        ),
        (
            {
                "plugins": [OBSTACLE],
                "obstacle_layer": {"observation_sources": "s", "s": {"data_type": "Sonar"}},
            },
            "data_type must be one of",
        ),
        (
            {"plugins": [INFLATION], "inflation_layer": {"inflation_radius": "far"}},
            "inflation_radius must be a finite number",
        ),
        ({"plugins": "static_layer"}, "plugins must be a list"),
        ({"footprint": [[0, 0], [1, 1]]}, "at least three points"),
        ({"static_map": "yes"}, "static_map must be true or false"),
    ],
)
def test_bad_parameters_name_the_problem(values: dict[str, object], message: str) -> None:
    with pytest.raises(NavigationParamsError, match=message):
        CostmapParams.from_ros(values)


def test_unused_namespaces_are_reported() -> None:
    _, warnings = CostmapParams.from_ros({"plugins": [INFLATION], "obstacle_layer/enabled": True})
    assert any("no plugin named obstacle_layer" in w for w in warnings)
