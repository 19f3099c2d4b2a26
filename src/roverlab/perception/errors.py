"""Errors of the perception algorithms."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["PerceptionError"]


class PerceptionError(RoverlabError):
    """A detector cannot be set up (a missing classifier file, a bad parameter)."""
