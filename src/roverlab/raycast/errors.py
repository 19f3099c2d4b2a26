"""Errors of the ray casting kernels."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["RaycastError", "RaycastInputError"]


class RaycastError(RoverlabError):
    """Base class of every error raised by :mod:`roverlab.raycast`."""


class RaycastInputError(RaycastError, ValueError):
    """An argument has the wrong shape, dtype or value (NaN pose, negative range, ...)."""
