"""Planar range sensing: exact 2-D ray casts against a Scene or an occupancy grid.

* :func:`cast_2d` / :func:`cast_2d_many`: distance from a laser at height ``z`` to the first
  segment or circle whose ``[zmin, zmax]`` contains ``z``, through the scene's uniform grid
  (:mod:`roverlab.raycast.accel`); exact, equal to testing every primitive.
* :func:`cast_grid` / :func:`cast_grid_many`: distance to the first occupied cell of an
  occupancy grid (the map-as-world case, AMCL's beam model, map-based scan simulation),
  exact to the cell boundary.

Every function returns ``inf`` for a beam with nothing within ``range_max`` and ``0.0`` for
a beam whose origin lies inside (or on) an obstacle. Angles are radians; world angles are
measured from the x axis counter-clockwise; poses are ``(x, y, yaw)``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.raycast.accel import (
    Grid,
    circle_hit,
    dda_steps,
    grid_entry,
    scene_grid,
    segment_distance,
)
from roverlab.raycast.errors import RaycastInputError
from roverlab.raycast.scene import Scene
from roverlab.raycast.sweep import SWEEP_MAX_PRIMITIVES_PER_BEAM, fan_step, sweep_fan

__all__ = ["Fan", "cast_2d", "cast_2d_many", "cast_grid", "cast_grid_many", "grid_ray"]

_jit = numba.njit(cache=True, nogil=True)

# Two grid-cell boundary distances closer than this (in cells) are a corner crossing.
_CORNER_TOL = 1e-9


@_jit
def _cast_ray(
    ox: float,
    oy: float,
    dx: float,
    dy: float,
    z: float,
    rmax: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    cstart: NDArray[np.int32],
    items: NDArray[np.int32],
    nseg: int,
) -> float:
    t0, ix, iy = grid_entry(ox, oy, dx, dy, gx0, gy0, cell, nx, ny)
    if t0 > rmax:
        return math.inf
    stepx, stepy, offx, offy, invdx, invdy = dda_steps(dx, dy)
    best = math.inf
    while True:
        tmx = (gx0 + (ix + offx) * cell - ox) * invdx if stepx != 0 else math.inf
        tmy = (gy0 + (iy + offy) * cell - oy) * invdy if stepy != 0 else math.inf
        texit = min(tmx, tmy)
        c = iy * nx + ix
        for k in range(cstart[c], cstart[c + 1]):
            it = items[k]
            if it < nseg:
                if z < segz[it, 0] or z > segz[it, 1]:
                    continue
                t = segment_distance(
                    ox, oy, dx, dy, segs[it, 0], segs[it, 1], segs[it, 2], segs[it, 3], best
                )
            else:
                j = it - nseg
                if z < circz[j, 0] or z > circz[j, 1]:
                    continue
                t, _ = circle_hit(ox, oy, dx, dy, circs[j, 0], circs[j, 1], circs[j, 2])
            best = min(best, t)
        if best <= texit or texit > rmax:
            break
        if tmx < tmy:
            ix += stepx
            if ix < 0 or ix >= nx:
                break
        else:
            iy += stepy
            if iy < 0 or iy >= ny:
                break
    return best if best <= rmax else math.inf


@_jit
def _cast_2d_kernel(
    poses: NDArray[np.float64],
    z: float,
    angles: NDArray[np.float64],
    ca: NDArray[np.float64],
    sa: NDArray[np.float64],
    rmax: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    cstart: NDArray[np.int32],
    items: NDArray[np.int32],
    nseg: int,
    out: NDArray[np.float64],
) -> None:
    """Every pose's fan: beam ``i`` along ``angles[i]`` turned by the pose's yaw, whose
    unit vector at yaw 0 is ``(ca[i], sa[i])``."""
    n = angles.shape[0]
    # a uniform fan in a small scene: the angular sweep (same ranges, see .sweep)
    step = fan_step(angles)
    sweep = step > 0.0 and segs.shape[0] + circs.shape[0] <= SWEEP_MAX_PRIMITIVES_PER_BEAM * n
    dxs = np.empty(n)
    dys = np.empty(n)
    for p in range(poses.shape[0]):
        ox = poses[p, 0]
        oy = poses[p, 1]
        yaw = poses[p, 2]
        cy = math.cos(yaw)
        sy = math.sin(yaw)
        for i in range(n):
            if yaw == 0.0:
                dxs[i] = ca[i]
                dys[i] = sa[i]
            else:
                dxs[i] = cy * ca[i] - sy * sa[i]
                dys[i] = sy * ca[i] + cy * sa[i]
        if sweep:
            sweep_fan(ox, oy, z, yaw + angles[0], step, dxs, dys, rmax,
                      segs, segz, circs, circz, out[p])  # fmt: skip
            continue
        for i in range(n):
            out[p, i] = _cast_ray(
                ox, oy, dxs[i], dys[i], z, rmax, segs, segz, circs, circz,
                gx0, gy0, cell, nx, ny, cstart, items, nseg,
            )  # fmt: skip


@_jit
def _grid_ray(
    gx: float,
    gy: float,
    dx: float,
    dy: float,
    rmax: float,
    grid: NDArray[np.uint8],
    occ: int,
) -> float:
    """First occupied cell along a ray in cell units (cell (r, c) = [c, c+1) x [r, r+1))."""
    h, w = grid.shape
    t0, ix, iy = grid_entry(gx, gy, dx, dy, 0.0, 0.0, 1.0, w, h)
    if t0 > rmax:
        return math.inf
    if grid[iy, ix] == occ:
        return t0
    stepx, stepy, offx, offy, invdx, invdy = dda_steps(dx, dy)
    while True:
        tmx = ((ix + offx) - gx) * invdx if stepx != 0 else math.inf
        tmy = ((iy + offy) - gy) * invdy if stepy != 0 else math.inf
        t = min(tmx, tmy)
        if t > rmax:
            return math.inf
        if abs(tmx - tmy) <= _CORNER_TOL * max(1.0, t):
            # through a cell corner: the two side cells touch the ray too (no leaks
            # through diagonal gaps)
            nix = ix + stepx
            niy = iy + stepy
            inx = 0 <= nix < w
            iny = 0 <= niy < h
            if (inx and grid[iy, nix] == occ) or (iny and grid[niy, ix] == occ):
                return t
            if not (inx and iny):
                return math.inf
            ix = nix
            iy = niy
        elif tmx < tmy:
            ix += stepx
            if ix < 0 or ix >= w:
                return math.inf
        else:
            iy += stepy
            if iy < 0 or iy >= h:
                return math.inf
        if grid[iy, ix] == occ:
            return t


#: The grid ray kernel itself, for other compiled kernels (amcl's beam model): ``grid_ray(gx,
#: gy, dx, dy, rmax, grid, occ)`` with the origin and ``rmax`` in cell units and ``(dx, dy)``
#: a unit direction; returns the distance in cells to the first cell equal to ``occ``
#: (``inf``: none within ``rmax``; cells outside the grid are free).
grid_ray = _grid_ray


@_jit
def _cast_grid_kernel(
    poses: NDArray[np.float64],
    angles: NDArray[np.float64],
    rmax: float,
    grid: NDArray[np.uint8],
    occ: int,
    resolution: float,
    gox: float,
    goy: float,
    out: NDArray[np.float64],
) -> None:
    n = angles.shape[0]
    ca = np.cos(angles)
    sa = np.sin(angles)
    inv = 1.0 / resolution
    rmax_cells = rmax * inv
    for p in range(poses.shape[0]):
        gx = (poses[p, 0] - gox) * inv
        gy = (poses[p, 1] - goy) * inv
        yaw = poses[p, 2]
        cy = math.cos(yaw)
        sy = math.sin(yaw)
        for i in range(n):
            if yaw == 0.0:
                dx = ca[i]
                dy = sa[i]
            else:
                dx = cy * ca[i] - sy * sa[i]
                dy = sy * ca[i] + cy * sa[i]
            t = _grid_ray(gx, gy, dx, dy, rmax_cells, grid, occ)
            r = t * resolution
            out[p, i] = r if r <= rmax else math.inf


def _angles(angles: ArrayLike) -> NDArray[np.float64]:
    a = np.ascontiguousarray(angles, dtype=np.float64)
    if a.ndim != 1:
        raise RaycastInputError(f"angles must be a 1-D array, got shape {a.shape}")
    if not np.isfinite(a).all():
        raise RaycastInputError("angles hold NaN or infinite values")
    return a


def _poses(poses: ArrayLike) -> NDArray[np.float64]:
    p = np.ascontiguousarray(poses, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise RaycastInputError(f"poses must have shape (P, 3) (x, y, yaw), got {p.shape}")
    if not np.isfinite(p).all():
        raise RaycastInputError("poses hold NaN or infinite values")
    return p


def _finite(name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v):
        raise RaycastInputError(f"{name} must be finite, got {value}")
    return v


def _range_max(range_max: float) -> float:
    r = float(range_max)
    if not r > 0.0:  # also rejects NaN
        raise RaycastInputError(f"range_max must be > 0, got {range_max}")
    return r


@_jit
def _unit_vectors(angles: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    return np.cos(angles), np.sin(angles)


def _run_scene(
    scene: Scene,
    poses: NDArray[np.float64],
    z: float,
    angles: NDArray[np.float64],
    rmax: float,
    unit: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    out: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    ca, sa = _unit_vectors(angles) if unit is None else unit
    if out is None:
        out = np.empty((poses.shape[0], angles.shape[0]), dtype=np.float64)
    _cast_2d_kernel(poses, z, angles, ca, sa, rmax, *_scene_args(scene), out)
    return out


_F64 = NDArray[np.float64]
_I32 = NDArray[np.int32]
_SceneArgs = tuple[_F64, _F64, _F64, _F64, float, float, float, int, int, _I32, _I32, int]


def _scene_args(scene: Scene) -> _SceneArgs:
    """The scene's arrays and grid as :func:`_cast_2d_kernel` takes them."""
    g: Grid = scene_grid(scene)
    return (
        scene.segments, scene.segment_z, scene.circles, scene.circle_z,
        g.x0, g.y0, g.cell, g.nx, g.ny, g.cell_start, g.items, g.n_segments,
    )  # fmt: skip


