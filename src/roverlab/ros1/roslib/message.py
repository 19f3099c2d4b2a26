"""``roslib.message.get_message_class`` / ``get_service_class``."""

from __future__ import annotations

from typing import Any

from roverlab.msgs import normalize_type_name
from roverlab.ros1.messages import message_class, service_class

__all__ = ["get_message_class", "get_service_class"]


def get_message_class(message_type: str, reload_on_error: bool = False) -> Any:
    """The class of ``pkg/Name`` (None if unknown, as roslib)."""
    try:
        return message_class(normalize_type_name(message_type))
    except Exception:
        return None


def get_service_class(service_type: str, reload_on_error: bool = False) -> Any:
    try:
        return service_class(service_type)
    except Exception:
        return None
