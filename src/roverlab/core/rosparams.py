"""Parameter dataclasses named after a ROS package's ``<param>`` names (amcl, slam_gmapping).

A :class:`FieldKinds` says which fields of such a dataclass hold integers, booleans, strings
or may be ``None`` (the rest are numbers). It converts a launch file's values the way the
ROS parameter server hands them to the C++ node (an int for a double, an integral float for
an int) and checks each field's type, naming the field in the error.

:func:`unknown_warning` is the one line every tolerant parameter reader (amcl, move_base,
the costmaps and planners) gives for a name nothing reads: ROS ignores such a parameter.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["FieldKinds", "unknown_warning"]


def unknown_warning(where: str, key: str, known: Iterable[str]) -> str:
    """The warning for a parameter nothing reads: its name, a "did you mean" hint, and
    that it is ignored (ROS ignores parameters no plugin reads)."""
    near = difflib.get_close_matches(key, list(known), n=1)
    hint = f" (did you mean {near[0]}?)" if near else ""
    return f"{where}: unknown parameter {key!r}{hint} is ignored"


@dataclass(frozen=True, slots=True)
class FieldKinds:
    """The non-number fields of a ROS parameter dataclass.

    Attributes:
        ints: integer fields (an integral float is taken as an int).
        bools: boolean fields.
        strs: non-empty string fields.
        optional: number fields that may be ``None``.
    """

    ints: frozenset[str] = frozenset()
    bools: frozenset[str] = frozenset()
    strs: frozenset[str] = frozenset()
    optional: frozenset[str] = frozenset()

    def kwargs(
        self,
        params: Mapping[str, Any],
        names: Collection[str],
        *,
        ignored: Collection[str],
        unknown: Callable[[str], Exception | None],
    ) -> dict[str, Any]:
        """Keyword arguments for the dataclass from ROS-named ``params``.

        Names in ``ignored`` are dropped; for a name not in ``names``, ``unknown(name)`` is
        raised, or the name dropped when it returns None (a reader that warns instead);
        an integral float becomes an int for an integer field and an int a float for a
        number field; booleans, strings and anything else pass as they are (the dataclass
        checks them with :meth:`check`).
        """
        kwargs: dict[str, Any] = {}
        for key, value in params.items():
            if key in ignored:
                continue
            if key not in names:
                err = unknown(key)
                if err is not None:
                    raise err
                continue
            if isinstance(value, bool) or key in self.strs or key in self.bools:
                kwargs[key] = value
            elif key in self.ints and isinstance(value, float) and value.is_integer():
                kwargs[key] = int(value)
            elif key not in self.ints and isinstance(value, int):
                kwargs[key] = float(value)
            else:
                kwargs[key] = value
        return kwargs

    def check(self, params: object, error: Callable[[str], Exception]) -> None:
        """Raise ``error(message)`` for the first field of dataclass ``params`` whose value
        has the wrong type (``"particles must be an int, got 2.5"``)."""
        for f in dataclasses.fields(params):  # type: ignore[arg-type]
            message = self._type_error(f.name, getattr(params, f.name))
            if message:
                raise error(message)

    def _type_error(self, name: str, value: object) -> str:
        if name in self.strs:
            if not isinstance(value, str) or not value:
                return f"{name} must be a non-empty string, got {value!r}"
            return ""
        if value is None and name in self.optional:
            return ""
        if name in self.bools:
            if not isinstance(value, bool):
                return f"{name} must be true or false, got {value!r}"
            return ""
        if name in self.ints:
            if isinstance(value, bool) or not isinstance(value, int):
                return f"{name} must be an int, got {value!r}"
            return ""
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"{name} must be a number, got {value!r}"
        if not math.isfinite(value):
            return f"{name} must be finite, got {value!r}"
        return ""
