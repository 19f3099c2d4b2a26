"""Errors of :mod:`roverlab.slam.gmapping`."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["GMappingError", "GMappingInputError", "GMappingParamsError"]


class GMappingError(RoverlabError):
    """Base class of every error raised by :mod:`roverlab.slam.gmapping`."""


class GMappingParamsError(GMappingError, ValueError):
    """A parameter is out of range, of the wrong type, or unknown (a misspelt ROS name)."""


class GMappingInputError(GMappingError, ValueError):
    """A scan, pose or timestamp has the wrong shape or non-finite values."""