def _check_pose(x: float, y: float, z: float, yaw: float) -> None:
    if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(z) and math.isfinite(yaw)):
        raise RaycastInputError(f"lidar pose must be finite, got ({x}, {y}, {z}, {yaw})")


class Fan:
    """One sensor's fan of beams, cast again and again from moving poses (a simulated
    lidar): the beams' unit vectors are computed once and turned by each pose's yaw,
    and the arguments are checked once, where :func:`cast_2d` checks them every call.

    Args:
        rel_angles: (N,) beam angles relative to the sensor's yaw (rad).
        range_max: maximum range (m).

    Raises:
        RaycastInputError: non-finite angles, non-positive ``range_max``.
    """

    def __init__(self, rel_angles: ArrayLike, range_max: float) -> None:
        self.angles = _angles(rel_angles)
        self.range_max = _range_max(range_max)
        self._unit = _unit_vectors(self.angles)
        self._pose = np.zeros((1, 3))
        self._out = np.empty((1, self.angles.shape[0]))

    def cast(self, scene: Scene, x: float, y: float, z: float, yaw: float) -> NDArray[np.float64]:
        """Ranges from ``(x, y)`` at height ``z`` with the sensor turned to ``yaw``, as
        :func:`cast_2d_many` for one pose. The array is reused by the next call.

        Raises:
            RaycastInputError: a non-finite pose.
        """
        _check_pose(x, y, z, yaw)
        pose = self._pose[0]
        pose[0], pose[1], pose[2] = x, y, yaw
        _run_scene(scene, self._pose, z, self.angles, self.range_max, self._unit, self._out)
        return self._out[0]

    def cast_later(
        self, scene: Scene, x: float, y: float, z: float, yaw: float
    ) -> Callable[[], NDArray[np.float64]]:
        """:meth:`cast` deferred: the pose is checked and the scene's arrays and grid are
        taken now; the returned function casts (into arrays of its own, so it may run in
        any thread, any number of times) and returns what :meth:`cast` returns now.

        Raises:
            RaycastInputError: a non-finite pose (now, as :meth:`cast`).
        """
        _check_pose(x, y, z, yaw)
        args = _scene_args(scene)
        angles, (ca, sa), rmax = self.angles, self._unit, self.range_max

        def cast() -> NDArray[np.float64]:
            out = np.empty((1, angles.shape[0]), dtype=np.float64)
            _cast_2d_kernel(np.array([[x, y, yaw]]), z, angles, ca, sa, rmax, *args, out)
            return out[0]

        return cast


