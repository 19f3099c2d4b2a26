"""Service and action types, and ROS interface files (``.msg``, ``.srv``, ``.action``).

The rosbags ROS 2 type store has messages only. This module adds:

* **services**: a ``.srv`` file ``pkg/srv/Name.srv`` becomes the two message types
  ``pkg/srv/Name_Request`` and ``pkg/srv/Name_Response`` (the ROS 2 convention, so the CDR
  bytes are rclpy's), grouped in a :class:`ServiceType` with ``Request`` / ``Response``
  constructors: ``get_service_type("std_srvs/Empty").Request()``;
* **actions** the ROS 1 actionlib way: ``pkg/action/Name.action`` becomes the seven
  messages ``genaction`` makes (``NameGoal``, ``NameResult``, ``NameFeedback``,
  ``NameActionGoal`` with header and ``actionlib_msgs/GoalID``, ``NameActionResult`` and
  ``NameActionFeedback`` with header and ``actionlib_msgs/GoalStatus``, and ``NameAction``),
  grouped in an :class:`ActionType`;
* definitions bundled with roverlab (``interfaces/<pkg>/{msg,srv,action}``: std_srvs,
  nav_msgs services, map_msgs, move_base_msgs, ...), registered lazily the first time a
  type of their package is asked for, and :func:`register_interface_file` /
  :func:`register_package_interfaces` for a user's own files.

Type names are accepted in the ROS 2 form (``std_srvs/srv/Empty``,
``move_base_msgs/action/MoveBase``), the ROS 1 form (``std_srvs/Empty``,
``move_base_msgs/MoveBaseAction``) and the Python module form (``std_srvs.srv.Empty``).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

from rosbags.interfaces import Nodetype
from rosbags.typesys import get_types_from_msg

from ._store import PLACEHOLDER_FIELD, STORE
from .errors import UnknownTypeError
from .factory import MessageFactory, get_factory

__all__ = [
    "BUNDLED_INTERFACES_DIR",
    "ActionType",
    "ServiceType",
    "action_typenames",
    "get_action_type",
    "get_service_type",
    "register_action",
    "register_interface_file",
    "register_message",
    "register_package_interfaces",
    "register_service",
    "service_typenames",
]

BUNDLED_INTERFACES_DIR: Final = Path(__file__).parent / "interfaces"
_EXTENSIONS: Final = {".msg": "msg", ".srv": "srv", ".action": "action"}
_SEPARATOR: Final = re.compile(r"^---\s*$", re.MULTILINE)
_PLACEHOLDER: Final[Any] = (PLACEHOLDER_FIELD, (Nodetype.BASE, ("uint8", 0)))

_SERVICES: dict[str, ServiceType] = {}
_ACTIONS: dict[str, ActionType] = {}


@dataclass(frozen=True)
class ServiceType:
    """A service: its name and the constructors of its request and response.

    Attributes:
        typename: ``std_srvs/srv/Empty``.
        Request: constructor of ``std_srvs/srv/Empty_Request`` (defaults for every field).
        Response: constructor of ``std_srvs/srv/Empty_Response``.
    """

    typename: str
    Request: MessageFactory[Any] = field(repr=False)
    Response: MessageFactory[Any] = field(repr=False)

    @property
    def short_name(self) -> str:
        return self.typename.rsplit("/", 1)[-1]


@dataclass(frozen=True)
class ActionType:
    """A ROS 1 actionlib action: its name and the constructors of its seven messages.

    Attributes:
        typename: ``move_base_msgs/action/MoveBase``.
        Goal, Result, Feedback: the user's parts (``MoveBaseGoal`` ...).
        ActionGoal, ActionResult, ActionFeedback: what travels on the ``goal``, ``result``
            and ``feedback`` topics (header + goal id or status + the part).
        Action: ``MoveBaseAction`` (the three wrapped messages).
    """

    typename: str
    Goal: MessageFactory[Any] = field(repr=False)
    Result: MessageFactory[Any] = field(repr=False)
    Feedback: MessageFactory[Any] = field(repr=False)
    ActionGoal: MessageFactory[Any] = field(repr=False)
    ActionResult: MessageFactory[Any] = field(repr=False)
    ActionFeedback: MessageFactory[Any] = field(repr=False)
    Action: MessageFactory[Any] = field(repr=False)

    @property
    def short_name(self) -> str:
        return self.typename.rsplit("/", 1)[-1]

    @property
    def ros1_name(self) -> str:
        """``move_base_msgs/MoveBaseAction``, as ROS 1 tools spell it."""
        pkg, _, name = self.typename.split("/")
        return f"{pkg}/{name}Action"


# ----------------------------------------------------------------------------- parsing
def _split_name(name: str, kind: str) -> tuple[str, str]:
    """``(package, Name)`` of ``pkg/Name``, ``pkg/<kind>/Name`` or ``pkg.<kind>.Name``."""
    parts = name.strip().replace(".", "/").split("/")
    if len(parts) == 3 and parts[1] == kind:
        parts = [parts[0], parts[2]]
    if len(parts) != 2 or not all(p.isidentifier() for p in parts):
        raise UnknownTypeError(f"not a {kind} type name: {name!r} (expected pkg/{kind}/Name)")
    return parts[0], parts[1]


def _parse_part(text: str, package: str, full: str) -> dict[str, Any]:
    """The rosbags typedef of one message text, registered under ``full``.

    Bare type names in the text refer to the package's messages (``pkg/msg/X``), as in ROS.
    An empty message gets ROS 2's placeholder field, so its CDR bytes are rclpy's.
    """
    tmp = f"{package}/msg/{full.rsplit('/', 1)[-1]}"
    try:
        parsed = get_types_from_msg(text, tmp)
    except Exception as err:  # rosbags raises its own grammar errors
        detail = " ".join(str(err).split())  # rosbags' grammar errors span lines
        raise UnknownTypeError(f"invalid definition of {full}: {detail}") from err
    consts, fields = parsed.pop(tmp)
    if not fields:
        fields = [_PLACEHOLDER]
    return {full: (consts, fields), **parsed}


def _parts(text: str, count: int, what: str) -> list[str]:
    parts = _SEPARATOR.split(text)
    if len(parts) != count:
        raise UnknownTypeError(
            f"invalid {what} definition: expected {count - 1} '---' separator line(s), "
            f"found {len(parts) - 1}"
        )
    return parts


def register_message(name: str, text: str) -> str:
    """Register a ``.msg`` definition as ``pkg/msg/Name``; returns the full name.

    Raises:
        UnknownTypeError: a bad name or definition, or a clash with a known type.
    """
    package, short = _split_name(name, "msg")
    full = f"{package}/msg/{short}"
    STORE.register(_parse_part(text, package, full))
    return full


def register_service(name: str, text: str) -> ServiceType:
    """Register a ``.srv`` definition (request ``---`` response) as ``pkg/srv/Name``.

    Raises:
        UnknownTypeError: a bad name or definition, or a clash with a known type.
    """
    package, short = _split_name(name, "srv")
    request, response = _parts(text, 2, f"service {package}/srv/{short}")
    base = f"{package}/srv/{short}"
    typedefs = _parse_part(request, package, base + "_Request")
    typedefs.update(_parse_part(response, package, base + "_Response"))
    STORE.register(typedefs)
    return _service(base)


def register_action(name: str, text: str) -> ActionType:
    """Register a ROS 1 ``.action`` definition (goal ``---`` result ``---`` feedback) as
    the seven actionlib messages of ``pkg/action/Name``.

    Raises:
        UnknownTypeError: a bad name or definition, or a clash with a known type.
    """
    package, short = _split_name(name, "action")
    goal, result, feedback = _parts(text, 3, f"action {package}/action/{short}")
    m = f"{package}/msg/{short}"
    typedefs: dict[str, Any] = {}
    typedefs.update(_parse_part(goal, package, m + "Goal"))
    typedefs.update(_parse_part(result, package, m + "Result"))
    typedefs.update(_parse_part(feedback, package, m + "Feedback"))
    header = "std_msgs/Header header\n"
    wrappers = {
        "ActionGoal": f"{header}actionlib_msgs/GoalID goal_id\n{m}Goal goal",
        "ActionResult": f"{header}actionlib_msgs/GoalStatus status\n{m}Result result",
        "ActionFeedback": f"{header}actionlib_msgs/GoalStatus status\n{m}Feedback feedback",
        "Action": (
            f"{m}ActionGoal action_goal\n{m}ActionResult action_result\n"
            f"{m}ActionFeedback action_feedback"
        ),
    }
    for suffix, body in wrappers.items():
        typedefs.update(_parse_part(body, package, m + suffix))
    STORE.register(typedefs)
    return _action(f"{package}/action/{short}")


def register_interface_file(path: str | os.PathLike[str], package: str | None = None) -> str:
    """Register one ``.msg`` / ``.srv`` / ``.action`` file; returns the full type name.

    Args:
        path: the file, normally ``<package>/<msg|srv|action>/<Name>.<ext>``.
        package: the package name (default: the folder above ``msg``/``srv``/``action``).

    Raises:
        UnknownTypeError: an unreadable file or a bad definition (the message names the
            file).
    """
    p = Path(path)
    kind = _EXTENSIONS.get(p.suffix)
    if kind is None:
        raise UnknownTypeError(f"{p}: not a .msg, .srv or .action file")
    pkg = package or p.parent.parent.name
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeError) as err:
        raise UnknownTypeError(f"{p}: cannot read: {err}") from err
    name = f"{pkg}/{kind}/{p.stem}"
    try:
        if kind == "msg":
            return register_message(name, text)
        if kind == "srv":
            return register_service(name, text).typename
        return register_action(name, text).typename
    except UnknownTypeError as err:
        raise UnknownTypeError(f"{p}: {err}") from err


def register_package_interfaces(package_dir: str | os.PathLike[str], package: str) -> list[str]:
    """Register every interface file of a ROS package folder (``msg/``, ``srv/``,
    ``action/``), messages first so services and actions can use them.

    Returns:
        The full names registered (or already known).
    """
    root = Path(package_dir)
    files = [f for kind in ("msg", "srv", "action") for f in sorted((root / kind).glob("*.*"))]
    pending = [f for f in files if f.suffix in _EXTENSIONS]
    names: list[str] = []
    # a message may use another of the same package defined later in name order
    while pending:
        failed: list[Path] = []
        last_error: UnknownTypeError | None = None
        for f in pending:
            try:
                names.append(register_interface_file(f, package))
            except UnknownTypeError as err:
                failed.append(f)
                last_error = err
        if len(failed) == len(pending):
            assert last_error is not None
            raise last_error
        pending = failed
    return names


# ----------------------------------------------------------------------------- bundled
def _bundled_index() -> dict[str, Path]:
    if not BUNDLED_INTERFACES_DIR.is_dir():
        return {}
    return {p.name: p for p in BUNDLED_INTERFACES_DIR.iterdir() if p.is_dir()}


_BUNDLED: Final = _bundled_index()
_LOADED: set[str] = set()


def _load_bundled(full: str) -> bool:
    package = full.split("/", 1)[0]
    if package in _LOADED or package not in _BUNDLED:
        return False
    _LOADED.add(package)
    register_package_interfaces(_BUNDLED[package], package)
    return True


STORE.add_type_source(_load_bundled)


# ----------------------------------------------------------------------------- lookups
def _service(base: str) -> ServiceType:
    found = _SERVICES.get(base)
    if found is None:
        found = ServiceType(base, get_factory(base + "_Request"), get_factory(base + "_Response"))
        _SERVICES[base] = found
    return found


def _action(base: str) -> ActionType:
    found = _ACTIONS.get(base)
    if found is None:
        pkg, _, short = base.split("/")
        m = f"{pkg}/msg/{short}"
        found = ActionType(
            base,
            Goal=get_factory(m + "Goal"),
            Result=get_factory(m + "Result"),
            Feedback=get_factory(m + "Feedback"),
            ActionGoal=get_factory(m + "ActionGoal"),
            ActionResult=get_factory(m + "ActionResult"),
            ActionFeedback=get_factory(m + "ActionFeedback"),
            Action=get_factory(m + "Action"),
        )
        _ACTIONS[base] = found
    return found


def get_service_type(ref: object) -> ServiceType:
    """The :class:`ServiceType` of ``std_srvs/srv/Empty``, ``std_srvs/Empty``,
    ``std_srvs.srv.Empty`` or of a ServiceType (returned as is).

    Raises:
        UnknownTypeError: not a service type name, or an unknown service.
    """
    if isinstance(ref, ServiceType):
        return ref
    name = str(getattr(ref, "typename", ref))
    package, short = _split_name(name, "srv")
    base = f"{package}/srv/{short}"
    try:
        return _service(base)
    except UnknownTypeError:
        known = service_typenames()
        close = [k for k in known if k.rsplit("/", 1)[-1].lower() == short.lower()]
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise UnknownTypeError(f"unknown service type {name!r}{hint}") from None


def get_action_type(ref: object) -> ActionType:
    """The :class:`ActionType` of ``move_base_msgs/action/MoveBase``,
    ``move_base_msgs/MoveBaseAction``, ``move_base_msgs/MoveBase``, the ``...Action``
    message class or factory, or of an ActionType (returned as is).

    Raises:
        UnknownTypeError: not an action type name, or an unknown action.
    """
    if isinstance(ref, ActionType):
        return ref
    msgtype = getattr(ref, "__msgtype__", None)
    name = str(msgtype if isinstance(msgtype, str) else ref).strip()
    parts = name.replace(".", "/").split("/")
    if len(parts) == 3 and parts[1] in ("msg", "action"):
        parts = [parts[0], parts[2]]
    if len(parts) != 2 or not all(p.isidentifier() for p in parts):
        raise UnknownTypeError(f"not an action type name: {name!r} (expected pkg/action/Name)")
    package, short = parts
    if short.endswith("Action") and len(short) > len("Action"):
        candidates = [short[: -len("Action")], short]
    else:
        candidates = [short]
    for cand in candidates:
        try:
            STORE.resolve(f"{package}/msg/{cand}ActionGoal")
        except UnknownTypeError:
            continue
        return _action(f"{package}/action/{cand}")
    raise UnknownTypeError(f"unknown action type {name!r}")


def service_typenames() -> list[str]:
    """Every service type known now (bundled packages included), sorted."""
    for package in _BUNDLED:
        _load_bundled(package + "/")
    suffix = "_Request"
    return sorted(
        t[: -len(suffix)]
        for t in STORE.typenames()
        if "/srv/" in t
        and t.endswith(suffix)
        and t[: -len(suffix)] + "_Response" in STORE.typestore.types
    )


def action_typenames() -> list[str]:
    """Every actionlib action type known now (bundled packages included), sorted."""
    for package in _BUNDLED:
        _load_bundled(package + "/")
    suffix = "ActionGoal"
    out = []
    for t in STORE.typenames():
        if t.endswith(suffix) and "/msg/" in t:
            base = t[: -len(suffix)]
            if base + "ActionResult" in STORE.typestore.types:
                pkg, _, short = base.split("/")
                out.append(f"{pkg}/action/{short}")
    return sorted(out)
