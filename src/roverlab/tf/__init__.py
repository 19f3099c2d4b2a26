"""Coordinate frames over time with tf2 semantics.

``BufferCore`` (pure) and ``Buffer`` (thread-safe, waits with a timeout) store transforms
and answer ``lookup_transform(target, source, time)`` = ``target_T_source``;
``TransformBroadcaster``, ``StaticTransformBroadcaster`` and ``TransformListener`` carry
them over ``/tf`` and ``/tf_static``. Errors are tf2's, under :class:`TransformException`.
"""

from __future__ import annotations

from roverlab.tf.buffer import (
    DEFAULT_AUTHORITY,
    DEFAULT_CACHE_TIME,
    MAX_GRAPH_DEPTH,
    Buffer,
    BufferCore,
)
from roverlab.tf.convert import (
    TF_MESSAGE_TYPE,
    TRANSFORM_STAMPED_TYPE,
    format_transform_echo,
    tf_message,
    transform_from_msg,
    transform_to_msg,
)
from roverlab.tf.errors import (
    BackwardExtrapolationException,
    ConnectivityException,
    ExtrapolationException,
    ForwardExtrapolationException,
    InvalidArgumentException,
    LookupException,
    NoDataForExtrapolationException,
    TimeoutException,
    TransformException,
)
from roverlab.tf.message_filter import TfMessageFilter, Throttle
from roverlab.tf.ros import (
    TF_STATIC_TOPIC,
    TF_TOPIC,
    NodeLike,
    StaticTransformBroadcaster,
    TransformBroadcaster,
    TransformListener,
)

__all__ = [
    "DEFAULT_AUTHORITY",
    "DEFAULT_CACHE_TIME",
    "MAX_GRAPH_DEPTH",
    "TF_MESSAGE_TYPE",
    "TF_STATIC_TOPIC",
    "TF_TOPIC",
    "TRANSFORM_STAMPED_TYPE",
    "BackwardExtrapolationException",
    "Buffer",
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "ForwardExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "NoDataForExtrapolationException",
    "NodeLike",
    "StaticTransformBroadcaster",
    "TfMessageFilter",
    "Throttle",
    "TimeoutException",
    "TransformBroadcaster",
    "TransformException",
    "TransformListener",
    "format_transform_echo",
    "tf_message",
    "transform_from_msg",
    "transform_to_msg",
]
