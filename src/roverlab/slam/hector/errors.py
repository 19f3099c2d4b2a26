"""Errors of :mod:`roverlab.slam.hector`."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["HectorError", "HectorInputError", "HectorParamsError", "OutOfMapError"]


class HectorError(RoverlabError):
    """Base class of every error raised by :mod:`roverlab.slam.hector`."""


class HectorParamsError(HectorError, ValueError):
    """A parameter is out of range, of the wrong type, or unknown (a misspelt ROS name)."""


class HectorInputError(HectorError, ValueError):
    """A scan or pose has the wrong shape or non-finite values."""


class OutOfMapError(HectorError):
    """The robot left the fixed-size map; a larger ``map_size`` (or resolution) is needed."""
