"""Field values: defaults, validation and coercion, and conversion to and from plain dicts.

Shared by the constructors (:mod:`.factory`), :func:`from_dict` and the YAML reader. Errors
name the field by its dotted path from the top message (``pose.position.x``, ``poses[2].pose``)
and start with a *label* for the top type: ``'Twist'`` for constructors, the full type name
for :func:`from_dict`.
"""

from __future__ import annotations

import difflib
import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Final

import numpy as np

from ._store import STORE, FieldKind, FieldSpec, TypeSpec
from .errors import FieldError, MessageValueError

__all__ = [
    "coerce_field",
    "default_makers",
    "default_message",
    "from_dict",
    "message_from_mapping",
    "messages_equal",
    "to_dict",
    "to_plain",
    "unknown_field",
]

_FLOAT_BASES: Final = frozenset({"float32", "float64", "float128"})
_INT_RANGES: Final[dict[str, tuple[int, int]]] = {
    base: (int(np.iinfo(dt).min), int(np.iinfo(dt).max))
    for base, dt in (
        ("byte", np.int8),
        ("char", np.uint8),
        ("int8", np.int8),
        ("uint8", np.uint8),
        ("int16", np.int16),
        ("uint16", np.uint16),
        ("int32", np.int32),
        ("uint32", np.uint32),
        ("int64", np.int64),
        ("uint64", np.uint64),
    )
}
_BYTES_LIKE: Final = (bytes, bytearray, memoryview)


def _join(prefix: str, name: str) -> str:
    return f"{prefix}.{name}" if prefix else name


def _describe(value: object) -> str:
    """Short description of a value for error messages: ``str 'abc'``, ``dict``, ``list``."""
    if isinstance(value, str):
        text = value if len(value) <= 20 else value[:17] + "..."
        return f"str {text!r}"
    if isinstance(value, bool | int | float):
        return f"{type(value).__name__} {value!r}"
    if isinstance(value, np.ndarray):
        return f"{value.dtype} array of shape {value.shape}"
    return type(value).__name__


