"""hector_mapping (Kohlbrecher et al. 2011) as a pure algorithm: no node, no TF, no clock.

* :class:`HectorParams`: the ROS parameters (names and defaults of hector_mapping).
* :class:`HectorSLAM`: ``process(ranges, angles, odom_pose=None) -> SE2`` per scan;
  ``run_log(log)`` over a ``roverlab.slam.data.logs.LaserLog``; ``occupancy()`` for the map.
* :func:`scan_constraint`: how well a scan fixes the robot (degenerate in a bare corridor).
* :class:`MultiResGrid`: the multi-resolution log-odds map with compiled Bresenham updates.
* :func:`match`: the coarse-to-fine Gauss-Newton matcher; :func:`interpolate` and
  :func:`cost`: its bilinear map value / gradient and its objective, for inspection.
"""

from roverlab.slam.degeneracy import ScanConstraint, scan_constraint
from roverlab.slam.hector.errors import (
    HectorError,
    HectorInputError,
    HectorParamsError,
    OutOfMapError,
)
from roverlab.slam.hector.grid import HectorMap, MultiResGrid, prob_to_log_odds
from roverlab.slam.hector.matcher import cost, interpolate, match, normal_equations
from roverlab.slam.hector.params import MOTION_PREDICTIONS, NODE_PARAMETERS, HectorParams
from roverlab.slam.hector.slam import (
    GuardCounts,
    HectorRun,
    HectorSLAM,
    Runaway,
    ScanLike,
    run_log,
)

__all__ = [
    "MOTION_PREDICTIONS",
    "NODE_PARAMETERS",
    "GuardCounts",
    "HectorError",
    "HectorInputError",
    "HectorMap",
    "HectorParams",
    "HectorParamsError",
    "HectorRun",
    "HectorSLAM",
    "MultiResGrid",
    "OutOfMapError",
    "Runaway",
    "ScanConstraint",
    "ScanLike",
    "cost",
    "interpolate",
    "match",
    "normal_equations",
    "prob_to_log_odds",
    "run_log",
    "scan_constraint",
]
