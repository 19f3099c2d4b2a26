"""The house rules: every import inside roverlab points down the layers below, so no two
packages import each other and a new upward import fails here, naming the file."""

from __future__ import annotations

import ast
import functools
from collections import defaultdict
from pathlib import Path

import roverlab

SRC = Path(roverlab.__file__).resolve().parent

#: Lowest first. A package imports only packages of lower layers (or of its own layer, as
#: long as that makes no cycle). The algorithms under localization/, navigation/,
#: perception/ and slam/ know nothing of launch files, the dashboard or the command line.
LAYERS: list[tuple[str, ...]] = [
    ("errors", "fileio", "geometry", "raycast", "charts", "packages"),
    ("msgs",),
    ("core", "world"),
    ("tf", "actionlib", "batch"),
    ("description", "maps", "perception"),
    ("drivers", "sim", "slam", "navigation", "ros1", "teleop"),
    ("localization", "viz", "bag"),
    ("foxglove",),
    ("launch",),
    ("autonomy", "navbench"),
    ("cli",),
]
LAYER = {pkg: i for i, names in enumerate(LAYERS) for pkg in names}


def _package_of(path: Path) -> str:
    rel = path.relative_to(SRC).parts
    return rel[0] if len(rel) > 1 else rel[0].removesuffix(".py")


@functools.cache
def _imports() -> dict[str, dict[str, list[str]]]:
    """package -> imported package -> files (relative to src/roverlab) importing it."""
    out: dict[str, dict[str, list[str]]] = defaultdict(lambda: defaultdict(list))
    for path in sorted(SRC.rglob("*.py")):
        pkg = _package_of(path)
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            elif isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            else:
                continue
            for name in names:
                parts = name.split(".")
                if parts[0] == "roverlab" and len(parts) > 1 and parts[1] != pkg:
                    out[pkg][parts[1]].append(str(path.relative_to(SRC)))
    return out


def test_every_package_has_a_layer() -> None:
    packages = {_package_of(p) for p in SRC.rglob("*.py")} - {"__init__"}
    assert packages - set(LAYER) == set(), "add the new package to LAYERS"


def test_imports_point_down() -> None:
    upward = [
        f"{files[0]} imports roverlab.{dep} (layer {LAYER[dep]}) from layer {LAYER[pkg]}"
        for pkg, deps in _imports().items()
        for dep, files in deps.items()
        if dep in LAYER and LAYER[dep] > LAYER[pkg]
    ]
    assert upward == []


def test_no_two_packages_import_each_other() -> None:
    graph = {pkg: set(deps) for pkg, deps in _imports().items()}
    cycles = []
    for pkg, deps in graph.items():
        # everything reachable from pkg's imports; pkg among it is a cycle
        seen, todo = set(), list(deps)
        while todo:
            d = todo.pop()
            if d not in seen:
                seen.add(d)
                todo.extend(graph.get(d, ()))
        if pkg in seen:
            cycles.append(pkg)
    assert cycles == []
