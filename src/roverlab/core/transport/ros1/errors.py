"""Errors of the ROS 1 wire protocol."""

from __future__ import annotations

from roverlab.core.errors import TransportError

__all__ = ["HeaderError", "MasterError", "ProtocolError", "Ros1Error"]


class Ros1Error(TransportError):
    """Something on the ROS 1 wire failed."""


class ProtocolError(Ros1Error):
    """A peer sent bytes that are not TCPROS (bad length, cut short, over a cap)."""


class HeaderError(ProtocolError):
    """A malformed TCPROS connection header, or one the other side rejected."""


class MasterError(Ros1Error):
    """The master answered an API call with a failure code, or could not be reached."""
