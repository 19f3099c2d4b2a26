"""SLAM data: laser logs, trajectories, the relative-pose metric and pose graphs.

The data side of SLAM, shared by the SLAM algorithms and the benchmarks:

* :mod:`.logs`: laser logs (CARMEN ``.clf``, ROS 1 bags, ROS 2 bags, MCAP) as a
  :class:`LaserLog` of :class:`ScanRecord` (ranges, beam geometry, odometry pose, laser
  offset, exact timestamp text);
* :mod:`.trajectory`: :class:`Trajectory` and TUM trajectory files;
* :mod:`.evaluation`: Kuemmerle et al.'s relative-pose metric on ``.relations`` files;
* :mod:`.posegraph`: g2o ``VERTEX_SE2`` / ``EDGE_SE2`` graphs, chi2 and the sparse
  Gauss-Newton / Levenberg-Marquardt optimiser the graph-SLAM back end uses.

Every error is a :class:`SlamError` (a :class:`roverlab.errors.RoverlabError`).
"""

from __future__ import annotations

from .errors import EvaluationError, LogError, PoseGraphError, SlamError, TrajectoryError
from .evaluation import Metrics, Relations, evaluate, read_relations
from .logs import (
    LaserLog,
    ScanRecord,
    carmen_beam_geometry,
    iter_log,
    load_log,
    read_bag,
    read_clf,
)
from .pose_solver import OptimizationReport, chordal_initialisation, optimize
from .posegraph import (
    PoseGraph,
    chi2,
    edge_errors,
    odometry_initialisation,
    read_g2o,
    write_g2o,
)
from .trajectory import Trajectory, format_timestamp, read_tum, write_tum

__all__ = [
    "EvaluationError",
    "LaserLog",
    "LogError",
    "Metrics",
    "OptimizationReport",
    "PoseGraph",
    "PoseGraphError",
    "Relations",
    "ScanRecord",
    "SlamError",
    "Trajectory",
    "TrajectoryError",
    "carmen_beam_geometry",
    "chi2",
    "chordal_initialisation",
    "edge_errors",
    "evaluate",
    "format_timestamp",
    "iter_log",
    "load_log",
    "odometry_initialisation",
    "optimize",
    "read_bag",
    "read_clf",
    "read_g2o",
    "read_relations",
    "read_tum",
    "write_g2o",
    "write_tum",
]
