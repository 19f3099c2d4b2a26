"""Typed node parameters, as rclpy's: declared with a default, validated on every set.

Parameter files are the ROS 2 YAML layout::

    slam_gmapping:            # node name (or /** for every node)
      ros__parameters:
        particles: 30
        maxUrange: 4.5

A flat mapping (the ROS 1 ``rosparam load`` layout) is accepted too when the file is
loaded for one node.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

import yaml

from roverlab.core.errors import ParameterError

__all__ = [
    "Parameter",
    "ParameterDescriptor",
    "ParameterType",
    "SetParametersResult",
    "flatten_parameters",
    "load_parameter_file",
    "parameters_for_node",
]


class ParameterType(Enum):
    """The ROS 2 parameter types (rcl_interfaces/ParameterType)."""

    NOT_SET = 0
    BOOL = 1
    INTEGER = 2
    DOUBLE = 3
    STRING = 4
    BYTE_ARRAY = 5
    BOOL_ARRAY = 6
    INTEGER_ARRAY = 7
    DOUBLE_ARRAY = 8
    STRING_ARRAY = 9

    @staticmethod
    def of(value: Any) -> ParameterType:
        """Infer the type of a Python value; raises ParameterError if none fits."""
        if value is None:
            return ParameterType.NOT_SET
        if isinstance(value, bool):
            return ParameterType.BOOL
        if isinstance(value, int):
            return ParameterType.INTEGER
        if isinstance(value, float):
            return ParameterType.DOUBLE
        if isinstance(value, str):
            return ParameterType.STRING
        if isinstance(value, bytes | bytearray):
            return ParameterType.BYTE_ARRAY
        if isinstance(value, list | tuple):
            if all(isinstance(v, bool) for v in value):
                return ParameterType.BOOL_ARRAY if value else ParameterType.DOUBLE_ARRAY
            if all(isinstance(v, int) and not isinstance(v, bool) for v in value):
                return ParameterType.INTEGER_ARRAY
            if all(isinstance(v, int | float) and not isinstance(v, bool) for v in value):
                return ParameterType.DOUBLE_ARRAY
            if all(isinstance(v, str) for v in value):
                return ParameterType.STRING_ARRAY
        raise ParameterError(f"value {value!r} has no ROS parameter type")


_NAMES = {
    ParameterType.BOOL: "bool",
    ParameterType.INTEGER: "integer",
    ParameterType.DOUBLE: "double",
    ParameterType.STRING: "string",
    ParameterType.BYTE_ARRAY: "byte array",
    ParameterType.BOOL_ARRAY: "bool array",
    ParameterType.INTEGER_ARRAY: "integer array",
    ParameterType.DOUBLE_ARRAY: "double array",
    ParameterType.STRING_ARRAY: "string array",
    ParameterType.NOT_SET: "not set",
}


def coerce(name: str, ptype: ParameterType, value: Any) -> Any:
    """Convert ``value`` to parameter type ``ptype`` or raise ParameterError.

    Unlike ROS 2 (which rejects ``1`` for a double parameter), an integer is accepted for a
    double and converted, as ROS 1 did: launch files write ``value="5"`` for doubles.
    Strings from launch files (``value="0.05"``) are parsed as YAML scalars first.
    """
    if isinstance(value, str) and ptype not in (ParameterType.STRING, ParameterType.NOT_SET):
        with contextlib.suppress(yaml.YAMLError):
            value = yaml.safe_load(value)
    if ptype is ParameterType.NOT_SET:
        return value
    vt = ParameterType.of(value)
    if vt is ptype:
        if ptype is ParameterType.DOUBLE:
            return float(value)
        return list(value) if isinstance(value, tuple) else value
    if ptype is ParameterType.DOUBLE and vt is ParameterType.INTEGER:
        return float(value)
    if ptype is ParameterType.DOUBLE_ARRAY and vt is ParameterType.INTEGER_ARRAY:
        return [float(v) for v in value]
    if (
        ptype in (ParameterType.INTEGER_ARRAY, ParameterType.BOOL_ARRAY, ParameterType.STRING_ARRAY)
        and isinstance(value, list | tuple)
        and not value
    ):
        return []
    raise ParameterError(
        f"parameter '{name}' is of type {_NAMES[ptype]}, cannot set it to {value!r} "
        f"({_NAMES.get(vt, type(value).__name__)})"
    )


@dataclass(frozen=True, slots=True)
class ParameterDescriptor:
    """What a declaration says about a parameter (rcl_interfaces/ParameterDescriptor)."""

    description: str = ""
    read_only: bool = False
    min_value: float | None = None
    max_value: float | None = None
    choices: tuple[Any, ...] = ()


@dataclass(slots=True)
class Parameter:
    """A declared parameter: name, type fixed at declaration, current value."""

    name: str
    type: ParameterType
    value: Any
    descriptor: ParameterDescriptor = field(default_factory=ParameterDescriptor)

    def validate(self, value: Any) -> Any:
        v = coerce(self.name, self.type, value)
        d = self.descriptor
        if d.min_value is not None and v < d.min_value:
            raise ParameterError(
                f"parameter '{self.name}' = {v} is below its minimum {d.min_value}"
            )
        if d.max_value is not None and v > d.max_value:
            raise ParameterError(
                f"parameter '{self.name}' = {v} is above its maximum {d.max_value}"
            )
        if d.choices and v not in d.choices:
            raise ParameterError(
                f"parameter '{self.name}' = {v!r} is not one of {', '.join(map(repr, d.choices))}"
            )
        return v


@dataclass(frozen=True, slots=True)
class SetParametersResult:
    successful: bool
    reason: str = ""


SetCallback = Callable[[list[Parameter]], SetParametersResult]


def flatten_parameters(data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mappings become dotted names (``{a: {b: 1}}`` -> ``{'a.b': 1}``), as ROS 2."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten_parameters(value, name + "."))
        else:
            out[name] = value
    return out


def load_parameter_file(path: str | Path) -> dict[str, dict[str, Any]]:
    """Read a ROS 2 parameter YAML file: ``{node_name: {param: value}}`` (names flattened).

    Node keys are normalised without a leading slash; ``/**`` stays as the wildcard key.
    A file without ``ros__parameters`` sections is returned as ``{'': flat_params}``, the
    ROS 1 layout, to be applied to whichever node loads it.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as err:
        raise ParameterError(f"{p}: cannot read parameter file: {err.strerror}") from err
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise ParameterError(f"{p}: malformed YAML{where}: {problem}") from err
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ParameterError(f"{p}: a parameter file must be a mapping, got {type(data).__name__}")
    result: dict[str, dict[str, Any]] = {}
    ros2 = False
    for key, value in data.items():
        if isinstance(value, dict) and "ros__parameters" in value:
            ros2 = True
            params = value["ros__parameters"] or {}
            if not isinstance(params, dict):
                raise ParameterError(f"{p}: 'ros__parameters' of '{key}' must be a mapping")
            node = str(key) if str(key) == "/**" else str(key).lstrip("/")
            result.setdefault(node, {}).update(flatten_parameters(params))
    if not ros2:
        result[""] = flatten_parameters(data)
    return result


def parameters_for_node(
    files: Mapping[str, dict[str, Any]], node_name: str, namespace: str = "/"
) -> dict[str, Any]:
    """Pick from a loaded file the parameters meant for one node (wildcard first)."""
    full = (namespace.rstrip("/") + "/" + node_name).lstrip("/")
    out: dict[str, Any] = {}
    for key in ("", "/**", node_name, full):
        if key in files:
            out.update(files[key])
    return out
