"""``load_world``: one entry point for bundled worlds, SDF, YAML worlds and map images."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from roverlab.world.errors import WorldError
from roverlab.world.image_world import is_map_yaml, load_image_world
from roverlab.world.model import World
from roverlab.world.sdf import load_sdf
from roverlab.world.yaml_world import read_yaml, world_from_dict

__all__ = ["BUNDLED_WORLDS", "BUNDLED_WORLDS_DIR", "bundled_world_path", "load_world"]

BUNDLED_WORLDS_DIR = Path(__file__).resolve().parent / "bundled"

#: Bundled worlds and what they hold; every one spawns robots at (0, 0, 0).
BUNDLED_WORLDS: dict[str, str] = {
    "empty": "ground plane only",
    "maze": "8 m x 8 m Building Editor maze, 1.45 m corridors, spawn in the centre cell",
    "maze_faces": "the maze with three face posters (face_detector), one 2.3 m north of the spawn",
    "office": "12 m x 8 m office: reception, three rooms, desks, pillars, a face poster",
    "house": "10 m x 8 m house: living room, kitchen, bedroom, bathroom, furniture",
    "warehouse": "14 m x 9 m warehouse: pallet racks and aisles, loading area, site office",
    "apartment": "11 m x 9.5 m apartment: five rooms, a hallway, doors 0.8 to 1.6 m",
}


def bundled_world_path(name: str) -> Path:
    """The ``.world`` file of a bundled world (see :data:`BUNDLED_WORLDS`)."""
    if name not in BUNDLED_WORLDS:
        raise WorldError(
            f"unknown world {name!r}: bundled worlds are {', '.join(sorted(BUNDLED_WORLDS))}"
        )
    return BUNDLED_WORLDS_DIR / f"{name}.world"


def load_world(
    name_or_path: str | os.PathLike[str], *, model_path: Sequence[str | os.PathLike[str]] = ()
) -> World:
    """Load a world by bundled name (:data:`BUNDLED_WORLDS`: ``maze``, ``office``...) or file.

    Files: ``.world`` / ``.sdf`` (Gazebo SDF), ``.yaml`` / ``.yml`` (a YAML world, or a
    map_server map YAML when it has ``image`` and ``resolution`` keys).

    Args:
        name_or_path: a bundled world name or a path.
        model_path: extra folders searched first for SDF ``model://`` includes.

    Raises:
        WorldError: unknown name, missing file, unknown suffix or any loader error.
    """
    if isinstance(name_or_path, str) and name_or_path in BUNDLED_WORLDS:
        return load_sdf(bundled_world_path(name_or_path), model_path=model_path)
    path = Path(name_or_path)
    if not path.is_file():
        if isinstance(name_or_path, str) and not path.suffix and os.sep not in name_or_path:
            raise WorldError(
                f"unknown world {name_or_path!r}: not a file, and bundled worlds are "
                f"{', '.join(sorted(BUNDLED_WORLDS))}"
            )
        raise WorldError(f"{path}: world file not found")
    suffix = path.suffix.lower()
    if suffix in (".world", ".sdf"):
        return load_sdf(path, model_path=model_path)
    if suffix in (".yaml", ".yml"):
        data = read_yaml(path)
        if is_map_yaml(data):
            return load_image_world(path)
        return world_from_dict(data, source=path)
    raise WorldError(f"{path}: unknown world file type {suffix!r} (use .world, .sdf or .yaml)")
