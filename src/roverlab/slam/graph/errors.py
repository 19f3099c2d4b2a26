"""Errors of :mod:`roverlab.slam.graph`."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["GraphSlamError", "GraphSlamInputError", "GraphSlamParamsError"]


class GraphSlamError(RoverlabError):
    """Base class of every error raised by :mod:`roverlab.slam.graph`."""


class GraphSlamParamsError(GraphSlamError, ValueError):
    """A parameter is out of range, of the wrong type, or unknown (a misspelt ROS name)."""


class GraphSlamInputError(GraphSlamError, ValueError):
    """A scan or pose has the wrong shape or non-finite values, or time runs backwards."""
