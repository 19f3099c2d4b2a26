"""Errors of :mod:`roverlab.description`.

Every error is a :class:`DescriptionError` (a :class:`~roverlab.errors.RoverlabError`) whose
message is one line naming the file and, where there is one, the element or macro at fault.
"""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["DescriptionError", "PackageNotFoundError", "URDFError", "XacroError"]


class DescriptionError(RoverlabError):
    """Base class of every robot-description error."""


class PackageNotFoundError(DescriptionError):
    """A ROS package name that no folder of the package path provides."""


class XacroError(DescriptionError):
    """A xacro file that cannot be expanded (bad XML, undefined macro, missing include...)."""


class URDFError(DescriptionError):
    """An expanded URDF that is not a valid robot (dangling joint, two roots, bad size...)."""
