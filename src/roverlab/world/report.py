"""World and robot warnings as a user reads them: grouped, each group one line.

The loaders record one line per element they skip or change. Printed one by one, fifty
``model Dumpster_12 skipped: model://dumpster not found`` lines bury the one that matters,
so :func:`group_warnings` folds lines that differ only in the element they name::

    3 models skipped: Dumpster, Dumpster_0, Dumpster_1 -- model://dumpster not found; put
    Gazebo's models on GAZEBO_MODEL_PATH (looked in: ...)

Lines with nothing to fold with stay as they are.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["group_warnings", "world_warnings"]

_MISSING_MODEL = re.compile(
    r"^(?P<where>.*?): model (?P<name>.+?) skipped: (?P<uri>\S+) not found$"
)
_MISSING_MESH = re.compile(
    r"^(?P<where>.*?): (?P<label>.*?): mesh (?P<uri>\S+) not found: skipped$"
)


def _names(items: Sequence[str], limit: int = 8) -> str:
    shown = ", ".join(items[:limit])
    return shown + (f" and {len(items) - limit} more" if len(items) > limit else "")


def group_warnings(lines: Iterable[str], search: Sequence[Path] = ()) -> list[str]:
    """Fold a loader's warnings (see the module docstring); order of first appearance."""
    groups: dict[tuple[str, str], list[str]] = {}
    order: list[tuple[str, str] | str] = []
    for line in lines:
        m = _MISSING_MODEL.match(line)
        key: tuple[str, str] | None = None
        item = ""
        if m:
            key, item = ("model", m["uri"]), m["name"]
        else:
            m = _MISSING_MESH.match(line)
            if m:
                key, item = ("mesh", m["uri"]), m["label"]
        if key is None:
            order.append(line)
            continue
        if key not in groups:
            groups[key] = []
            order.append(key)
        groups[key].append(item)
    looked = f" (looked in: {', '.join(str(p) for p in search)})" if search else ""
    out: list[str] = []
    for entry in order:
        if isinstance(entry, str):
            out.append(entry)
            continue
        kind, uri = entry
        items = list(dict.fromkeys(groups[entry]))
        if kind == "model":
            noun = "model" if len(items) == 1 else "models"
            out.append(
                f"{len(items)} {noun} skipped: {_names(items)} — {uri} not found; put Gazebo's "
                f"models on GAZEBO_MODEL_PATH or ROVERLAB_MODEL_PATH{looked}"
            )
        else:
            noun = "collision" if len(items) == 1 else "collisions"
            out.append(f"{len(items)} mesh {noun} skipped: {_names(items)} — {uri} not found")
    return out


def world_warnings(world: object) -> list[str]:
    """A loaded world's warnings, grouped, with the model search path of its file."""
    from roverlab.world.sdf import model_search_path

    lines = list(getattr(world, "warnings", ()))
    source = getattr(world, "source", None)
    search = model_search_path((), Path(source).resolve().parent) if source else []
    return group_warnings(lines, search)
