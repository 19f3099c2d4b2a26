"""Errors of the device drivers."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = ["DeviceError", "DriverError"]


class DriverError(RoverlabError):
    """A driver's configuration is invalid (a parameter, a calibration file)."""


class DeviceError(DriverError):
    """A device cannot be opened, stopped answering, or sent something unreadable."""
