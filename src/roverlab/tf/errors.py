"""Errors of the transform library, named and arranged as tf2's exceptions.

``except TransformException`` catches every lookup failure, as ``tf2.TransformException``
does in rclpy code.
"""

from __future__ import annotations

from roverlab.errors import RoverlabError


class TransformException(RoverlabError):  # noqa: N818 (tf2 names)
    """Base class of every tf error."""


class LookupException(TransformException):
    """A frame is unknown to the buffer (or the tree contains a loop)."""


class ConnectivityException(TransformException):
    """The two frames are known but belong to different trees."""


class ExtrapolationException(TransformException):
    """The requested time lies outside the data cached for an edge of the chain."""


class ForwardExtrapolationException(ExtrapolationException):
    """The requested time is newer than the latest data of an edge."""


class BackwardExtrapolationException(ExtrapolationException):
    """The requested time is older than the oldest data of an edge."""


class NoDataForExtrapolationException(ExtrapolationException):
    """An edge holds a single sample (or none) and the requested time is not its stamp."""


class TimeoutException(TransformException):
    """A transform did not become available within the time allowed."""


class InvalidArgumentException(TransformException):
    """A malformed transform or frame id: empty id, leading '/', NaN, self-parenting."""
