"""A URDF ``<mesh>`` as points the simulator can use (its footprint and height)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from roverlab.description.errors import DescriptionError
from roverlab.description.model import Mesh
from roverlab.description.packages import resolve_uri
from roverlab.geometry.mesh import MeshError, load_mesh

__all__ = ["mesh_points"]


def mesh_points(mesh: Mesh, source: str) -> NDArray[np.float64]:
    """The hull vertices of every part of ``mesh`` (``package://``, ``file://`` or a path
    relative to the robot file ``source``), scaled, in the geometry's own frame.

    Raises:
        DescriptionError: the file cannot be found or read (one line naming it).
    """
    path = resolve_uri(mesh.filename)
    if not path.is_absolute() and source and not source.startswith("<"):
        path = Path(source).parent / path
    try:
        parts = load_mesh(path)
    except MeshError as err:
        raise DescriptionError(str(err)) from err
    hulls = [p.hull for p in parts if len(p.hull)]
    if not hulls:
        raise DescriptionError(f"{path}: mesh has no vertices")
    return np.vstack(hulls) * np.asarray(mesh.scale, dtype=np.float64)
