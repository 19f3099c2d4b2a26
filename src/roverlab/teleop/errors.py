"""Errors of the keyboard teleoperation package."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["NotATerminalError", "TeleopError"]


class TeleopError(RoverlabError):
    """A bad teleop setting (speed, turn, command-line argument)."""


class NotATerminalError(TeleopError):
    """Keys can only be read one at a time from a terminal (a TTY), not from a pipe or file."""
