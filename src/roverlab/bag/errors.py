"""Errors of :mod:`roverlab.bag`."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["BagError"]


class BagError(RoverlabError):
    """A bag could not be written or read (the message names the file and the problem)."""
