"""Errors of the node runtime."""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = [
    "GraphError",
    "InvalidTopicNameError",
    "ParameterError",
    "ServiceError",
    "ServiceUnavailableError",
    "TopicTypeError",
    "TransportError",
]


class GraphError(RoverlabError):
    """Something about the node graph is inconsistent (duplicate node name, ...)."""


class InvalidTopicNameError(GraphError):
    """A topic or node name that ROS would reject."""


class TopicTypeError(GraphError):
    """A topic used with two different message types."""


class ParameterError(RoverlabError):
    """Unknown, mistyped or invalid parameter."""


class TransportError(RoverlabError):
    """The inter-process transport could not be opened or failed."""


class ServiceError(RoverlabError):
    """A service call failed: the server's callback raised, or its answer was not a
    response of the service's type, or no answer came."""


class ServiceUnavailableError(ServiceError):
    """No server of the service is known (in this process or, over a transport, another)."""
