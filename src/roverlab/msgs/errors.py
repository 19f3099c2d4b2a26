"""Errors of :mod:`roverlab.msgs`.

Every error derives from :class:`MessageError`, itself a :class:`~roverlab.errors.RoverlabError`,
and carries a one-line message that names the type and, where there is one, the field path.
"""

from __future__ import annotations

from roverlab.errors import RoverlabError

__all__ = [
    "FieldError",
    "MessageError",
    "MessageValueError",
    "MessageYAMLError",
    "SerializationError",
    "UnknownTypeError",
]


class MessageError(RoverlabError):
    """Base class of all message errors."""


class UnknownTypeError(MessageError):
    """A message type name that the type store does not know."""


class FieldError(MessageError):
    """A field name (or dotted field path) that the message type does not have."""


class MessageValueError(MessageError):
    """A field value of the wrong kind (a string for a float, a dict for a number, ...)."""


class MessageYAMLError(MessageError):
    """Text that is not valid YAML, or not a YAML mapping, where a message was expected."""


class SerializationError(MessageError):
    """Bytes that are not a valid CDR serialisation of the requested type."""
