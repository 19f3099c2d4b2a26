"""How good is a SLAM map? Compare an occupancy grid with the world's ground truth.

Pure: arrays in, a small typed result out (no bus, no clock).

1. **Ground truth** (:func:`ground_truth`): the world's solid shapes rasterised at the lidar's
   height on a grid of the map's resolution (:meth:`roverlab.world.World.occupancy`).
2. **Alignment** (:func:`align_map`): a SLAM map's frame is the robot's pose when mapping
   started, so ``world_T_map`` is first the known spawn pose (``prior``); a two-stage
   search over translation (+-``search_xy_m``) and rotation (+-``search_theta_rad``) around it
   then maximises the agreement: the fraction of the map's occupied cells that fall on a
   ground-truth wall plus the fraction of its free cells that fall on free ground (each
   fraction counts, so a few hundred wall cells weigh as much as thousands of free ones).
3. **Scores** (:func:`evaluate_map`), over the map's *known* cells (occupied: value >=
   ``occupied_threshold``; free: 0 <= value <= ``free_threshold``; unknown -1 and the
   uncertain values between are not scored -- the region the robot saw):

   * ``accuracy``: the fraction classified correctly, with a one-cell tolerance band at
     wall boundaries: an occupied map cell is correct when a ground-truth wall cell lies
     within one cell of it (its 3 x 3 neighbourhood), a free map cell when a ground-truth
     free cell does. Away from boundaries (more than one cell from any wall edge) a cell
     must match exactly; only the one-cell band either side of a wall face accepts both
     labels, which absorbs the half-cell quantisation of two lattices that need not line
     up. ``strict_accuracy`` is the same without the band;
   * the **wall distance**: for each occupied map cell, the distance (in cells, between
     cell centres on the ground-truth lattice) to the nearest ground-truth wall cell;
     ``wall_distance_max``, ``wall_distance_p95`` and ``wall_distance_mean``;
   * ``coverage``: the fraction of the ground truth's free cells reachable from the map's
     origin (4-connected flood fill) that the map knows.

:func:`write_overlay_png` draws the aligned map over the ground truth, for looking at it.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit
from numpy.typing import NDArray
from PIL import Image
from scipy import ndimage

from roverlab.fileio import atomic_write
from roverlab.geometry import SE2
from roverlab.slam.data.errors import SlamError
from roverlab.world import World

__all__ = [
    "GroundTruth",
    "MapQuality",
    "MapQualityError",
    "OccupancyMapLike",
    "ReachableArea",
    "align_map",
    "evaluate_map",
    "grid_from_msg",
    "ground_truth",
    "write_overlay_png",
]

# map_saver's defaults: occupied >= 65, free <= 25 (0.65 and 0.196 of 100)
_OCCUPIED_THRESHOLD = 65
_FREE_THRESHOLD = 25
_IDENTITY = SE2()


class MapQualityError(SlamError):
    """A map or a ground truth cannot be scored (empty, malformed, nothing known)."""


@dataclass(frozen=True, slots=True)
class OccupancyMapLike:
    """An occupancy grid as arrays (``nav_msgs/OccupancyGrid`` conventions).

    Attributes:
        data: (H, W) int8: -1 unknown, 0..100 occupancy; row 0 at the lowest y.
        origin_xy: map-frame ``(x, y)`` of the outer corner of cell ``[0, 0]`` (m).
        resolution: cell size (m).
    """

    data: NDArray[np.int8]
    origin_xy: tuple[float, float]
    resolution: float

    def __post_init__(self) -> None:
        data = np.asarray(self.data)
        if data.ndim != 2 or data.size == 0:
            raise MapQualityError(f"a map must be a non-empty 2-D grid, got shape {data.shape}")
        if not (math.isfinite(self.resolution) and self.resolution > 0.0):
            raise MapQualityError(f"map resolution must be > 0, got {self.resolution}")
        if not all(math.isfinite(v) for v in self.origin_xy):
            raise MapQualityError(f"map origin must be finite, got {self.origin_xy}")


def grid_from_msg(msg: Any) -> OccupancyMapLike:
    """The arrays of a ``nav_msgs/OccupancyGrid`` (its origin's yaw must be 0, as SLAM's).

    Raises:
        MapQualityError: a rotated origin or a data size that does not match the info.
    """
    info = msg.info
    q = info.origin.orientation
    if abs(float(q.z)) > 1e-9 or abs(float(q.x)) > 1e-9 or abs(float(q.y)) > 1e-9:
        raise MapQualityError("occupancy grids with a rotated origin are not supported")
    width, height = int(info.width), int(info.height)
    data = np.asarray(msg.data, dtype=np.int8)
    if data.size != width * height:
        raise MapQualityError(f"occupancy grid: {data.size} cells for a {width} x {height} map")
    return OccupancyMapLike(
        data=data.reshape(height, width),
        origin_xy=(float(info.origin.position.x), float(info.origin.position.y)),
        resolution=float(info.resolution),
    )


@dataclass(frozen=True, slots=True)
class GroundTruth:
    """The world's occupancy at the lidar's height.

    Attributes:
        occupied: (rows, cols) bool, row 0 at the lowest y (world frame).
        origin_xy: world ``(x, y)`` of the outer corner of cell ``[0, 0]`` (m).
        resolution: cell size (m).
    """

    occupied: NDArray[np.bool_]
    origin_xy: tuple[float, float]
    resolution: float


def ground_truth(
    world: World, *, resolution: float, z_m: float, padding_m: float = 1.0
) -> GroundTruth:
    """Rasterise ``world`` at height ``z_m`` (the lidar's) with cells of ``resolution``.

    Args:
        world: the simulated world.
        resolution: cell size (m): the SLAM map's.
        z_m: the height of the scan plane above the floor (m).
        padding_m: free margin around the world's shapes (m).

    Raises:
        MapQualityError: a bad resolution, or a world without solid shapes.
    """
    if not (math.isfinite(resolution) and resolution > 0.0):
        raise MapQualityError(f"ground truth resolution must be > 0, got {resolution}")
    occ, origin = world.occupancy(resolution, z_m, z_m, padding=padding_m)
    if not occ.any():
        raise MapQualityError(f"world {world.name!r} has nothing solid at z = {z_m:.3f} m")
    return GroundTruth(
        occupied=occ, origin_xy=(float(origin[0]), float(origin[1])), resolution=float(resolution)
    )


@dataclass(frozen=True, slots=True)
class MapQuality:
    """Scores of one map against the ground truth (see the module docstring).

    Attributes:
        accuracy: fraction of known cells classified correctly (one-cell tolerance band).
        strict_accuracy: the same without the band.
        occupied_accuracy: fraction of the occupied cells that are correct (with the band).
        free_accuracy: fraction of the free cells that are correct (with the band).
        known_cells: cells scored (occupied + free).
        occupied_cells: occupied cells scored.
        free_cells: free cells scored.
        wall_distance_max: largest distance of an occupied cell to a true wall (cells).
        wall_distance_p95: its 95th percentile (cells).
        wall_distance_mean: its mean (cells).
        coverage: fraction of the reachable true free cells the map knows.
        alignment: ``world_T_map`` used.
        resolution: the map's cell size (m).
    """

    accuracy: float
    strict_accuracy: float
    occupied_accuracy: float
    free_accuracy: float
    known_cells: int
    occupied_cells: int
    free_cells: int
    wall_distance_max: float
    wall_distance_p95: float
    wall_distance_mean: float
    coverage: float
    alignment: SE2
    resolution: float

    def summary(self) -> str:
        """One line with the figures."""
        a = self.alignment
        return (
            f"{100 * self.accuracy:.2f}% of {self.known_cells} known cells correct "
            f"(strict {100 * self.strict_accuracy:.2f}%, occupied "
            f"{100 * self.occupied_accuracy:.2f}%, free {100 * self.free_accuracy:.2f}%); "
            f"wall distance max {self.wall_distance_max:.2f} / p95 "
            f"{self.wall_distance_p95:.2f} / mean {self.wall_distance_mean:.2f} cells; "
            f"coverage {100 * self.coverage:.1f}%; alignment ({a.x:.3f} m, {a.y:.3f} m, "
            f"{math.degrees(a.theta):.2f} deg)"
        )


# ------------------------------------------------------------------------------ kernels
@njit(cache=True)
def _agreement(
    occ_pts: NDArray[np.float64],
    free_pts: NDArray[np.float64],
    cands: NDArray[np.float64],
    gt: NDArray[np.bool_],
    ox: float,
    oy: float,
    inv_res: float,
    out: NDArray[np.float64],
) -> None:
    """For each candidate ``(x, y, theta)``: fraction of occupied points on true walls plus
    fraction of free points on true free cells (points outside the raster count as free)."""
    rows, cols = gt.shape
    n_occ = occ_pts.shape[0]
    n_free = free_pts.shape[0]
    for k in range(cands.shape[0]):
        tx, ty, th = cands[k, 0], cands[k, 1], cands[k, 2]
        c, s = math.cos(th), math.sin(th)
        hits = 0
        for i in range(n_occ):
            px, py = occ_pts[i, 0], occ_pts[i, 1]
            col = int(math.floor((tx + c * px - s * py - ox) * inv_res))
            row = int(math.floor((ty + s * px + c * py - oy) * inv_res))
            if 0 <= row < rows and 0 <= col < cols and gt[row, col]:
                hits += 1
        free = 0
        for i in range(n_free):
            px, py = free_pts[i, 0], free_pts[i, 1]
            col = int(math.floor((tx + c * px - s * py - ox) * inv_res))
            row = int(math.floor((ty + s * px + c * py - oy) * inv_res))
            if not (0 <= row < rows and 0 <= col < cols) or not gt[row, col]:
                free += 1
        score = 0.0
        if n_occ > 0:
            score += hits / n_occ
        if n_free > 0:
            score += free / n_free
        out[k] = score


# ------------------------------------------------------------------------------ helpers
def _classify(
    grid: OccupancyMapLike, occupied_threshold: int, free_threshold: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    if not 0 <= free_threshold < occupied_threshold <= 100:
        raise MapQualityError(
            "need 0 <= free_threshold < occupied_threshold <= 100, got "
            f"{free_threshold} and {occupied_threshold}"
        )
    d = np.asarray(grid.data)
    occ = d >= occupied_threshold
    free = (d >= 0) & (d <= free_threshold)
    return occ, free


def _centres(grid: OccupancyMapLike, mask: NDArray[np.bool_]) -> NDArray[np.float64]:
    """Map-frame centres (N, 2) of the cells in ``mask``."""
    rows, cols = np.nonzero(mask)
    r = grid.resolution
    pts = np.empty((rows.size, 2))
    pts[:, 0] = grid.origin_xy[0] + (cols + 0.5) * r
    pts[:, 1] = grid.origin_xy[1] + (rows + 0.5) * r
    return pts


def _to_world(pts: NDArray[np.float64], pose: SE2) -> NDArray[np.float64]:
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    out = np.empty_like(pts)
    out[:, 0] = pose.x + c * pts[:, 0] - s * pts[:, 1]
    out[:, 1] = pose.y + s * pts[:, 0] + c * pts[:, 1]
    return out


def _gt_cells(
    world_pts: NDArray[np.float64], gt: GroundTruth
) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
    """Row, column (clipped) and inside-flag of the ground-truth cell under each point."""
    inv = 1.0 / gt.resolution
    col = np.floor((world_pts[:, 0] - gt.origin_xy[0]) * inv).astype(np.intp)
    row = np.floor((world_pts[:, 1] - gt.origin_xy[1]) * inv).astype(np.intp)
    rows, cols = gt.occupied.shape
    inside = (row >= 0) & (row < rows) & (col >= 0) & (col < cols)
    return np.clip(row, 0, rows - 1), np.clip(col, 0, cols - 1), inside


def _grid_search(
    occ_pts: NDArray[np.float64],
    free_pts: NDArray[np.float64],
    gt: GroundTruth,
    centre: SE2,
    half_xy: float,
    step_xy: float,
    half_th: float,
    step_th: float,
) -> tuple[SE2, float]:
    nxy = round(half_xy / step_xy)
    nth = round(half_th / step_th)
    offs = np.arange(-nxy, nxy + 1) * step_xy
    ths = np.arange(-nth, nth + 1) * step_th
    gx, gy, gth = np.meshgrid(offs, offs, ths, indexing="ij")
    cands = np.stack(
        [centre.x + gx.ravel(), centre.y + gy.ravel(), centre.theta + gth.ravel()], axis=1
    )
    # the unmoved centre first: among equal scores, argmax keeps the prior
    dist = np.abs(gx.ravel()) + np.abs(gy.ravel()) + np.abs(gth.ravel())
    cands = np.ascontiguousarray(cands[np.argsort(dist, kind="stable")])
    out = np.empty(cands.shape[0])
    _agreement(
        occ_pts,
        free_pts,
        cands,
        np.ascontiguousarray(gt.occupied),
        gt.origin_xy[0],
        gt.origin_xy[1],
        1.0 / gt.resolution,
        out,
    )
    k = int(np.argmax(out))
    return SE2(float(cands[k, 0]), float(cands[k, 1]), float(cands[k, 2])), float(out[k])


# ------------------------------------------------------------------------------ API
def align_map(
    grid: OccupancyMapLike,
    gt: GroundTruth,
    *,
    prior: SE2 = _IDENTITY,
    search_xy_m: float = 0.3,
    search_theta_rad: float = math.radians(5.0),
    occupied_threshold: int = _OCCUPIED_THRESHOLD,
    free_threshold: int = _FREE_THRESHOLD,
) -> SE2:
    """``world_T_map`` maximising the agreement of ``grid`` with ``gt`` near ``prior``.

    A coarse search (steps of one cell and ~0.5 degree over the whole window) is refined by
    a fine one (fifth-of-a-cell and 0.1 degree steps) around its best candidate.

    Args:
        grid: the SLAM map.
        gt: the ground truth (same resolution recommended).
        prior: the known ``world_T_map`` (the robot's spawn pose when mapping started).
        search_xy_m: half-width of the translational search (m); 0 keeps the prior's.
        search_theta_rad: half-width of the rotational search (rad); 0 keeps the prior's.
        occupied_threshold: map values at or above this are occupied.
        free_threshold: map values 0..this are free.

    Raises:
        MapQualityError: a map without occupied or free cells, bad thresholds, a
            non-finite prior or search window.
    """
    if not all(math.isfinite(v) for v in (prior.x, prior.y, prior.theta)):
        raise MapQualityError(f"the prior pose must be finite, got {prior}")
    occ, free = _classify(grid, occupied_threshold, free_threshold)
    if not occ.any() or not free.any():
        raise MapQualityError("the map has no occupied or no free cells: nothing to align")
    if not (search_xy_m >= 0.0 and search_theta_rad >= 0.0):  # NaN fails too
        raise MapQualityError("search windows must be >= 0")
    occ_pts = _centres(grid, occ)
    free_pts = _centres(grid, free)
    res = grid.resolution
    step_th = math.radians(0.5)
    best, _ = _grid_search(
        occ_pts, free_pts, gt, prior, search_xy_m, res, search_theta_rad, step_th
    )
    fine_xy = res / 5.0 if search_xy_m > 0.0 else res
    fine_th = math.radians(0.1) if search_theta_rad > 0.0 else step_th
    best, _ = _grid_search(
        occ_pts,
        free_pts,
        gt,
        best,
        res if search_xy_m > 0.0 else 0.0,
        fine_xy,
        step_th if search_theta_rad > 0.0 else 0.0,
        fine_th,
    )
    return best


def evaluate_map(
    grid: OccupancyMapLike,
    gt: GroundTruth,
    *,
    prior: SE2 = _IDENTITY,
    search_xy_m: float = 0.3,
    search_theta_rad: float = math.radians(5.0),
    occupied_threshold: int = _OCCUPIED_THRESHOLD,
    free_threshold: int = _FREE_THRESHOLD,
) -> MapQuality:
    """Align ``grid`` to ``gt`` (:func:`align_map`) and score it (see the module docstring).

    Raises:
        MapQualityError: an empty map (no occupied or no free cells), bad thresholds.
    """
    pose = align_map(
        grid,
        gt,
        prior=prior,
        search_xy_m=search_xy_m,
        search_theta_rad=search_theta_rad,
        occupied_threshold=occupied_threshold,
        free_threshold=free_threshold,
    )
    occ, free = _classify(grid, occupied_threshold, free_threshold)
    truth = gt.occupied
    near_wall = ndimage.binary_dilation(truth, structure=np.ones((3, 3), bool))
    near_free = ndimage.binary_dilation(~truth, structure=np.ones((3, 3), bool), border_value=1)
    wall_dist = ndimage.distance_transform_edt(~truth)

    r, c, inside = _gt_cells(_to_world(_centres(grid, occ), pose), gt)
    occ_tol = near_wall[r, c] & inside
    occ_strict = truth[r, c] & inside
    # beyond the raster there is nothing (the raster is padded around every shape)
    dist = np.where(inside, wall_dist[r, c], np.inf)
    r, c, inside = _gt_cells(_to_world(_centres(grid, free), pose), gt)
    free_tol = near_free[r, c] | ~inside
    free_strict = ~truth[r, c] | ~inside

    n_occ, n_free = int(occ_tol.size), int(free_tol.size)
    known = n_occ + n_free
    return MapQuality(
        accuracy=float((occ_tol.sum() + free_tol.sum()) / known),
        strict_accuracy=float((occ_strict.sum() + free_strict.sum()) / known),
        occupied_accuracy=float(occ_tol.mean()),
        free_accuracy=float(free_tol.mean()),
        known_cells=known,
        occupied_cells=n_occ,
        free_cells=n_free,
        wall_distance_max=float(dist.max()),
        wall_distance_p95=float(np.percentile(dist, 95)),
        wall_distance_mean=float(dist.mean()),
        coverage=_coverage(grid, gt, pose, occ | free),
        alignment=pose,
        resolution=grid.resolution,
    )


def _coverage(
    grid: OccupancyMapLike, gt: GroundTruth, pose: SE2, known: NDArray[np.bool_]
) -> float:
    """Fraction of the true free cells reachable from the map origin that the map knows."""
    return ReachableArea(gt, pose).known_fraction(grid, known)


class ReachableArea:
    """The ground truth's free cells reachable (4-connected) from the map frame's origin,
    as points in the map frame: what share of them a map knows, however it grows.

    Args:
        gt: the ground truth.
        world_T_map: the map frame's pose in the world (the robot's spawn pose).
    """

    def __init__(self, gt: GroundTruth, world_T_map: SE2) -> None:
        labels, _ = ndimage.label(~gt.occupied)
        r0, c0, inside = _gt_cells(np.array([[world_T_map.x, world_T_map.y]]), gt)
        if not inside[0] or labels[r0[0], c0[0]] == 0:
            rows = cols = np.zeros(0, dtype=np.intp)
        else:
            rows, cols = np.nonzero(labels == labels[r0[0], c0[0]])
        res = gt.resolution
        pts = np.empty((rows.size, 2))
        pts[:, 0] = gt.origin_xy[0] + (cols + 0.5) * res
        pts[:, 1] = gt.origin_xy[1] + (rows + 0.5) * res
        self.points = _to_world(pts, ~world_T_map)  # world -> map frame
        #: the reachable free area (m^2)
        self.area_m2 = float(rows.size * res * res)

    def known_fraction(
        self, grid: OccupancyMapLike, known: NDArray[np.bool_] | None = None
    ) -> float:
        """Share of the reachable cells that ``grid`` knows (``known``: its known-cell
        mask; default: occupied or free by :func:`evaluate_map`'s thresholds)."""
        if not len(self.points):
            return 0.0
        if known is None:
            occ, free = _classify(grid, _OCCUPIED_THRESHOLD, _FREE_THRESHOLD)
            known = occ | free
        mc = np.floor((self.points[:, 0] - grid.origin_xy[0]) / grid.resolution).astype(np.intp)
        mr = np.floor((self.points[:, 1] - grid.origin_xy[1]) / grid.resolution).astype(np.intp)
        h, w = known.shape
        ok = (mr >= 0) & (mr < h) & (mc >= 0) & (mc < w)
        return float(np.count_nonzero(known[mr[ok], mc[ok]]) / len(self.points))


def write_overlay_png(
    path: str | os.PathLike[str],
    grid: OccupancyMapLike,
    gt: GroundTruth,
    alignment: SE2,
    *,
    scale: int = 3,
    occupied_threshold: int = _OCCUPIED_THRESHOLD,
    free_threshold: int = _FREE_THRESHOLD,
) -> Path:
    """Draw the aligned map over the ground truth as a PNG (written atomically).

    Colours: true walls dark grey, true free space white; the map's free cells light
    blue; its occupied cells green where within one cell of a true wall, red elsewhere.
    North (+y) is up.

    Returns:
        The path written.

    Raises:
        MapQualityError: the file cannot be written, or a bad ``scale``.
    """
    if not 1 <= scale <= 16:
        raise MapQualityError(f"overlay scale must be in 1..16, got {scale}")
    truth = gt.occupied
    near_wall = ndimage.binary_dilation(truth, structure=np.ones((3, 3), bool))
    img = np.full((*truth.shape, 3), 255, dtype=np.uint8)
    img[truth] = (90, 90, 90)
    occ, free = _classify(grid, occupied_threshold, free_threshold)
    r, c, inside = _gt_cells(_to_world(_centres(grid, free), alignment), gt)
    fr, fc = r[inside], c[inside]
    img[fr, fc] = np.where(truth[fr, fc, None], (60, 60, 140), (170, 210, 255))
    r, c, inside = _gt_cells(_to_world(_centres(grid, occ), alignment), gt)
    orr, occ_c = r[inside], c[inside]
    img[orr, occ_c] = np.where(near_wall[orr, occ_c, None], (0, 170, 0), (230, 0, 0))
    picture = Image.fromarray(np.ascontiguousarray(img[::-1]), "RGB")
    if scale > 1:
        picture = picture.resize(
            (picture.width * scale, picture.height * scale), Image.Resampling.NEAREST
        )
    out = Path(path)
    try:
        atomic_write(out, lambda fh: picture.save(fh, format="PNG"))
    except OSError as err:
        raise MapQualityError(f"{out}: cannot write: {err.strerror or err}") from err
    return out
