"""ROS 1 graph names: namespaces and resolution against a caller (rosgraph.names)."""

from __future__ import annotations

__all__ = ["canonical", "namespace_of", "resolve_name"]


def canonical(name: str) -> str:
    """``name`` without repeated or trailing slashes (``/`` stays ``/``)."""
    if not name:
        return name
    parts = [p for p in name.split("/") if p]
    lead = "/" if name.startswith("/") else ""
    return lead + "/".join(parts) if parts else "/"


def namespace_of(name: str) -> str:
    """The namespace a node name lives in, with a trailing slash: ``/a/b`` -> ``/a/``."""
    name = canonical(name)
    if not name or name == "/":
        return "/"
    head = name.rsplit("/", 1)[0]
    return head + "/" if head else "/"


def resolve_name(name: str, caller_id: str) -> str:
    """``name`` as a global name, seen from node ``caller_id``: ``~x`` is private to the
    caller, ``x`` lives in the caller's namespace, ``/x`` stays."""
    if not name:
        return namespace_of(caller_id)
    if name.startswith("/"):
        return canonical(name)
    if name.startswith("~"):
        return canonical(canonical(caller_id) + "/" + name[1:])
    return canonical(namespace_of(caller_id) + name)
