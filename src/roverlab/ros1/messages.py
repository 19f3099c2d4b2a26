"""ROS 1 message and service classes over roverlab's types: ``from geometry_msgs.msg import
Pose`` in a rospy script.

* :class:`Ros1MessageClass`: genpy's constructor rules (no arguments, every field
  positionally, or keywords: ``Pose(Point(1, 2, 0), Quaternion(0, 0, 0, 1))``), ``_type``,
  ``__slots__``, ``_slot_types``, ``_has_header``, constants as attributes
  (``GoalStatus.SUCCEEDED``), ``isinstance``. Instances are roverlab messages (ROS 2
  layout), so they publish, serialise and record like any other.
* :class:`Ros1ServiceClass`: ``std_srvs.srv.Empty`` with ``_request_class`` and
  ``_response_class``; ``EmptyRequest`` / ``EmptyResponse`` are message classes.
* :class:`InterfaceModule`: the ``pkg.msg`` / ``pkg.srv`` module, its names made on demand
  (and listed in ``__all__`` for ``from actionlib_msgs.msg import *``).

Where ROS 1 and ROS 2 layouts differ, the ROS 1 spelling is accepted: ``Header`` has no
``seq`` in ROS 2 (``Header(seq, stamp, frame_id)`` drops it; reading ``header.seq`` gives
0); ``CameraInfo``'s ``D``, ``K``, ``R``, ``P`` read and write ``d``, ``k``, ``r``, ``p``;
stamps have ``secs``/``nsecs`` (see :mod:`roverlab.ros1.rospy.rostime`).
"""

from __future__ import annotations

import types
from typing import Any

from roverlab.msgs import (
    MessageFactory,
    get_factory,
    get_service_type,
    message_definition,
)
from roverlab.msgs import classes as mc
from roverlab.msgs._store import STORE, FieldKind

__all__ = [
    "InterfaceModule",
    "Ros1MessageClass",
    "Ros1ServiceClass",
    "message_class",
    "ros1_name",
    "service_class",
]


def ros1_name(typename: str) -> str:
    """``geometry_msgs/Pose`` of ``geometry_msgs/msg/Pose``."""
    pkg, _, name = typename.split("/")
    return f"{pkg}/{name}"


class Ros1MessageClass:
    """A ROS 1 (genpy) message class: calling it builds a roverlab message."""

    def __init__(self, factory: MessageFactory[Any]) -> None:
        self._factory = factory
        spec = STORE.spec(factory.typename)
        self._fields = tuple(f.name for f in spec.visible_fields)
        self._type = ros1_name(factory.typename)
        self.__slots__ = list(self._fields)
        self._slot_types = [f.describe() for f in spec.visible_fields]
        self._has_header = bool(
            spec.visible_fields
            and spec.visible_fields[0].kind is FieldKind.MESSAGE
            and spec.visible_fields[0].typename == "std_msgs/msg/Header"
        )
        self._md5sum = "*"  # ROS 1's md5 of its own text; roverlab does not check it
        self.__name__ = factory.short_name
        self._is_header = factory.typename == "std_msgs/msg/Header"

    @property
    def __msgtype__(self) -> str:
        return self._factory.typename

    @property
    def cls(self) -> type[Any]:
        return self._factory.cls

    @property
    def _full_text(self) -> str:
        return message_definition(self._factory.typename)

    def __call__(self, *args: Any, **kwds: Any) -> Any:
        if args and kwds:
            raise TypeError(f"{self._type}: give fields either positionally or by keyword")
        if self._is_header:
            kwds.pop("seq", None)
            if len(args) == 3:
                args = args[1:]  # ROS 1's (seq, stamp, frame_id)
        if args:
            if len(args) != len(self._fields):
                raise TypeError(
                    f"Invalid number of arguments, args should be {list(self._fields)} "
                    f"args are {args!r}"
                )
            kwds = dict(zip(self._fields, args, strict=True))
        return self._factory(**kwds)

    def __instancecheck__(self, obj: object) -> bool:
        return isinstance(obj, self._factory.cls)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(self._factory, name)

    def __repr__(self) -> str:
        return f"<ROS 1 message class {self._type}>"


class Ros1ServiceClass:
    """A ROS 1 service class (``std_srvs.srv.Empty``)."""

    def __init__(self, typename: str) -> None:
        srv = get_service_type(typename)
        self.typename = srv.typename
        self._type = ros1_name(srv.typename)
        self.__name__ = srv.short_name
        self._request_class = message_class(srv.Request.typename)
        self._response_class = message_class(srv.Response.typename)

    def __repr__(self) -> str:
        return f"<ROS 1 service class {self._type}>"


_MESSAGES: dict[str, Ros1MessageClass] = {}
_SERVICES: dict[str, Ros1ServiceClass] = {}


def message_class(typename: str) -> Ros1MessageClass:
    found = _MESSAGES.get(typename)
    if found is None:
        found = Ros1MessageClass(get_factory(typename))
        _MESSAGES[typename] = found
    return found


def service_class(typename: str) -> Ros1ServiceClass:
    found = _SERVICES.get(typename)
    if found is None:
        found = Ros1ServiceClass(typename)
        _SERVICES[typename] = found
    return found


class InterfaceModule(types.ModuleType):
    """``pkg.msg`` or ``pkg.srv``: attributes are made from the type store on first use."""

    def __init__(self, name: str, package: str, kind: str) -> None:
        super().__init__(name, f"ROS 1 {kind} classes of {package} (roverlab)")
        self._package = package
        self._kind = kind
        self.__all__ = self._names()

    def _names(self) -> list[str]:
        prefix = f"{self._package}/{self._kind}/"
        names = [t[len(prefix) :] for t in STORE.typenames() if t.startswith(prefix)]
        if self._kind == "srv":
            out = []
            for n in names:
                if n.endswith("_Request"):
                    base = n[: -len("_Request")]
                    out += [base, base + "Request", base + "Response"]
            return sorted(out)
        return sorted(names)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        base = f"{self._package}/{self._kind}/"
        try:
            if self._kind == "msg":
                value: Any = message_class(base + name)
            elif name.endswith("Request") and STORE.has(
                base + name[: -len("Request")] + "_Request"
            ):
                value = message_class(base + name[: -len("Request")] + "_Request")
            elif name.endswith("Response") and STORE.has(
                base + name[: -len("Response")] + "_Response"
            ):
                value = message_class(base + name[: -len("Response")] + "_Response")
            else:
                value = service_class(base + name)
        except Exception:
            raise AttributeError(
                f"module '{self.__name__}' has no {self._kind} type '{name}'"
            ) from None
        setattr(self, name, value)
        return value


def _header_seq() -> None:
    """ROS 1's ``Header.seq``: reads 0 unless set (ROS 2 has no such field; not sent)."""
    mc.Header.seq = 0  # type: ignore[attr-defined]


def _camera_info_uppercase() -> None:
    def alias(lower: str) -> property:
        return property(
            lambda self: getattr(self, lower),
            lambda self, value: setattr(self, lower, value),
        )

    for upper in ("D", "K", "R", "P"):
        setattr(mc.CameraInfo, upper, alias(upper.lower()))


_header_seq()
_camera_info_uppercase()
