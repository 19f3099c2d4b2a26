"""The launch package's errors."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["LaunchError"]


class LaunchError(RoverlabError):
    """A launch file could not be read or run."""
