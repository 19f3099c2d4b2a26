"""Static worlds: Gazebo ``.world``/SDF files, a YAML world format and map images.

A :class:`World` holds static shapes (boxes, cylinders, spheres, extruded polylines,
posters) and compiles into the ray-casting :class:`~roverlab.raycast.scene.Scene`
(:meth:`World.to_scene`), ground-truth occupancy grids (:meth:`World.occupancy`) and
exact footprint collision checks (:meth:`World.footprint_collides`).

Load one with :func:`load_world` (a bundled name: ``maze``, ``office``, ``house``,
``empty``; or a ``.world``, ``.sdf`` or ``.yaml`` file), or with the format's own
loader: :func:`load_sdf`, :func:`load_yaml_world`, :func:`load_image_world`.
"""

from roverlab.world.errors import WorldError
from roverlab.world.image_world import load_image_world, occupied_rectangles
from roverlab.world.loader import BUNDLED_WORLDS, BUNDLED_WORLDS_DIR, bundled_world_path, load_world
from roverlab.world.model import (
    BoxShape,
    CylinderShape,
    PolylineShape,
    PosterShape,
    Shape,
    SphereShape,
    World,
)
from roverlab.world.report import group_warnings, world_warnings
from roverlab.world.sdf import load_sdf, model_search_path
from roverlab.world.yaml_world import load_yaml_world

__all__ = [
    "BUNDLED_WORLDS",
    "BUNDLED_WORLDS_DIR",
    "BoxShape",
    "CylinderShape",
    "PolylineShape",
    "PosterShape",
    "Shape",
    "SphereShape",
    "World",
    "WorldError",
    "bundled_world_path",
    "group_warnings",
    "load_image_world",
    "load_sdf",
    "load_world",
    "load_yaml_world",
    "model_search_path",
    "occupied_rectangles",
    "world_warnings",
]
