"""Errors of :mod:`roverlab.localization.amcl`."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["AmclError", "AmclInputError", "AmclMapError", "AmclParamsError"]


class AmclError(RoverlabError):
    """Base class of every error raised by :mod:`roverlab.localization.amcl`."""


class AmclParamsError(AmclError, ValueError):
    """A parameter is out of range, of the wrong type, or unknown (a misspelt ROS name)."""


class AmclMapError(AmclError, ValueError):
    """A map amcl cannot localise in (no free cell, bad shape or resolution, rotated)."""


class AmclInputError(AmclError, ValueError):
    """A scan, odometry pose or initial pose amcl cannot use (shape, non-finite values,
    a pose outside the map)."""
