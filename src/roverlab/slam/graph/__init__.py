"""Graph SLAM (slam_karto / slam_toolbox, Karto's mapper) as a pure algorithm.

* :class:`GraphParams`: the ROS parameters (slam_toolbox / slam_karto names, slam_toolbox
  defaults).
* :class:`GraphSLAM`: ``process(ranges, angles, odom_pose, timestamp, ...) -> SE2`` per
  scan; ``map_to_odom()``, ``occupancy()``, ``graph()`` (a ``roverlab.slam.data.PoseGraph``);
  ``run_log(log) -> GraphRun``.
* :func:`run_graph`: ``run_graph(records, params_dict) -> GraphRun`` for the CLI.
* :mod:`.matcher`: Karto's correlative scan matcher, searched by branch and bound.
* :mod:`.kernels`: the matcher's compiled kernels.
"""

from roverlab.slam.graph.errors import (
    GraphSlamError,
    GraphSlamInputError,
    GraphSlamParamsError,
)
from roverlab.slam.graph.matcher import (
    CorrelationGrid,
    MatchResult,
    Penalty,
    build_grid,
    match_scan,
    response,
    valid_points,
)
from roverlab.slam.graph.params import NODE_PARAMETERS, GraphParams
from roverlab.slam.graph.slam import GraphMap, GraphRun, GraphSLAM, ScanLike, run_graph, run_log

__all__ = [
    "NODE_PARAMETERS",
    "CorrelationGrid",
    "GraphMap",
    "GraphParams",
    "GraphRun",
    "GraphSLAM",
    "GraphSlamError",
    "GraphSlamInputError",
    "GraphSlamParamsError",
    "MatchResult",
    "Penalty",
    "ScanLike",
    "build_grid",
    "match_scan",
    "response",
    "run_graph",
    "run_log",
    "valid_points",
]
