"""Helpers for the message tests: a generic filler and an independent deep comparison.

Both walk the rosbags typestore's own field definitions (not roverlab's layouts), so they
check :mod:`roverlab.msgs` against rosbags rather than against itself.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, get_typestore

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)

_DTYPES = {
    "bool": np.bool_,
    "byte": np.int8,
    "char": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}


def _scalar(base: str, rng: np.random.Generator) -> Any:
    """A random non-default value of a base type (never 0, '', False)."""
    if base == "bool":
        return True
    if base == "string":
        return "s" + "".join(rng.choice(list("abcxyz:/ _"), size=5))
    dtype = np.dtype(_DTYPES[base])
    if dtype.kind == "f":
        # values exactly representable in float32, so float32 round trips compare equal
        return float(np.float32(rng.uniform(0.5, 100.0)))
    info = np.iinfo(dtype)
    return int(rng.integers(1, min(int(info.max), 1000), endpoint=True))


def _array(base: str, count: int, rng: np.random.Generator) -> Any:
    if base == "string":
        return [_scalar(base, rng) for _ in range(count)]
    return np.array([_scalar(base, rng) for _ in range(count)], dtype=_DTYPES[base])


def fill(typename: str, rng: np.random.Generator) -> Any:
    """A message of ``typename`` with a non-default value in every leaf field.

    Sequences get 3 elements (at most their bound), fixed arrays their full length.
    """
    _consts, fields = TYPESTORE.fielddefs[typename]
    values: list[Any] = []
    for _name, desc in fields:
        node = desc[0]
        if node == Nodetype.BASE:
            values.append(_scalar(desc[1][0], rng))
        elif node == Nodetype.NAME:
            values.append(fill(desc[1], rng))
        else:
            (sub_node, sub), count = desc[1]
            if node == Nodetype.SEQUENCE:
                count = min(count, 3) if count else 3
            if sub_node == Nodetype.NAME:
                values.append([fill(sub, rng) for _ in range(count)])
            else:
                values.append(_array(sub[0], count, rng))
    return TYPESTORE.types[typename](*values)


def assert_same(a: Any, b: Any, path: str = "") -> None:
    """Assert two messages are equal field by field (numpy-aware), naming the first diff."""
    assert type(a).__msgtype__ == type(b).__msgtype__, path
    _consts, fields = TYPESTORE.fielddefs[type(a).__msgtype__]
    for name, desc in fields:
        x, y = getattr(a, name), getattr(b, name)
        where = f"{path}.{name}" if path else name
        node = desc[0]
        if node == Nodetype.NAME:
            assert_same(x, y, where)
        elif node == Nodetype.BASE:
            assert type(x) is type(y) or {type(x), type(y)} <= {int, float}, where
            assert x == y, where
        elif desc[1][0][0] == Nodetype.NAME:
            assert len(x) == len(y), where
            for i, (xi, yi) in enumerate(zip(x, y, strict=True)):
                assert_same(xi, yi, f"{where}[{i}]")
        elif desc[1][0][1][0] == "string":
            assert list(x) == list(y), where
        else:
            assert isinstance(x, np.ndarray) and isinstance(y, np.ndarray), where
            assert x.dtype == y.dtype, where
            np.testing.assert_array_equal(x, y, err_msg=where)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(1234)


@pytest.fixture
def filler(rng: np.random.Generator) -> Callable[[str], Any]:
    return lambda typename: fill(typename, rng)


@pytest.fixture
def same() -> Callable[[Any, Any], None]:
    return assert_same
