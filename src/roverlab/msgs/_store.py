"""The type store behind :mod:`roverlab.msgs`: type names and per-type field layouts.

One :class:`MessageStore` wraps the rosbags ``ROS2_JAZZY`` typestore (immutable data) and
caches, per type, a :class:`TypeSpec` describing its fields in a form the constructors,
converters and serialisers can walk quickly.
"""

from __future__ import annotations

import difflib
import keyword
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any, Final

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from .errors import UnknownTypeError

__all__ = [
    "INTERFACE_KINDS",
    "STORE",
    "FieldKind",
    "FieldSpec",
    "MessageStore",
    "TypeSpec",
    "normalize_type_name",
]

#: Numeric base types and the numpy dtype rosbags uses for arrays of them.
#: (rosbags maps ``byte`` to int8 and ``char`` to uint8, for scalars and arrays alike.)
NUMERIC_DTYPES: Final[dict[str, np.dtype[Any]]] = {
    "bool": np.dtype(np.bool_),
    "byte": np.dtype(np.int8),
    "char": np.dtype(np.uint8),
    "int8": np.dtype(np.int8),
    "uint8": np.dtype(np.uint8),
    "int16": np.dtype(np.int16),
    "uint16": np.dtype(np.uint16),
    "int32": np.dtype(np.int32),
    "uint32": np.dtype(np.uint32),
    "int64": np.dtype(np.int64),
    "uint64": np.dtype(np.uint64),
    "float32": np.dtype(np.float32),
    "float64": np.dtype(np.float64),
    "float128": np.dtype(np.longdouble),
}

#: Non-zero default values declared in the ROS 2 ``.msg`` files of the store's types
#: (rosbags keeps no defaults). ``geometry_msgs/Quaternion`` defaults to the identity.
ROS2_FIELD_DEFAULTS: Final[dict[str, dict[str, float]]] = {
    "geometry_msgs/msg/Quaternion": {"w": 1.0},
}

#: The field ROS 2 adds to empty structures (``std_msgs/Empty``); hidden from users.
PLACEHOLDER_FIELD: Final = "structure_needs_at_least_one_member"


class FieldKind(Enum):
    """How a field is stored on the rosbags dataclass."""

    NUMBER = "number"  #: bool, integer or float scalar -> Python bool / int / float
    STRING = "string"  #: str
    MESSAGE = "message"  #: nested message instance
    NUMBERS = "numbers"  #: fixed array or sequence of numbers -> 1-D numpy array
    STRINGS = "strings"  #: fixed array or sequence of strings -> list[str]
    MESSAGES = "messages"  #: fixed array or sequence of messages -> list[msg]


@dataclass(frozen=True, slots=True)
class FieldSpec:
    """One field of a message type.

    Attributes:
        name: ROS field name (the key in dicts and YAML).
        attr: Attribute name on the rosbags dataclass (``name`` + ``_`` for Python keywords).
        kind: Storage kind.
        base: Base type (``float64``, ``string``, ...) for number/string kinds, else ``''``.
        typename: Nested message type for message kinds, else ``''``.
        dtype: numpy dtype for number kinds, else ``None``.
        length: Length of a fixed-size array, 0 otherwise.
        bound: Upper bound of a bounded sequence, 0 if unbounded.
        string_bound: Upper bound of a bounded string (or of each string of an array).
        default: Non-zero default declared in the ``.msg`` file, for number fields.
    """

    name: str
    attr: str
    kind: FieldKind
    base: str = ""
    typename: str = ""
    dtype: np.dtype[Any] | None = None
    length: int = 0
    bound: int = 0
    string_bound: int = 0
    default: float | None = None

    @property
    def is_array(self) -> bool:
        """Whether the field holds several values (fixed array or sequence)."""
        return self.kind in (FieldKind.NUMBERS, FieldKind.STRINGS, FieldKind.MESSAGES)

    def describe(self) -> str:
        """ROS-style type of the field, e.g. ``float64[36]`` or ``geometry_msgs/msg/Pose[]``."""
        elem = self.typename or self.base
        if not self.is_array:
            return elem
        if self.length:
            return f"{elem}[{self.length}]"
        return f"{elem}[<={self.bound}]" if self.bound else f"{elem}[]"


