"""Typed parameter sets built from ROS parameter dictionaries.

Every planner, controller and costmap layer keeps its parameters in a frozen, keyword-only
dataclass whose fields carry the ROS names and defaults. :func:`build_params` makes one from
a ``<param>`` / ``rosparam`` mapping: numbers are converted as the ROS parameter server does
(an int for a double, an integral float for an int), a value of the wrong type or an
a value of the wrong type is a :class:`~roverlab.navigation.errors.NavigationParamsError`
naming it; an unknown name is a warning naming it (with a "did you mean" hint) and is
otherwise ignored, as ROS ignores a parameter no plugin reads; names a ROS package renamed
are taken under their new name with a warning, as ``nav_core::warnRenamedParameter`` does.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Mapping
from typing import Any, TypeVar

from roverlab.core.rosparams import unknown_warning
from roverlab.navigation.errors import NavigationParamsError

__all__ = [
    "ParamsResult",
    "build_params",
    "check",
    "flatten_ros",
    "is_number",
    "unknown_warning",
]

T = TypeVar("T")


def check(ok: bool, message: str) -> None:
    """Raise :class:`NavigationParamsError` with ``message`` unless ``ok``."""
    if not ok:
        raise NavigationParamsError(message)


def is_number(value: object) -> bool:
    """A finite int or float (bools excluded)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def flatten_ros(data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mappings become ``/``-joined names (``{a: {b: 1}}`` -> ``{'a/b': 1}``); a ``.``
    separator (ROS 2 YAML files) is read as ``/``. Lists stay values."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        name = prefix + str(key).strip("/").replace(".", "/")
        if isinstance(value, Mapping):
            out.update(flatten_ros(value, name + "/"))
        else:
            out[name] = value
    return out


def _coerce(where: str, name: str, annotation: str, value: Any) -> Any:
    kind = annotation.replace(" ", "")
    optional = kind.endswith("|None")
    if optional:
        kind = kind[: -len("|None")]
        if value is None:
            return None
    if kind == "bool":
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        raise NavigationParamsError(f"{where}: {name} must be true or false, got {value!r}")
    if kind == "int":
        if isinstance(value, float) and value.is_integer():
            return int(value)
        if isinstance(value, int) and not isinstance(value, bool):
            return value
        raise NavigationParamsError(f"{where}: {name} must be an integer, got {value!r}")
    if kind == "float":
        if is_number(value):
            return float(value)
        raise NavigationParamsError(f"{where}: {name} must be a finite number, got {value!r}")
    if kind == "str":
        if isinstance(value, str):
            return value
        raise NavigationParamsError(f"{where}: {name} must be a string, got {value!r}")
    return value  # structured values are checked by the dataclass itself


@dataclasses.dataclass(frozen=True, slots=True)
class ParamsResult:
    """What :func:`build_params` read besides the parameters: lines to log as warnings."""

    warnings: tuple[str, ...] = ()


def build_params(
    cls: type[T],
    values: Mapping[str, Any],
    *,
    where: str,
    renamed: Mapping[str, str] | None = None,
    ignored: Iterable[str] = (),
    extra: Mapping[str, Any] | None = None,
) -> tuple[T, ParamsResult]:
    """An instance of dataclass ``cls`` from a ROS parameter mapping.

    Args:
        cls: a dataclass whose field names are the ROS parameter names.
        values: ``{name: value}`` (ROS names).
        where: the package or plugin name used in messages (``dwa_local_planner``).
        renamed: ``{old_name: new_name}``; an old name is used when the new one is not
            given (a warning is returned either way).
        ignored: ROS names roverlab accepts but does not implement (a warning each).
        extra: keyword values set by the caller (not user parameters).

    Returns:
        The instance and the warnings.

    Raises:
        NavigationParamsError: a value of the wrong type or range (an unknown name is a
            warning).
    """
    fields = {f.name: f for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    renamed = dict(renamed or {})
    ignored_set = set(ignored)
    warnings: list[str] = []
    kwargs: dict[str, Any] = dict(extra or {})
    for old, new in renamed.items():
        if old in values:
            if new in values:
                warnings.append(
                    f"{where}: parameter {old} is deprecated and {new} is set: {old} ignored"
                )
            else:
                warnings.append(f"{where}: parameter {old} has been renamed to {new}")
    for key, value in values.items():
        name = renamed.get(key, key)
        if key in renamed and renamed[key] in values:
            continue
        if key in ignored_set:
            warnings.append(f"{where}: parameter {key} is not implemented by roverlab (ignored)")
            continue
        field = fields.get(name)
        if field is None or not field.init:
            known = [f for f, fd in fields.items() if fd.init] + list(renamed)
            warnings.append(unknown_warning(where, key, known))
            continue
        kwargs[name] = _coerce(where, key, str(field.type), value)
    try:
        return cls(**kwargs), ParamsResult(tuple(warnings))
    except TypeError as err:  # a structured value of the wrong shape
        raise NavigationParamsError(f"{where}: {err}") from err
