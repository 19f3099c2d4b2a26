"""Costmap2DROS / costmap_2d_node on the deterministic executor."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from roverlab.core import Context, QoSProfile
from roverlab.geometry import SE2, Transform3
from roverlab.launch.registry import REGISTRY
from roverlab.msgs import OccupancyGrid, array_to_occupancy_grid, make_scan, occupancy_grid_to_array
from roverlab.navigation.costmap.node import Costmap2DNode
from roverlab.navigation.errors import NavigationParamsError
from roverlab.tf import TransformBroadcaster, transform_to_msg
from tests.navigation.conftest import INFLATION, OBSTACLE, STATIC

LATCHED = QoSProfile(depth=1, durability="transient_local")


def _world(ctx: Context, robot: SE2) -> None:
    """A map publisher (10 x 10 m, a wall at x = 5 m) and TF map -> base_link -> laser."""
    node = ctx.create_node("world")
    grid = np.zeros((100, 100), np.int8)
    grid[:, 50] = 100
    node.create_publisher(OccupancyGrid, "/map", LATCHED).publish(
        array_to_occupancy_grid(grid, resolution=0.1, frame_id="map")
    )
    tfb = TransformBroadcaster(node)

    def tick() -> None:
        now = node.get_clock().now()
        tfb.send_transform(
            [
                transform_to_msg("map", "base_link", now, Transform3.from_se2(robot)),
                transform_to_msg("base_link", "laser", now, Transform3((0.1, 0.0, 0.2))),
            ]
        )

    node.create_timer(0.05, tick)


def _params() -> dict[str, Any]:
    return {
        "costmap/global_frame": "map",
        "costmap/robot_base_frame": "base_link",
        "costmap/update_frequency": 5.0,
        "costmap/publish_frequency": 2.0,
        "costmap/robot_radius": 0.2,
        "costmap/plugins": [STATIC, OBSTACLE, INFLATION],
        "costmap/obstacle_layer/observation_sources": "scan",
        "costmap/obstacle_layer/scan/data_type": "LaserScan",
        "costmap/obstacle_layer/scan/clearing": True,
        "costmap/inflation_layer/inflation_radius": 0.3,
    }


def test_costmap_node_publishes_the_costmap_updates_and_footprint() -> None:
    ctx = Context()
    _world(ctx, SE2(2.0, 5.0, 0.0))
    node = REGISTRY[("costmap_2d", "costmap_2d_node")]
    assert node is not None
    cm_node = Costmap2DNode(ctx, parameter_overrides=_params())
    maps: list[Any] = []
    updates: list[Any] = []
    feet: list[Any] = []
    sub = ctx.create_node("listener")
    sub.create_subscription(OccupancyGrid, "/costmap_2d_node/costmap/costmap", maps.append, LATCHED)
    sub.create_subscription(
        "map_msgs/msg/OccupancyGridUpdate", "/costmap_2d_node/costmap/costmap_updates",
        updates.append, 10,
    )  # fmt: skip
    sub.create_subscription(
        "geometry_msgs/msg/PolygonStamped", "/costmap_2d_node/costmap/footprint", feet.append, 10
    )
    ctx.spin_for(1.5)
    assert maps, "no costmap published"
    grid = occupancy_grid_to_array(maps[-1])
    assert grid.shape == (100, 100)
    assert grid[50, 50] == 100 and grid[50, 51] == 99  # lethal, inscribed: 0.1 m <= 0.196
    assert grid[50, 20] == 0
    assert feet and feet[-1].header.frame_id == "map"
    xs = [p.x for p in feet[-1].polygon.points]
    assert min(xs) == pytest.approx(2.0 - 0.21) and max(xs) == pytest.approx(2.0 + 0.21)
    # a box seen 1 m ahead of the laser is marked and inflated, and sent as an update
    scans = ctx.create_node("laser")
    pub = scans.create_publisher("sensor_msgs/msg/LaserScan", "/scan", 10)
    ranges = np.full(181, np.inf)
    ranges[90] = 1.0
    pub.publish(
        make_scan(
            ranges, angle_min=-np.pi / 2, angle_max=np.pi / 2, range_min=0.1, range_max=8.0,
            frame_id="laser", stamp=scans.get_clock().now(),
        )
    )  # fmt: skip
    ctx.spin_for(1.5)
    costmap = cm_node.costmap_ros.costmap
    cell = costmap.world_to_map(3.1, 5.0)
    assert cell is not None and costmap.get_cost(*cell) == 254
    assert updates and all(u.width * u.height == len(u.data) for u in updates)
    assert cm_node.unused_parameter_overrides() == []
    ctx.shutdown()


def test_costmap_and_footprint_messages_are_built_only_for_a_reader() -> None:
    ctx = Context()
    _world(ctx, SE2(2.0, 5.0, 0.0))
    cm_node = Costmap2DNode(ctx, parameter_overrides=_params())
    ros = cm_node.costmap_ros
    built: list[str] = []
    real = ros._publisher.next_message

    def counted(*args: Any, **kwargs: Any) -> Any:
        built.append("costmap")
        return real(*args, **kwargs)

    ros._publisher.next_message = counted  # type: ignore[method-assign]
    ctx.spin_for(1.5)
    assert ros.updates >= 5 and built == []  # updated, nothing published
    maps: list[Any] = []
    feet: list[Any] = []
    sub = ctx.create_node("listener")
    sub.create_subscription(OccupancyGrid, "/costmap_2d_node/costmap/costmap", maps.append, LATCHED)
    sub.create_subscription(
        "geometry_msgs/msg/PolygonStamped", "/costmap_2d_node/costmap/footprint", feet.append, 10
    )
    ctx.spin_for(1.0)
    # a reader that came late gets the whole grid, and the footprint every update
    assert built and maps and occupancy_grid_to_array(maps[0]).shape == (100, 100)
    assert len(feet) >= 4
    ctx.shutdown()


def test_bad_costmap_parameter_fails_the_node_with_its_name() -> None:
    ctx = Context()
    with pytest.raises(NavigationParamsError, match="costmap: update_frequency must be >= 0"):
        Costmap2DNode(ctx, parameter_overrides={"costmap/update_frequency": -5.0})
    ctx.shutdown()


def test_costmap_node_from_a_launch_file_with_pre_hydro_rosparam_files(tmp_path: Any) -> None:
    from roverlab.launch import build_launch

    (tmp_path / "common.yaml").write_text(
        "obstacle_range: 3.0\nraytrace_range: 3.5\nfootprint: [[-0.1, -0.1], [-0.1, 0.1], "
        "[0.1, 0.1], [0.1, -0.1]]\ninflation_radius: 0.4\ncost_scaling_factor: 3.0\n"
        "map_type: costmap\nobservation_sources: scan\n"
        "scan: {sensor_frame: laser, data_type: LaserScan, topic: scan, marking: true, "
        "clearing: true}\n"
    )
    (tmp_path / "global.yaml").write_text(
        "costmap:\n  global_frame: map\n  robot_base_frame: base_link\n"
        "  update_frequency: 5.0\n  publish_frequency: 1.0\n  static_map: true\n"
    )
    launch_file = tmp_path / "costmap.launch"
    launch_file.write_text(
        f"""<launch>
  <node pkg="costmap_2d" type="costmap_2d_node" name="costmap_node">
    <rosparam file="{tmp_path}/common.yaml" command="load" ns="costmap"/>
    <rosparam file="{tmp_path}/global.yaml" command="load"/>
  </node>
</launch>"""
    )
    ctx = Context()
    _world(ctx, SE2(2.0, 5.0, 0.0))
    launch = build_launch(launch_file, context=ctx)
    (node,) = launch.nodes
    assert isinstance(node, Costmap2DNode)
    p = node.costmap_ros.params
    assert [s.type.split("::")[1] for s in p.plugins] == [
        "StaticLayer",
        "ObstacleLayer",
        "InflationLayer",
    ]
    assert p.footprint is not None and len(p.footprint) == 4
    ctx.spin_for(1.0)
    grid = node.costmap_ros.costmap
    assert grid.size_x == 100 and grid.get_cost(50, 50) == 254
    assert not launch.warnings, launch.warnings
    ctx.shutdown()
