"""Errors of the map package."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["GridError", "MapError"]


class MapError(RoverlabError):
    """A map file or map setting that cannot be used: one line naming the file and problem."""


class GridError(MapError, ValueError):
    """A bad argument to an occupancy grid (size, resolution, scan shape, non-finite pose)."""
