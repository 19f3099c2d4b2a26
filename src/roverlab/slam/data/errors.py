"""Errors of the SLAM data package: logs, trajectories, metrics and pose graphs."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["EvaluationError", "LogError", "PoseGraphError", "SlamError", "TrajectoryError"]


class SlamError(RoverlabError):
    """Base class of the errors of :mod:`roverlab.slam.data`."""


class LogError(SlamError):
    """A laser log (CARMEN ``.clf``, ROS bag, MCAP) cannot be read; names file and line."""


class TrajectoryError(SlamError):
    """A TUM trajectory cannot be read or written, or its poses are malformed."""


class EvaluationError(SlamError):
    """A relations file is malformed, or a trajectory cannot be scored against it."""


class PoseGraphError(SlamError):
    """A g2o pose graph is malformed or unsupported, or an optimisation cannot proceed."""