def cast_2d(
    scene: Scene, x: float, y: float, z: float, angles: ArrayLike, range_max: float
) -> NDArray[np.float64]:
    """Cast planar rays from ``(x, y)`` at height ``z`` along world ``angles``.

    Args:
        scene: the scene (its grid is built on first use and cached).
        x, y: ray origin in the world frame (m).
        z: laser height (m); only primitives with ``zmin <= z <= zmax`` are seen.
        angles: (N,) world angles of the beams (rad).
        range_max: beams with nothing within this distance (m) return ``inf``.

    Returns:
        (N,) float64 distances (m): ``inf`` for no hit, ``0.0`` when the origin is inside a
        circle or on a segment.

    Raises:
        RaycastInputError: non-finite pose or angles, non-positive ``range_max``.
    """
    pose = np.array([[_finite("x", x), _finite("y", y), 0.0]])
    return _run_scene(scene, pose, _finite("z", z), _angles(angles), _range_max(range_max))[0]


def cast_2d_many(
    scene: Scene, poses: ArrayLike, z: float, rel_angles: ArrayLike, range_max: float
) -> NDArray[np.float64]:
    """Cast the same fan of beams from many poses (particle filters, multi-robot).

    Args:
        scene: the scene.
        poses: (P, 3) ``x, y, yaw`` of the sensor in the world frame.
        z: laser height (m).
        rel_angles: (N,) beam angles relative to each pose's yaw (rad).
        range_max: maximum range (m).

    Returns:
        (P, N) float64 distances, as :func:`cast_2d`.

    Raises:
        RaycastInputError: bad shapes, non-finite values, non-positive ``range_max``.
    """
    return _run_scene(
        scene, _poses(poses), _finite("z", z), _angles(rel_angles), _range_max(range_max)
    )


