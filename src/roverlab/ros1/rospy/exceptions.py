"""rospy's exceptions, under their ROS 1 names."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = [
    "ROSException",
    "ROSInitException",
    "ROSInternalException",
    "ROSInterruptException",
    "ROSSerializationException",
    "ROSTimeMovedBackwardsException",
    "ServiceException",
    "TransportException",
]


class ROSException(RoverlabError):  # noqa: N818 (rospy's name)
    """Base class of rospy's errors."""


class ROSInitException(ROSException):
    """The node is used before ``rospy.init_node``."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """A wait ended because the node is shutting down (Ctrl-C, SIGTERM)."""


class ROSTimeMovedBackwardsException(ROSInterruptException):
    """Sim time jumped back during a sleep (the simulation restarted)."""

    def __init__(self, time: float = 0.0) -> None:
        super().__init__("ROS time moved backwards")
        self.time = time


class ROSSerializationException(ROSException):
    """A message could not be serialised."""


class ROSInternalException(Exception):  # noqa: N818 (rospy's name)
    """An error inside the rospy layer."""


class TransportException(ROSException):
    """The transport failed."""


class ServiceException(ROSException):
    """A service call failed (the server's error, or no such service)."""