@dataclass(frozen=True, slots=True)
class TypeSpec:
    """Field layout of one message type.

    Attributes:
        typename: Full ROS 2 name, ``pkg/msg/Name``.
        short: Short name, ``Name``.
        cls: The rosbags dataclass.
        fields: Fields in definition order (including the placeholder of empty messages).
        by_name: Fields by ROS name, without the placeholder.
        constants: Constants of the type by name.
    """

    typename: str
    short: str
    cls: type[Any]
    fields: tuple[FieldSpec, ...]
    by_name: dict[str, FieldSpec] = field(repr=False)
    constants: dict[str, Any] = field(repr=False)

    @property
    def visible_fields(self) -> tuple[FieldSpec, ...]:
        """Fields a user sees (the placeholder of empty messages left out)."""
        return tuple(self.by_name.values())


#: The middle part of a full type name: messages, and the request/response messages of
#: services (``std_srvs/srv/Empty_Request``).
INTERFACE_KINDS: Final = ("msg", "srv", "action")


def normalize_type_name(name: str) -> str:
    """Normalise a message type name to the ROS 2 form ``pkg/msg/Name``.

    Accepts ``geometry_msgs/msg/Twist``, the ROS 1 form ``geometry_msgs/Twist`` and the
    Python module form ``geometry_msgs.msg.Twist``; also the message types of services
    (``std_srvs/srv/Empty_Request``). The type need not exist.

    Args:
        name: Type name in any accepted form.

    Returns:
        The ``pkg/msg/Name`` form.

    Raises:
        UnknownTypeError: ``name`` is not shaped like a message type name.
    """
    text = name.strip()
    parts = text.replace(".", "/").split("/") if "/" not in text else text.split("/")
    if len(parts) == 2:
        parts = [parts[0], "msg", parts[1]]
    if (
        len(parts) != 3
        or parts[1] not in INTERFACE_KINDS
        or not all(p.isidentifier() for p in parts)
    ):
        raise UnknownTypeError(
            f"not a message type name: {name!r} (expected pkg/msg/Name){STORE.suggest(text)}"
        )
    return "/".join(parts)


def _field_spec(name: str, desc: Any, defaults: dict[str, float]) -> FieldSpec:
    attr = f"{name}_" if keyword.iskeyword(name) else name
    node = desc[0]
    if node == Nodetype.BASE:
        base, bound = desc[1]
        if base == "string":
            return FieldSpec(name, attr, FieldKind.STRING, base=base, string_bound=bound)
        return FieldSpec(
            name,
            attr,
            FieldKind.NUMBER,
            base=base,
            dtype=NUMERIC_DTYPES[base],
            default=defaults.get(name),
        )
    if node == Nodetype.NAME:
        return FieldSpec(name, attr, FieldKind.MESSAGE, typename=desc[1])
    (sub_node, sub), count = desc[1]
    length, bound = (count, 0) if node == Nodetype.ARRAY else (0, count)
    if sub_node == Nodetype.NAME:
        return FieldSpec(name, attr, FieldKind.MESSAGES, typename=sub, length=length, bound=bound)
    base, string_bound = sub
    if base == "string":
        return FieldSpec(
            name,
            attr,
            FieldKind.STRINGS,
            base=base,
            length=length,
            bound=bound,
            string_bound=string_bound,
        )
    return FieldSpec(
        name,
        attr,
        FieldKind.NUMBERS,
        base=base,
        dtype=NUMERIC_DTYPES[base],
        length=length,
        bound=bound,
    )


