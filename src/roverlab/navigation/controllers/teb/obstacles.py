"""teb_local_planner's obstacles from the costmap (``updateObstacleContainerWithCostmap``)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from roverlab.geometry import SE2
from roverlab.navigation.controllers.teb.params import TebParams
from roverlab.navigation.costmap.costmap_2d import LETHAL_OBSTACLE, Costmap2D

__all__ = ["association_reach", "costmap_obstacles", "model_reach"]


def model_reach(kind: str, values: NDArray[np.float64]) -> float:
    """How far the robot model reaches from the pose (m): 0 for a point."""
    if kind == "circular":
        return float(values[0])
    if kind == "two_circles":
        return float(max(abs(values[0]) + values[1], abs(values[2]) + values[3]))
    if kind in ("line", "polygon"):
        return float(np.hypot(values[0::2], values[1::2]).max())
    return 0.0


def association_reach(p: TebParams) -> float:
    """How far from a pose an obstacle can get an edge of that pose (m): the association
    cutoff (or force-inclusion distance, the larger) plus the model's reach."""
    return p.min_obstacle_dist * max(
        p.obstacle_association_cutoff_factor, p.obstacle_association_force_inclusion_factor
    ) + model_reach(p.footprint_model.type, p.footprint_model.as_array())


def costmap_obstacles(
    p: TebParams, pose: SE2, cm: Costmap2D, local: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Every lethal cell of ``cm`` as a point obstacle ``(K, 2)`` (``include_costmap_obstacles``),
    except those behind the robot farther than ``costmap_obstacles_behind_robot_dist``
    (TEB's filter) -- unless the local plan ``local`` itself runs behind the robot within
    :func:`association_reach` of the cell.

    That exception is roverlab's: the band, initialised from a plan that turns back, runs
    behind the robot, and TEB's feasibility check tests every cell its first metre passes.
    TEB drops those cells, so the optimiser never pushes the band off a post there and the
    check rejects the band every cycle (BARN world_176, 85 and 64 at 0.5 m/s stood still
    until move_base's recoveries). A plan running ahead keeps TEB's filter unchanged.
    """
    if not p.include_costmap_obstacles:
        return np.zeros((0, 2))
    ys, xs = np.nonzero(cm.costs == LETHAL_OBSTACLE)
    obs = np.column_stack(
        [cm.origin_x + (xs + 0.5) * cm.resolution, cm.origin_y + (ys + 0.5) * cm.resolution]
    )
    heading = np.array([math.cos(pose.theta), math.sin(pose.theta)])
    rel = obs - [pose.x, pose.y]
    far = np.hypot(rel[:, 0], rel[:, 1]) > p.costmap_obstacles_behind_robot_dist
    drop = (rel @ heading < 0) & far
    back = local[(local[:, :2] - [pose.x, pose.y]) @ heading < 0, :2]
    if drop.any() and len(back):
        idx = np.nonzero(drop)[0]
        hits = cKDTree(obs[idx]).query_ball_point(back, association_reach(p), return_sorted=False)
        near = np.unique(np.concatenate([np.asarray(h, dtype=np.int64) for h in hits]))
        drop[idx[near]] = False
    return np.ascontiguousarray(obs[~drop])
