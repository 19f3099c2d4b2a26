"""Map-quality scoring against the ground truth: alignment, the tolerance band, wall
distances, coverage, the overlay PNG and the errors, on a synthetic room."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from PIL import Image
from scipy import ndimage

from roverlab.geometry import SE2
from roverlab.msgs import array_to_occupancy_grid
from roverlab.slam.data.mapquality import (
    GroundTruth,
    MapQualityError,
    OccupancyMapLike,
    align_map,
    evaluate_map,
    grid_from_msg,
    ground_truth,
    write_overlay_png,
)
from roverlab.world.yaml_world import world_from_dict

RES = 0.05
# a 6 m x 4 m room (walls 0.1 m thick), a pillar box and an L-shaped partition
ROOM = {
    "name": "room",
    "walls": [
        {"points": [[-2, -1], [4, -1], [4, 3], [-2, 3]], "closed": True},
        {"points": [[1.5, 3], [1.5, 1.5], [2.5, 1.5]]},
    ],
    "boxes": [{"center": [-0.8, 1.8], "size": [0.4, 0.6, 1.0], "yaw": 0.4}],
}
WORLD = world_from_dict(ROOM, source=Path("room.yaml"))


@pytest.fixture(scope="module")
def gt() -> GroundTruth:
    return ground_truth(WORLD, resolution=RES, z_m=0.2)


def _slam_map(gt: GroundTruth, world_t_map: SE2, *, keep: float = 1.0) -> OccupancyMapLike:
    """What a perfect SLAM map of the room looks like in a map frame at ``world_t_map``:
    wall surfaces occupied, the room's inside free, the rest (behind walls) unknown.
    ``keep``: only cells with world x below ``-2 + keep * 6`` are known."""
    truth = gt.occupied
    labels, _ = ndimage.label(~truth)
    c0 = int((0.0 - gt.origin_xy[0]) / RES)
    r0 = int((0.0 - gt.origin_xy[1]) / RES)
    inside = labels == labels[r0, c0]
    surface = truth & ndimage.binary_dilation(inside, structure=np.ones((3, 3), bool))
    h = w = 200
    origin = (-5.0, -5.0)
    rows, cols = np.mgrid[0:h, 0:w]
    mx = origin[0] + (cols + 0.5) * RES
    my = origin[1] + (rows + 0.5) * RES
    c, s = math.cos(world_t_map.theta), math.sin(world_t_map.theta)
    wx = world_t_map.x + c * mx - s * my
    wy = world_t_map.y + s * mx + c * my
    gc = np.floor((wx - gt.origin_xy[0]) / RES).astype(int)
    gr = np.floor((wy - gt.origin_xy[1]) / RES).astype(int)
    ok = (gr >= 0) & (gr < truth.shape[0]) & (gc >= 0) & (gc < truth.shape[1])
    gr, gc = np.clip(gr, 0, truth.shape[0] - 1), np.clip(gc, 0, truth.shape[1] - 1)
    data = np.full((h, w), -1, dtype=np.int8)
    data[ok & inside[gr, gc]] = 0
    data[ok & surface[gr, gc]] = 100
    data[wx > -2.0 + keep * 6.0] = -1
    return OccupancyMapLike(data=data, origin_xy=origin, resolution=RES)


POSE = SE2(0.7, -0.3, 0.25)  # where the robot started mapping, in the world


def test_perfect_map_scores_full_marks_at_its_true_alignment(gt: GroundTruth) -> None:
    q = evaluate_map(_slam_map(gt, POSE), gt, prior=POSE)
    assert q.accuracy > 0.995
    assert q.occupied_accuracy > 0.99 and q.free_accuracy > 0.995
    assert q.wall_distance_p95 <= 1.0 and q.wall_distance_max <= 1.5
    assert q.coverage > 0.97
    assert abs(q.alignment.x - POSE.x) <= RES and abs(q.alignment.y - POSE.y) <= RES
    assert abs(q.alignment.theta - POSE.theta) <= math.radians(0.5)
    assert q.known_cells == q.occupied_cells + q.free_cells > 5000
    assert "known cells correct" in q.summary()


def test_search_recovers_an_offset_prior(gt: GroundTruth) -> None:
    grid = _slam_map(gt, POSE)
    off = SE2(POSE.x + 0.17, POSE.y - 0.12, POSE.theta + math.radians(2.5))
    pose = align_map(grid, gt, prior=off)
    assert math.hypot(pose.x - POSE.x, pose.y - POSE.y) <= RES
    assert abs(pose.theta - POSE.theta) <= math.radians(0.4)
    # without a search the prior is kept and the map scores worse
    stuck = evaluate_map(grid, gt, prior=off, search_xy_m=0.0, search_theta_rad=0.0)
    assert (stuck.alignment.x, stuck.alignment.y, stuck.alignment.theta) == (
        off.x,
        off.y,
        off.theta,
    )
    assert stuck.accuracy < evaluate_map(grid, gt, prior=off).accuracy - 0.01
    assert stuck.wall_distance_p95 > 1.0


def test_phantom_walls_lower_accuracy_and_raise_the_wall_distance(gt: GroundTruth) -> None:
    grid = _slam_map(gt, SE2())
    base = evaluate_map(grid, gt, search_xy_m=0.0, search_theta_rad=0.0)
    data = grid.data.copy()
    # a 10 x 10 block of phantom obstacles from world (0.5, 0.5) to (1.0, 1.0)
    r = int((0.5 - grid.origin_xy[1]) / RES)
    c = int((0.5 - grid.origin_xy[0]) / RES)
    data[r : r + 10, c : c + 10] = 100
    bad = evaluate_map(
        OccupancyMapLike(data, grid.origin_xy, RES), gt, search_xy_m=0.0, search_theta_rad=0.0
    )
    wrong_before = (1 - base.accuracy) * base.known_cells
    wrong_after = (1 - bad.accuracy) * bad.known_cells
    assert wrong_after - wrong_before == pytest.approx(100, abs=0.5)
    assert bad.occupied_cells == base.occupied_cells + 100
    # its far corner cell (0.525, 0.525) is 1.31 m (26 cells) from the partition's corner
    # (1.45, 1.45) and 1.475 m from the south wall's face
    assert 25.5 <= bad.wall_distance_max <= 28.0
    assert bad.wall_distance_p95 > base.wall_distance_p95


def test_tolerance_band_is_one_cell_either_side_of_a_wall_face(gt: GroundTruth) -> None:
    """Free cells on a wall's outer cell pass, a free cell two cells inside a 0.4 m box
    fails; an occupied cell one cell off a wall passes, two cells off fails."""
    truth = gt.occupied
    data = np.full(truth.shape, -1, dtype=np.int8)
    grid = OccupancyMapLike(data, gt.origin_xy, RES)
    # the pillar box at (-0.8, 1.8): its centre cell is deep inside
    col = int((-0.8 - gt.origin_xy[0]) / RES)
    row = int((1.8 - gt.origin_xy[1]) / RES)
    assert truth[row - 2 : row + 3, col - 2 : col + 3].all()
    data[10, 10] = 0  # far outside the room: free, correct
    data[row, col] = 0  # deep inside the box: wrong
    # the south wall's inner face: walls run along y = -1 (+-0.05)
    face = int(np.nonzero(truth[:, int((1.0 - gt.origin_xy[0]) / RES)])[0].max())
    fc = int((1.0 - gt.origin_xy[0]) / RES)
    data[face, fc] = 0  # free label on the wall's last cell: within the band
    data[face + 1, fc + 3] = 100  # occupied one cell off the wall: within the band
    data[face + 2, fc + 6] = 100  # two cells off: wrong
    q = evaluate_map(grid, gt, search_xy_m=0.0, search_theta_rad=0.0)
    assert q.known_cells == 5
    assert q.accuracy == pytest.approx(3 / 5)
    assert q.free_accuracy == pytest.approx(2 / 3)
    assert q.occupied_accuracy == pytest.approx(1 / 2)
    assert q.strict_accuracy == pytest.approx(1 / 5)
    assert q.wall_distance_max == pytest.approx(2.0)


def test_coverage_counts_the_reachable_free_cells_the_map_knows(gt: GroundTruth) -> None:
    half = evaluate_map(_slam_map(gt, SE2(), keep=0.5), gt, search_xy_m=0.0, search_theta_rad=0.0)
    assert 0.4 < half.coverage < 0.6
    assert half.accuracy > 0.995


def test_overlay_png(gt: GroundTruth, tmp_path: Path) -> None:
    grid = _slam_map(gt, POSE)
    data = grid.data.copy()
    data[100:104, 100:104] = 100  # map origin (0, 0): world POSE, in the middle of the room
    grid = OccupancyMapLike(data, grid.origin_xy, RES)
    q = evaluate_map(grid, gt, prior=POSE)
    out = write_overlay_png(tmp_path / "overlay.png", grid, gt, q.alignment, scale=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["overlay.png"]
    with Image.open(out) as im:
        assert im.size == (gt.occupied.shape[1] * 2, gt.occupied.shape[0] * 2)
        px = np.asarray(im.convert("RGB")).reshape(-1, 3)
    colours = {tuple(int(v) for v in p) for p in np.unique(px, axis=0)}
    assert {(90, 90, 90), (0, 170, 0), (230, 0, 0), (170, 210, 255)} <= colours
    with pytest.raises(MapQualityError, match="cannot write"):
        write_overlay_png(tmp_path / "no" / "such.png", grid, gt, q.alignment)
    with pytest.raises(MapQualityError, match="scale"):
        write_overlay_png(tmp_path / "x.png", grid, gt, q.alignment, scale=0)


def test_grid_from_msg_round_trip_and_errors() -> None:
    arr: NDArray[np.int8] = np.array([[-1, 0, 100], [0, 0, 50]], dtype=np.int8)
    msg = array_to_occupancy_grid(arr, resolution=0.1, origin=(-1.0, 2.0, 0.0))
    grid = grid_from_msg(msg)
    assert np.array_equal(grid.data, arr)
    assert grid.origin_xy == (-1.0, 2.0) and grid.resolution == pytest.approx(0.1)
    rotated = array_to_occupancy_grid(arr, resolution=0.1, origin=(0.0, 0.0, 0.3))
    with pytest.raises(MapQualityError, match="rotated"):
        grid_from_msg(rotated)
    with pytest.raises(MapQualityError, match="2-D"):
        OccupancyMapLike(np.zeros(4, dtype=np.int8), (0.0, 0.0), 0.1)
    with pytest.raises(MapQualityError, match="resolution"):
        OccupancyMapLike(arr, (0.0, 0.0), 0.0)


def test_bad_inputs_are_clear_errors(gt: GroundTruth) -> None:
    unknown = OccupancyMapLike(np.full((5, 5), -1, dtype=np.int8), (0.0, 0.0), RES)
    with pytest.raises(MapQualityError, match="nothing to align"):
        evaluate_map(unknown, gt)
    grid = _slam_map(gt, SE2())
    with pytest.raises(MapQualityError, match="free_threshold"):
        evaluate_map(grid, gt, occupied_threshold=20, free_threshold=30)
    with pytest.raises(MapQualityError, match="resolution"):
        ground_truth(WORLD, resolution=-1.0, z_m=0.2)
    with pytest.raises(MapQualityError, match="nothing solid"):
        ground_truth(WORLD, resolution=RES, z_m=5.0)


def test_a_non_finite_prior_or_search_window_is_an_error() -> None:
    grid = OccupancyMapLike(data=np.array([[0, 100]], dtype=np.int8), origin_xy=(0.0, 0.0),
                            resolution=0.05)  # fmt: skip
    gt = GroundTruth(occupied=np.array([[False, True]]), origin_xy=(0.0, 0.0), resolution=0.05)
    with pytest.raises(MapQualityError, match="prior pose must be finite"):
        align_map(grid, gt, prior=SE2(math.nan, 0.0, 0.0))
    with pytest.raises(MapQualityError, match="search windows must be >= 0"):
        align_map(grid, gt, search_xy_m=math.nan)
