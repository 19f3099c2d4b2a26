"""Shared ray casting: one compiled kernel set for lidar, camera, depth and map sensors.

* :class:`Scene`: the static 2.5-D world (vertical wall segments, vertical cylinders).
* :func:`cast_2d`, :func:`cast_2d_many`: exact planar laser ranges in a Scene.
* :func:`cast_grid`, :func:`cast_grid_many`: exact planar ranges in an occupancy grid;
  :func:`grid_ray`, their compiled one-ray kernel, for other kernels.
* :func:`render`: RGB + depth images of a pinhole camera (:func:`render_rgb`: RGB alone);
  :func:`depth_to_points`, :func:`optical_to_body`, :func:`body_to_optical` for point
  clouds.
* :func:`scene_grid`: the uniform-grid accelerator every Scene kernel walks (cached).

Kernels are ``numba.njit(cache=True, nogil=True)``: callers may run them from threads.
"""

from roverlab.raycast.accel import Grid, build_grid, scene_grid
from roverlab.raycast.camera import (
    MAX_LAYERS,
    CameraIntrinsics,
    body_to_optical,
    camera_intrinsics,
    depth_to_points,
    optical_to_body,
    render,
    render_rgb,
)
from roverlab.raycast.errors import RaycastError, RaycastInputError
from roverlab.raycast.lidar import cast_2d, cast_2d_many, cast_grid, cast_grid_many, grid_ray
from roverlab.raycast.scene import Scene

__all__ = [
    "MAX_LAYERS",
    "CameraIntrinsics",
    "Grid",
    "RaycastError",
    "RaycastInputError",
    "Scene",
    "body_to_optical",
    "build_grid",
    "camera_intrinsics",
    "cast_2d",
    "cast_2d_many",
    "cast_grid",
    "cast_grid_many",
    "depth_to_points",
    "grid_ray",
    "optical_to_body",
    "render",
    "render_rgb",
    "scene_grid",
]
