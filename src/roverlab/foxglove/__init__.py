"""Foxglove: the running system served over the Foxglove WebSocket protocol (foxglove_bridge)."""

from roverlab.foxglove.bridge import FoxgloveBridge, FoxgloveError

__all__ = ["FoxgloveBridge", "FoxgloveError"]
