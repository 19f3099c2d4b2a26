"""The global planners' ~potential topics (NavfnROS visualize_potential, GlobalPlanner
publish_potential): they were accepted and nothing was published."""

from __future__ import annotations

from typing import Any

from roverlab.core import Context
from roverlab.geometry import SE2
from roverlab.navigation.costmap import Costmap2D
from roverlab.navigation.move_base.potential import PotentialPublisher
from roverlab.navigation.planners import (
    GlobalPlanner,
    GlobalPlannerParams,
    NavfnParams,
    NavfnPlanner,
)


def test_potentials_are_published_when_the_planners_parameters_ask() -> None:
    ctx = Context()
    node = ctx.create_node("move_base")
    got: dict[str, list[Any]] = {"grid": [], "cloud": []}
    node.create_subscription("nav_msgs/OccupancyGrid", "/move_base/GlobalPlanner/potential",
                             got["grid"].append, 1)  # fmt: skip
    node.create_subscription("sensor_msgs/PointCloud2", "/move_base/NavfnROS/potential",
                             got["cloud"].append, 1)  # fmt: skip
    cm = Costmap2D(size_x=40, size_y=30, resolution=0.1)
    start, goal = SE2(0.5, 0.5, 0.0), SE2(3.5, 2.5, 0.0)
    gp = GlobalPlanner(GlobalPlannerParams())  # publish_potential: true by default
    gp.plan(start, goal, cm)
    PotentialPublisher(node, "GlobalPlanner", gp).publish(start, "map", 0.1)
    off = NavfnPlanner(NavfnParams())  # visualize_potential: false by default
    off.plan(start, goal, cm)
    PotentialPublisher(node, "NavfnROS", off).publish(start, "map", 0.1)
    ctx.spin_for(0.1)
    assert len(got["grid"]) == 1 and got["cloud"] == []
    grid = got["grid"][0]
    assert (grid.info.width, grid.info.height, grid.header.frame_id) == (40, 30, "map")
    assert max(grid.data) == 100 and (grid.data >= 0).sum() > 200  # reached cells, scaled
    on = NavfnPlanner(NavfnParams(visualize_potential=True))
    on.plan(start, goal, cm)
    PotentialPublisher(node, "NavfnROS", on).publish(start, "map", 0.1)
    ctx.spin_for(0.1)
    assert len(got["cloud"]) == 1 and got["cloud"][0].width > 100
    ctx.shutdown()