def _grid_u8(grid: ArrayLike, occupied_value: int) -> tuple[NDArray[np.uint8], int]:
    g = np.asarray(grid)
    if g.ndim != 2 or g.shape[0] == 0 or g.shape[1] == 0:
        raise RaycastInputError(f"grid must be a non-empty 2-D array, got shape {g.shape}")
    if g.dtype == np.bool_:
        return np.ascontiguousarray(g).view(np.uint8), 1
    if g.dtype == np.int8:
        if not -128 <= occupied_value <= 127:
            raise RaycastInputError(f"occupied_value {occupied_value} is not an int8 value")
        return np.ascontiguousarray(g).view(np.uint8), occupied_value & 0xFF
    if g.dtype == np.uint8:
        if not 0 <= occupied_value <= 255:
            raise RaycastInputError(f"occupied_value {occupied_value} is not a uint8 value")
        return np.ascontiguousarray(g), occupied_value
    raise RaycastInputError(f"grid dtype must be bool, uint8 or int8, got {g.dtype}")


def _run_grid(
    grid: ArrayLike,
    resolution: float,
    origin_xy: ArrayLike,
    poses: NDArray[np.float64],
    angles: NDArray[np.float64],
    range_max: float,
    occupied_value: int,
) -> NDArray[np.float64]:
    g, occ = _grid_u8(grid, int(occupied_value))
    res = float(resolution)
    if not (math.isfinite(res) and res > 0.0):
        raise RaycastInputError(f"resolution must be positive and finite, got {resolution}")
    org = np.asarray(origin_xy, dtype=np.float64).reshape(-1)
    if org.shape[0] < 2 or not np.isfinite(org[:2]).all():
        raise RaycastInputError(f"origin_xy must be two finite numbers, got {org.tolist()}")
    out = np.empty((poses.shape[0], angles.shape[0]), dtype=np.float64)
    _cast_grid_kernel(
        poses, angles, _range_max(range_max), g, occ, res, float(org[0]), float(org[1]), out
    )
    return out


def cast_grid(
    grid: ArrayLike,
    resolution: float,
    origin_xy: ArrayLike,
    x: float,
    y: float,
    angles: ArrayLike,
    range_max: float,
    *,
    occupied_value: int = 100,
) -> NDArray[np.float64]:
    """Cast planar rays through an occupancy grid (DDA, exact cell-boundary distances).

    Cell ``grid[r, c]`` covers ``x in origin_x + [c, c+1) * resolution`` and
    ``y in origin_y + [r, r+1) * resolution`` (the ``nav_msgs/OccupancyGrid`` layout: row 0
    at the origin, rows along +y). Cells outside the grid are free. A ray through the
    exact corner of two cells stops at the corner if either side cell is occupied.

    Args:
        grid: (H, W) bool (True = obstacle), uint8 or int8 (``OccupancyGrid.data``
            reshaped) array.
        resolution: cell side (m).
        origin_xy: world coordinates of the corner of cell ``(0, 0)`` (m).
        x, y: ray origin in the world frame (m).
        angles: (N,) world angles (rad).
        range_max: maximum range (m).
        occupied_value: cells equal to this value are obstacles (ignored for bool grids;
            100 is ``OccupancyGrid``'s occupied value).

    Returns:
        (N,) float64 distances: ``inf`` for no hit within ``range_max``, ``0.0`` when the
        origin's cell is occupied.

    Raises:
        RaycastInputError: bad grid dtype or shape, non-finite values, bad resolution.
    """
    pose = np.array([[_finite("x", x), _finite("y", y), 0.0]])
    return _run_grid(grid, resolution, origin_xy, pose, _angles(angles), range_max, occupied_value)[
        0
    ]


def cast_grid_many(
    grid: ArrayLike,
    resolution: float,
    origin_xy: ArrayLike,
    poses: ArrayLike,
    rel_angles: ArrayLike,
    range_max: float,
    *,
    occupied_value: int = 100,
) -> NDArray[np.float64]:
    """:func:`cast_grid` for the same fan of beams from many ``(x, y, yaw)`` poses.

    Returns:
        (P, N) float64 distances.
    """
    return _run_grid(
        grid, resolution, origin_xy, _poses(poses), _angles(rel_angles), range_max, occupied_value
    )
