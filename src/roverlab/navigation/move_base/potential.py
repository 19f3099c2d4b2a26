"""The global planners' potential topics, as NavfnROS and GlobalPlanner publish them:
``~NavfnROS/potential`` (``sensor_msgs/PointCloud2``, with ``visualize_potential``) and
``~GlobalPlanner/potential`` (``nav_msgs/OccupancyGrid``, with ``publish_potential``, on by
default), after every plan."""

from __future__ import annotations

from typing import Any

from roverlab.core import Node
from roverlab.geometry import SE2
from roverlab.msgs import OccupancyGrid, PointCloud2
from roverlab.navigation.planners import (
    GlobalPlanner,
    NavfnPlanner,
    potential_to_grid,
    potential_to_pointcloud,
)

__all__ = ["PotentialPublisher"]


class PotentialPublisher:
    """Publishes ``planner``'s last potential on ``~<name>/potential`` when its parameters
    ask for it (nothing is advertised otherwise)."""

    def __init__(self, node: Node, name: str, planner: Any) -> None:
        self.node = node
        self.planner = planner
        self.pub: Any = None
        if isinstance(planner, NavfnPlanner) and planner.params.visualize_potential:
            self.pub = node.create_publisher(PointCloud2, f"~/{name}/potential", 1)
        elif isinstance(planner, GlobalPlanner) and planner.params.publish_potential:
            self.pub = node.create_publisher(OccupancyGrid, f"~/{name}/potential", 1)

    def publish(self, start: SE2, frame_id: str, resolution: float) -> None:
        """The potential of the plan just made from ``start`` (``frame_id``)."""
        pot = getattr(self.planner, "potential", None)
        if self.pub is None or pot is None:
            return
        stamp = self.node.get_clock().now()
        ox, oy = self.planner.potential_origin
        if isinstance(self.planner, NavfnPlanner):
            cell = (int((start.x - ox) / resolution), int((start.y - oy) / resolution))
            inside = 0 <= cell[0] < pot.shape[1] and 0 <= cell[1] < pot.shape[0]
            msg = potential_to_pointcloud(
                pot, (ox, oy), resolution, cell if inside else None, frame_id, stamp
            )
        else:
            scale = float(self.planner.params.publish_scale)
            msg = potential_to_grid(pot, (ox, oy), resolution, frame_id, stamp, scale)
        self.pub.publish(msg)
