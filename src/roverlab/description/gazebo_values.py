"""Typed reads of a ``<gazebo>`` element's children (the text of ``<plugin>``, ``<sensor>``
and ``<gazebo reference>`` children), shared by the parsers of :mod:`.gazebo` and the
plugin parsers in modules of their own (:mod:`.gazebo_planar`)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping

from roverlab.description.errors import URDFError
from roverlab.description.gazebo_specs import NOISE_TYPES

__all__ = ["ElementValues", "flatten_element"]


class ElementValues:
    """Typed reads of child-element text, errors naming ``where``."""

    def __init__(self, values: Mapping[str, str], where: str, model_name: str = "") -> None:
        self.values = values
        self.where = where
        self.model_name = model_name

    def fail(self, key: str, problem: str) -> URDFError:
        return URDFError(f"{self.where}: <{key}>: {problem}")

    def text(self, key: str, default: str) -> str:
        value = self.values.get(key)
        return default if value is None else value.strip()

    def noise_type(self, key: str) -> str:
        """A ``<noise><type>``: Gazebo's ``none``, ``gaussian`` or ``gaussian_quantized``
        (Gazebo prints an error and adds no noise for any other; roverlab refuses it)."""
        value = self.text(key, "none")
        if value not in NOISE_TYPES:
            raise self.fail(key, f"unknown noise type '{value}' (one of {', '.join(NOISE_TYPES)})")
        return value

    def number(self, key: str, default: float) -> float:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        try:
            value = float(raw)
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not a number") from None
        if not math.isfinite(value):
            raise self.fail(key, f"'{raw.strip()}' is not a finite number")
        return value

    def non_negative(self, key: str, default: float) -> float:
        value = self.number(key, default)
        if value < 0:
            raise self.fail(key, f"{value:g} must not be negative")
        return value

    def integer(self, key: str, default: int, *, minimum: int = 0) -> int:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        try:
            value = int(raw.strip())
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not an integer") from None
        if value < minimum:
            raise self.fail(key, f"{value} must be >= {minimum}")
        return value

    def flag(self, key: str, default: bool) -> bool:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        word = raw.strip().lower()
        if word in ("true", "1"):
            return True
        if word in ("false", "0"):
            return False
        raise self.fail(key, f"'{raw.strip()}' is not a boolean (true/false/1/0)")

    def vector(self, key: str, default: tuple[float, float, float]) -> tuple[float, float, float]:
        raw = self.values.get(key)
        if raw is None or not raw.strip():
            return default
        parts = raw.split()
        try:
            nums = [float(p) for p in parts]
        except ValueError:
            raise self.fail(key, f"'{raw.strip()}' is not 3 numbers") from None
        if len(nums) != 3 or not all(math.isfinite(v) for v in nums):
            raise self.fail(key, f"'{raw.strip()}' is not 3 finite numbers")
        return (nums[0], nums[1], nums[2])


def flatten_element(elem: ET.Element, prefix: str = "") -> dict[str, str]:
    """Child element texts by tag; nested elements as ``a/b`` (the first occurrence wins)."""
    out: dict[str, str] = {}
    for child in elem:
        if not isinstance(child.tag, str):
            continue
        key = prefix + child.tag
        if len(child):
            for k, v in flatten_element(child, key + "/").items():
                out.setdefault(k, v)
        else:
            out.setdefault(key, (child.text or "").strip())
    return out