def unknown_field(label: str, spec: TypeSpec, path: str, name: str) -> FieldError:
    """The :class:`FieldError` for field ``name`` (at dotted ``path``) missing from ``spec``."""
    close = difflib.get_close_matches(name, list(spec.by_name), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return FieldError(f"{label} has no field {path!r}{hint}")


def _bad_value(label: str, path: str, expected: str, value: object) -> MessageValueError:
    return MessageValueError(f"{label} field {path!r}: expected {expected}, got {_describe(value)}")


# ---------------------------------------------------------------------------------- defaults


_Maker = Callable[[], Any]
_MAKERS: dict[str, tuple[_Maker, tuple[_Maker, ...]]] = {}


def _constant(value: object) -> _Maker:
    return lambda: value


def _field_maker(field: FieldSpec) -> _Maker:
    kind = field.kind
    if kind is FieldKind.NUMBER:
        if field.default is not None:
            return _constant(field.default)
        if field.base == "bool":
            return _constant(False)
        return _constant(0.0 if field.base in _FLOAT_BASES else 0)
    if kind is FieldKind.STRING:
        return _constant("")
    if kind is FieldKind.NUMBERS:
        return functools.partial(np.zeros, field.length, field.dtype)
    length = field.length
    if kind is FieldKind.STRINGS:
        return lambda: [""] * length
    sub = default_makers(STORE.spec(field.typename))[0]
    if kind is FieldKind.MESSAGE:
        return sub
    return lambda: [sub() for _ in range(length)]


def default_makers(spec: TypeSpec) -> tuple[_Maker, tuple[_Maker, ...]]:
    """Cached makers of defaults for ``spec``: (whole message, one per field in order).

    Field defaults are 0, 0.0, False, '' (or the ``.msg`` default, e.g. Quaternion ``w`` =
    1.0), the nested message's defaults, an empty (sequence) or zero-filled (fixed array)
    numpy array, or a list of default strings / messages; every call makes fresh objects.
    """
    found = _MAKERS.get(spec.typename)
    if found is None:
        fields = tuple(_field_maker(f) for f in spec.fields)
        cls = spec.cls
        if all(f.kind in (FieldKind.NUMBER, FieldKind.STRING) for f in spec.fields):
            constants = tuple(make() for make in fields)

            def make_message() -> Any:
                return cls(*constants)

        else:

            def make_message() -> Any:
                return cls(*[make() for make in fields])

        found = (make_message, fields)
        _MAKERS[spec.typename] = found
    return found


def default_message(spec: TypeSpec) -> Any:
    """A new message of type ``spec`` with every field at its default."""
    return default_makers(spec)[0]()


# ---------------------------------------------------------------------------------- coercion


_BOOLS: Final = (bool, np.bool_)
_INTS: Final = (int, np.integer)
_REALS: Final = (int, float, np.integer, np.floating)


def _number(base: str, value: object, label: str, path: str) -> bool | int | float:
    kind = type(value)
    if base in _FLOAT_BASES:
        if kind is float:
            return value  # type: ignore[return-value]
        if kind is not bool and isinstance(value, _REALS) and not isinstance(value, np.bool_):
            return float(value)
        raise _bad_value(label, path, f"a number ({base})", value)
    if base == "bool":
        if isinstance(value, _BOOLS):
            return bool(value)
        raise _bad_value(label, path, "a bool", value)
    if kind is bool or not isinstance(value, _INTS):
        raise _bad_value(label, path, f"an integer ({base})", value)
    number = int(value)
    low, high = _INT_RANGES[base]
    if not low <= number <= high:
        raise MessageValueError(
            f"{label} field {path!r}: {number} is out of range for {base} [{low}, {high}]"
        )
    return number


def _check_length(field: FieldSpec, count: int, label: str, path: str) -> None:
    if field.length and count != field.length:
        raise MessageValueError(
            f"{label} field {path!r}: expected exactly {field.length} values, got {count}"
        )
    if field.bound and count > field.bound:
        raise MessageValueError(
            f"{label} field {path!r}: expected at most {field.bound} values, got {count}"
        )


_KIND_OK: Final[dict[str, frozenset[str]]] = {
    "b": frozenset("b"),
    "i": frozenset("iu"),
    "u": frozenset("iu"),
    "f": frozenset("iuf"),
}


def _numbers(field: FieldSpec, value: object, label: str, path: str) -> np.ndarray[Any, Any]:
    dtype = field.dtype
    assert dtype is not None
    if isinstance(value, np.ndarray):
        arr = value
        if arr.ndim != 1:
            raise _bad_value(label, path, f"a 1-D array of {field.base}", value)
        if arr.dtype != dtype:
            if arr.dtype.kind not in _KIND_OK.get(dtype.kind, ()):
                raise _bad_value(label, path, f"an array of {field.base}", value)
            if dtype.kind in "iu" and arr.size:
                low, high = _INT_RANGES[field.base]
                if int(arr.min()) < low or int(arr.max()) > high:
                    raise MessageValueError(
                        f"{label} field {path!r}: values out of range for {field.base}"
                    )
            arr = arr.astype(dtype)
        elif not arr.flags.c_contiguous:
            arr = np.ascontiguousarray(arr)
    elif isinstance(value, _BYTES_LIKE):
        if dtype.itemsize != 1 or dtype.kind not in "iu":
            raise _bad_value(label, path, f"a sequence of {field.base}", value)
        arr = np.frombuffer(value, dtype=dtype)
    elif isinstance(value, list | tuple):
        items = [_number(field.base, item, label, f"{path}[{i}]") for i, item in enumerate(value)]
        arr = np.array(items, dtype=dtype)
    else:
        raise _bad_value(label, path, f"a sequence of {field.base}", value)
    _check_length(field, len(arr), label, path)
    return arr


def _string(field: FieldSpec, value: object, label: str, path: str) -> str:
    if not isinstance(value, str):
        raise _bad_value(label, path, "a string", value)
    if field.string_bound and len(value) > field.string_bound:
        raise MessageValueError(
            f"{label} field {path!r}: string longer than {field.string_bound} characters"
        )
    return value


def _message(typename: str, value: object, label: str, path: str) -> Any:
    if isinstance(value, Mapping):
        return message_from_mapping(STORE.spec(typename), value, label, path)
    if getattr(type(value), "__msgtype__", None) == typename:
        return value
    raise _bad_value(label, path, f"a {typename} message or a mapping", value)


def coerce_field(field: FieldSpec, value: object, label: str, path: str) -> Any:
    """Validate ``value`` for ``field`` and convert it to the stored form.

    Numbers become Python numbers (range-checked), number sequences 1-D numpy arrays of the
    field's dtype (an array of the exact dtype is kept, not copied), nested mappings messages.

    Raises:
        FieldError: A nested mapping names a field the type does not have.
        MessageValueError: The value has the wrong kind, length or range.
    """
    kind = field.kind
    if kind is FieldKind.NUMBER:
        return _number(field.base, value, label, path)
    if kind is FieldKind.STRING:
        return _string(field, value, label, path)
    if kind is FieldKind.MESSAGE:
        return _message(field.typename, value, label, path)
    if kind is FieldKind.NUMBERS:
        return _numbers(field, value, label, path)
    if isinstance(value, (str, Mapping, *_BYTES_LIKE)) or not isinstance(
        value, (Sequence, np.ndarray)
    ):
        expected = "strings" if kind is FieldKind.STRINGS else f"{field.typename} messages"
        raise _bad_value(label, path, f"a sequence of {expected}", value)
    _check_length(field, len(value), label, path)
    if kind is FieldKind.STRINGS:
        return [_string(field, item, label, f"{path}[{i}]") for i, item in enumerate(value)]
    return [_message(field.typename, item, label, f"{path}[{i}]") for i, item in enumerate(value)]


def message_from_mapping(
    spec: TypeSpec, data: Mapping[Any, Any], label: str, path: str = ""
) -> Any:
    """Build a message of type ``spec`` from a mapping of ROS field names (strict).

    Raises:
        FieldError: A key is not a field of the type (named by its dotted path).
        MessageValueError: A value has the wrong kind.
    """
    for key in data:
        if not isinstance(key, str) or key not in spec.by_name:
            raise unknown_field(label, spec, _join(path, str(key)), str(key))
    makers = default_makers(spec)[1]
    values = [
        coerce_field(f, data[f.name], label, _join(path, f.name)) if f.name in data else make()
        for f, make in zip(spec.fields, makers, strict=True)
    ]
    return spec.cls(*values)


def from_dict(typename: object, data: Mapping[str, Any]) -> Any:
    """Build a message from a (nested) dict of ROS field names, with validation.

    Args:
        typename: Type name in any accepted form, rosbags class or factory.
        data: Field values; missing fields take defaults, nested messages are dicts,
            number sequences are lists or numpy arrays.

    Returns:
        The message (a rosbags dataclass instance).

    Raises:
        UnknownTypeError: Unknown type.
        FieldError: Unknown field, named by dotted path
            (``geometry_msgs/msg/Twist has no field 'linear.w'``).
        MessageValueError: Wrong kind of value (string for a float, dict for a number,
            out-of-range integer, wrong array length), named by dotted path.
    """
    spec = STORE.spec(typename)
    if not isinstance(data, Mapping):
        raise MessageValueError(f"{spec.typename}: expected a mapping, got {_describe(data)}")
    return message_from_mapping(spec, data, spec.typename)


# ------------------------------------------------------------------------------- to plain


def _short_float32(value: float) -> float:
    """The shortest decimal that reads back as the same float32 (0.1, not 0.100000001...)."""
    return float(str(np.float32(value)))


def to_plain(msg: Any, *, short_float32: bool = False) -> dict[str, Any]:
    """Convert a message to nested dicts, lists and Python scalars.

    Args:
        msg: The message.
        short_float32: Round float32 values to the shortest decimal that reads back as the
            same float32 (for display).

    Returns:
        A dict in field order.
    """
    spec = STORE.spec(msg)
    out: dict[str, Any] = {}
    for f in spec.by_name.values():
        value = getattr(msg, f.attr)
        kind = f.kind
        if kind is FieldKind.NUMBER:
            if isinstance(value, np.generic):
                value = value.item()
            if short_float32 and f.base == "float32":
                value = _short_float32(value)
            out[f.name] = value
        elif kind is FieldKind.STRING:
            out[f.name] = value
        elif kind is FieldKind.MESSAGE:
            out[f.name] = to_plain(value, short_float32=short_float32)
        elif kind is FieldKind.NUMBERS:
            if isinstance(value, _BYTES_LIKE):
                out[f.name] = list(bytes(value))
            elif short_float32 and f.base == "float32":
                out[f.name] = [float(str(x)) for x in np.asarray(value, dtype=np.float32)]
            else:
                out[f.name] = np.asarray(value).tolist()
        elif kind is FieldKind.STRINGS:
            out[f.name] = list(value)
        else:
            out[f.name] = [to_plain(item, short_float32=short_float32) for item in value]
    return out


def to_dict(msg: Any) -> dict[str, Any]:
    """Convert a message to nested dicts of ROS field names and plain Python values.

    numpy arrays become lists of Python numbers (uint8 data arrays lists of ints); nested
    messages become dicts. ``from_dict(type_name(msg), to_dict(msg))`` rebuilds the message.
    """
    return to_plain(msg)


# ---------------------------------------------------------------------------------- equality


def messages_equal(a: Any, b: Any) -> bool:
    """Whether two messages have the same type and equal field values, numpy-aware.

    Float arrays compare NaN equal to NaN; a numpy array equals a list with the same values.
    (The rosbags dataclasses' ``==`` fails on numpy array fields.)
    """
    if getattr(type(a), "__msgtype__", None) != getattr(type(b), "__msgtype__", 0):
        return False
    spec = STORE.spec(a)
    for f in spec.fields:
        x, y = getattr(a, f.attr), getattr(b, f.attr)
        kind = f.kind
        if kind is FieldKind.MESSAGE:
            if not messages_equal(x, y):
                return False
        elif kind is FieldKind.NUMBERS:
            xa, ya = np.asarray(x), np.asarray(y)
            if xa.shape != ya.shape:
                return False
            nan_ok = xa.dtype.kind == "f" and ya.dtype.kind == "f"
            if not np.array_equal(xa, ya, equal_nan=nan_ok):
                return False
        elif kind is FieldKind.MESSAGES:
            if len(x) != len(y) or not all(map(messages_equal, x, y)):
                return False
        elif kind is FieldKind.NUMBER and f.base in _FLOAT_BASES:
            if not (x == y or (x != x and y != y)):
                return False
        elif kind is FieldKind.STRINGS:
            if list(x) != list(y):
                return False
        elif x != y:
            return False
    return True