class MessageStore:
    """Type names and field layouts of one rosbags typestore, cached per type.

    Args:
        typestore: The rosbags typestore to wrap.
    """

    def __init__(self, typestore: Typestore) -> None:
        self.typestore: Final = typestore
        self._canonical: dict[str, str] = {}
        self._specs: dict[str, TypeSpec] = {}
        self._short_index: dict[str, list[str]] = {}
        self._sources: list[Callable[[str], bool]] = []
        self._lock = threading.RLock()
        for full in typestore.types:
            self._index(full)

    def _index(self, full: str) -> None:
        self._short_index.setdefault(full.rsplit("/", 1)[-1].lower(), []).append(full)

    def register(self, typedefs: Mapping[str, Any]) -> list[str]:
        """Add type definitions (rosbags ``Typesdict``) to the store.

        A type already in the store with the same definition is left alone; a different
        definition under a known name is an error (messages on the wire would not match).

        Returns:
            The names that were new.

        Raises:
            UnknownTypeError: A name clashes with a different existing definition, or a
                field refers to a type that is neither known nor in ``typedefs``.
        """
        with self._lock:
            fielddefs = self.typestore.fielddefs
            new = {k: v for k, v in typedefs.items() if k not in fielddefs}
            for name, definition in typedefs.items():
                if name in fielddefs and fielddefs[name] != definition:
                    raise UnknownTypeError(
                        f"type {name} is already defined differently; cannot register it again"
                    )
            if not new:
                return []
            for name, (_consts, fields) in new.items():
                for fname, desc in fields:
                    ref = _referenced_type(desc)
                    if ref is None or ref in new or ref in fielddefs:
                        continue
                    if not self._try_sources(ref):
                        raise UnknownTypeError(
                            f"type {name}: field {fname!r} refers to unknown type {ref}"
                        )
            try:
                self.typestore.register(new)
            except Exception as err:  # rosbags raises its own TypesysError kinds
                raise UnknownTypeError(f"cannot register {', '.join(sorted(new))}: {err}") from err
            for name in new:
                self._index(name)
            return sorted(new)

    def add_type_source(self, source: Callable[[str], bool]) -> None:
        """Consult ``source(full_name)`` when a type is not in the store; it returns True
        after registering types (lazy loading of interface packages)."""
        self._sources.append(source)

    def _try_sources(self, full: str) -> bool:
        return any(source(full) for source in list(self._sources)) and (
            full in self.typestore.types
        )

    def typenames(self) -> list[str]:
        """All type names of the store, sorted."""
        return sorted(self.typestore.types)

    def suggest(self, name: str) -> str:
        """A `` (did you mean X?)`` suffix for an unknown type ``name``, or ``''``."""
        known = self.typenames()
        short = short_name_of(name)
        parts = name.strip().replace(".", "/").split("/")
        probe = "/".join([parts[0], "msg", parts[1]]) if len(parts) == 2 else "/".join(parts)
        candidates = difflib.get_close_matches(probe, known, n=1, cutoff=0.6)
        if not candidates:
            candidates = self._short_index.get(short.lower(), [])[:1]
        if not candidates:
            close = difflib.get_close_matches(short.lower(), list(self._short_index), n=1)
            candidates = self._short_index[close[0]][:1] if close else []
        return f" (did you mean {candidates[0]}?)" if candidates else ""

    def resolve(self, ref: object) -> str:
        """Canonical ``pkg/msg/Name`` of a type given by name, class, factory or message.

        Raises:
            UnknownTypeError: The type is not in the store.
        """
        key = _key(ref)
        found = self._canonical.get(key)
        if found is not None:
            return found
        full = normalize_type_name(key)
        if full not in self.typestore.types and not self._try_sources(full):
            raise UnknownTypeError(f"unknown message type {key!r}{self.suggest(key)}")
        self._canonical[key] = full
        return full

    def has(self, name: str) -> bool:
        """Whether a type of that name is known (or can be loaded from a type source)."""
        try:
            self.resolve(name)
        except UnknownTypeError:
            return False
        return True

    def spec(self, ref: object) -> TypeSpec:
        """Field layout of a type given by name, class, factory or message.

        Raises:
            UnknownTypeError: The type is not in the store.
        """
        key = _key(ref)
        found = self._specs.get(key)
        if found is not None:
            return found
        full = self.resolve(key)
        spec = self._specs.get(full)
        if spec is None:
            spec = self._build_spec(full)
            self._specs[full] = spec
        self._specs[key] = spec
        return spec

    def _build_spec(self, full: str) -> TypeSpec:
        consts, fielddefs = self.typestore.fielddefs[full]
        defaults = ROS2_FIELD_DEFAULTS.get(full, {})
        fields = tuple(_field_spec(name, desc, defaults) for name, desc in fielddefs)
        return TypeSpec(
            typename=full,
            short=full.rsplit("/", 1)[-1],
            cls=self.typestore.types[full],
            fields=fields,
            by_name={f.name: f for f in fields if f.name != PLACEHOLDER_FIELD},
            constants={name: value for name, _typ, value in consts},
        )


def _referenced_type(desc: Any) -> str | None:
    """The message type a rosbags field description refers to, or None for base types."""
    node = desc[0]
    if node == Nodetype.NAME:
        return str(desc[1])
    if node in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        sub_node, sub = desc[1][0]
        if sub_node == Nodetype.NAME:
            return str(sub)
    return None


def _key(ref: object) -> str:
    if type(ref) is str:
        return ref
    msgtype = getattr(ref, "__msgtype__", None)
    if not isinstance(msgtype, str):
        raise UnknownTypeError(f"not a message type or type name: {ref!r}")
    return msgtype


def short_name_of(name: str) -> str:
    """``Twist`` of ``geometry_msgs/msg/Twist`` (or of any accepted form)."""
    return name.replace(".", "/").rsplit("/", 1)[-1]


#: The one store of roverlab: ROS 2 Jazzy message definitions.
STORE: Final = MessageStore(get_typestore(Stores.ROS2_JAZZY))
