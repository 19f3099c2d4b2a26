"""hector_mapping: parameters, grid updates, the bilinear matcher, tracking, real logs."""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from PIL import Image

from roverlab.geometry import SE2
from roverlab.raycast import Scene, cast_2d
from roverlab.slam.data import evaluate, iter_log, read_relations
from roverlab.slam.hector import (
    NODE_PARAMETERS,
    HectorInputError,
    HectorMap,
    HectorParams,
    HectorParamsError,
    HectorSLAM,
    MultiResGrid,
    OutOfMapError,
    cost,
    interpolate,
    normal_equations,
    prob_to_log_odds,
    run_log,
)
from tests.slam.synthetic import scan_record

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "radish"

# A hector matcher without roverlab's additions (pre-searches, damping, more iterations).
PLAIN_HECTOR = {
    "scan_match_angle_search": 0.0,
    "scan_match_translation_search": 0.0,
    "scan_match_damping": False,
    "scan_match_iterations_coarse": 4,
    "scan_match_iterations_fine": 6,
}

# ------------------------------------------------------------------ synthetic world

ROOM = np.array(
    [
        # outer walls of a 10 m x 8 m room
        [0.0, 0.0, 10.0, 0.0],
        [10.0, 0.0, 10.0, 8.0],
        [10.0, 8.0, 0.0, 8.0],
        [0.0, 8.0, 0.0, 0.0],
        # a stub wall, a central box, a pillar and a cupboard
        [6.0, 0.0, 6.0, 1.2],
        [4.3, 3.3, 5.7, 3.3],
        [5.7, 3.3, 5.7, 4.7],
        [5.7, 4.7, 4.3, 4.7],
        [4.3, 4.7, 4.3, 3.3],
        [8.8, 6.8, 9.2, 6.8],
        [9.2, 6.8, 9.2, 7.2],
        [9.2, 7.2, 8.8, 7.2],
        [8.8, 7.2, 8.8, 6.8],
        [1.0, 6.8, 2.0, 6.8],
        [2.0, 6.8, 2.0, 7.4],
        [2.0, 7.4, 1.0, 7.4],
    ]
)
BEAMS = np.radians(np.linspace(-135.0, 135.0, 541))  # a 270 degree, 0.5 degree lidar
RANGE_MAX = 30.0


def _scene() -> Scene:
    return Scene(segments=ROOM)


def _loop(n: int) -> NDArray[np.float64]:
    """(n, 3) poses on an ellipse around the central box, heading along the path."""
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    x = 5.0 + 3.2 * np.cos(t)
    y = 4.0 + 2.2 * np.sin(t)
    heading = np.arctan2(2.2 * np.cos(t), -3.2 * np.sin(t))
    return np.stack([x, y, heading], axis=1)


def _scan(
    scene: Scene, pose: NDArray[np.float64], rng: np.random.Generator, noise_m: float = 0.01
) -> NDArray[np.float64]:
    ranges = cast_2d(scene, pose[0], pose[1], 0.5, pose[2] + BEAMS, RANGE_MAX)
    return ranges + rng.normal(0.0, noise_m, ranges.shape)


def _relative_to_first(poses: NDArray[np.float64]) -> NDArray[np.float64]:
    first = SE2(*poses[0])
    return np.array([(~first * SE2(*p)).as_array() for p in poses])


def _pose_errors(
    est: NDArray[np.float64], truth: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    d = est - truth
    return np.hypot(d[:, 0], d[:, 1]), np.abs((d[:, 2] + np.pi) % (2 * np.pi) - np.pi)


def _save_png(
    path: Path, grid: HectorMap, paths: list[tuple[NDArray[np.float64], tuple[int, int, int]]]
) -> NDArray[np.uint8]:
    """The map (unknown grey, free white, occupied black) with poses drawn, cropped."""
    img = np.full(grid.data.shape, 128, np.uint8)
    img[grid.data == 0] = 255
    img[grid.data == 100] = 0
    rgb = np.repeat(img[:, :, None], 3, axis=2)
    for poses, colour in paths:
        for x, y, _ in poses:
            c, r = grid.world_to_cell(float(x), float(y))
            rgb[max(r - 1, 0) : r + 2, max(c - 1, 0) : c + 2] = colour
    rows, cols = np.nonzero(grid.data >= 0)
    crop = rgb[rows.min() : rows.max() + 1, cols.min() : cols.max() + 1][::-1]
    Image.fromarray(np.ascontiguousarray(crop)).save(path)
    return crop


# ------------------------------------------------------------------ parameters


def test_defaults_are_hector_mappings() -> None:
    p = HectorParams()
    assert (p.map_resolution, p.map_size, p.map_start_x, p.map_start_y) == (0.025, 1024, 0.5, 0.5)
    assert p.map_multi_res_levels == 3
    assert (p.update_factor_free, p.update_factor_occupied) == (0.4, 0.9)
    assert (p.map_update_distance_thresh, p.map_update_angle_thresh) == (0.4, 0.9)
    assert (p.laser_min_dist, p.laser_max_dist) == (0.4, 30.0)
    assert (p.laser_z_min_value, p.laser_z_max_value) == (-1.0, 1.0)
    assert not p.use_odometry and not p.map_with_known_poses
    assert p.motion_prediction == "constant_velocity"  # roverlab's default (hector: constant_pose)
    assert [p.level_resolution(i) for i in range(3)] == [0.025, 0.05, 0.1]
    assert [p.level_size(i) for i in range(3)] == [1024, 512, 256]


def test_from_ros_takes_a_launch_files_params() -> None:
    # the <param> set of the seed's hector.launch, values as roslaunch types them
    launch = {
        "pub_map_odom_transform": True,
        "map_frame": "map",
        "base_frame": "base_footprint",
        "odom_frame": "odom",
        "use_tf_scan_transformation": True,
        "use_tf_pose_start_estimate": False,
        "map_resolution": 0.05,
        "map_size": 2048,
        "map_start_x": 0.5,
        "map_start_y": 0.5,
        "laser_z_min_value": -1.0,
        "laser_z_max_value": 1.0,
        "map_multi_res_levels": 2,
        "map_pub_period": 2,
        "laser_min_dist": 0.4,
        "laser_max_dist": 5.5,
        "output_timing": False,
        "pub_map_scanmatch_transform": True,
        "update_factor_free": 0.4,
        "update_factor_occupied": 0.7,
        "map_update_distance_thresh": 0.2,
        "map_update_angle_thresh": 0.06,
        "advertise_map_service": True,
        "scan_subscriber_queue_size": 5,
        "scan_topic": "scan",
    }
    p = HectorParams.from_ros(launch)
    assert (p.map_resolution, p.map_size, p.map_multi_res_levels) == (0.05, 2048, 2)
    assert (p.update_factor_occupied, p.laser_max_dist) == (0.7, 5.5)
    assert (p.map_update_distance_thresh, p.map_update_angle_thresh) == (0.2, 0.06)
    assert "map_pub_period" in NODE_PARAMETERS
    assert HectorParams.from_ros({"map_start_x": 1}).map_start_x == 1.0  # int for a float
    with pytest.raises(HectorParamsError, match="map_resolutoin"):
        HectorParams.from_ros({"map_resolutoin": 0.05})


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("map_resolution", 0.0),
        ("map_resolution", math.nan),
        ("map_size", 10.5),
        ("map_size", 16),  # too small for 3 levels
        ("map_start_x", 1.5),
        ("map_multi_res_levels", 0),
        ("update_factor_free", 1.0),
        ("update_factor_occupied", 0.0),
        ("map_update_distance_thresh", -0.1),
        ("laser_max_dist", 0.3),  # below laser_min_dist
        ("laser_z_max_value", -2.0),
        ("use_odometry", 1),
        ("motion_prediction", "kalman"),
        ("scan_match_angle_search_step", 0.0),
        ("revisit_search", -1.0),
        ("revisit_fit_ratio", 0.0),
        ("revisit_confirmations", 0),
    ],
)
def test_bad_parameters_are_rejected(field: str, value: object) -> None:
    with pytest.raises(HectorParamsError, match=field):
        HectorParams(**{field: value})  # type: ignore[arg-type]


# ------------------------------------------------------------------ grid updates


def test_one_beam_marks_free_cells_and_an_occupied_end() -> None:
    p = HectorParams(map_resolution=0.1, map_size=64, map_multi_res_levels=2)
    grid = MultiResGrid(p)
    grid.update(np.zeros(3), np.zeros(2), np.array([[1.0, 0.0]]))  # 10 cells along +x
    lo = grid.level_view(0, "logodds")
    cx, cy = 32, 32  # the start, at map_start 0.5
    free, occ = prob_to_log_odds(0.4), prob_to_log_odds(0.9)
    assert free == pytest.approx(math.log(0.4 / 0.6))
    assert occ == pytest.approx(math.log(0.9 / 0.1))
    np.testing.assert_allclose(lo[cy, cx : cx + 10], free, rtol=1e-6)
    assert lo[cy, cx + 10] == pytest.approx(occ, rel=1e-6)
    assert np.count_nonzero(lo) == 11
    prob = grid.level_view(0, "prob")
    assert prob[cy, cx + 10] == pytest.approx(0.9, rel=1e-6)
    assert prob[cy, cx] == pytest.approx(0.4, rel=1e-6)
    assert prob[0, 0] == 0.5  # unknown
    # the coarse level got the same beam at its own resolution: 5 cells
    lo1 = grid.level_view(1, "logodds")
    assert np.count_nonzero(lo1) == 6 and lo1[16, 21] == pytest.approx(occ, rel=1e-6)
    # the occupancy grid: -1 unknown, 0 free, 100 occupied, with a consistent origin
    m = grid.occupancy(0)
    assert m.data[cy, cx + 10] == 100 and m.data[cy, cx + 3] == 0 and m.data[0, 0] == -1
    assert m.world_to_cell(1.0, 0.0) == (cx + 10, cy)
    assert m.world_to_cell(0.0, 0.0) == (cx, cy)


def test_a_cell_changes_once_per_scan_and_a_hit_beats_a_pass() -> None:
    p = HectorParams(map_resolution=0.1, map_size=64, map_multi_res_levels=1)
    grid = MultiResGrid(p)
    free, occ = prob_to_log_odds(0.4), prob_to_log_odds(0.9)
    # two beams along +x: the short one ends in a cell the long one passes through
    grid.update(np.zeros(3), np.zeros(2), np.array([[2.0, 0.0], [0.5, 0.0], [2.0, 0.0]]))
    lo = grid.level_view(0, "logodds")
    assert lo[32, 32 + 5] == pytest.approx(occ, rel=1e-6)  # hit wins, no free on top
    assert lo[32, 32 + 2] == pytest.approx(free, rel=1e-6)  # passed 3 times, counted once
    assert lo[32, 32 + 20] == pytest.approx(occ, rel=1e-6)  # hit twice, counted once
    # a second scan adds evidence again
    grid.update(np.zeros(3), np.zeros(2), np.array([[2.0, 0.0]]))
    assert lo[32, 32 + 2] == pytest.approx(2 * free, rel=1e-6)
    assert lo[32, 32 + 5] == pytest.approx(occ + free, rel=1e-6)
    assert lo[32, 32 + 20] == pytest.approx(2 * occ, rel=1e-6)
    assert grid.updates == 2


def test_beams_ending_outside_the_map_are_skipped() -> None:
    p = HectorParams(map_resolution=0.1, map_size=64, map_multi_res_levels=1)
    grid = MultiResGrid(p)
    grid.update(np.zeros(3), np.zeros(2), np.array([[10.0, 0.0]]))  # 100 cells: outside
    assert not np.any(grid.logodds)


# ------------------------------------------------------------------ the matcher


def test_bilinear_value_and_gradient_match_finite_differences() -> None:
    rng = np.random.default_rng(1)
    prob = rng.uniform(0.0, 1.0, (12, 12)).astype(np.float32)
    # at cell centres the value is the cell's
    centres = np.array([[3.0, 4.0], [7.0, 2.0]])
    np.testing.assert_allclose(interpolate(prob, centres)[:, 0], [prob[4, 3], prob[2, 7]])
    # inside cells, the gradient is the derivative of the bilinear value
    coords = np.floor(rng.uniform(0.0, 10.0, (50, 2))) + rng.uniform(0.05, 0.95, (50, 2))
    eps = 1e-5
    out = interpolate(prob, coords)
    ex = np.array([eps, 0.0])
    ey = np.array([0.0, eps])
    dx = (interpolate(prob, coords + ex)[:, 0] - interpolate(prob, coords - ex)[:, 0]) / (2 * eps)
    dy = (interpolate(prob, coords + ey)[:, 0] - interpolate(prob, coords - ey)[:, 0]) / (2 * eps)
    np.testing.assert_allclose(out[:, 1], dx, atol=1e-6)
    np.testing.assert_allclose(out[:, 2], dy, atol=1e-6)
    assert np.all(np.abs(out[:, 1]) + np.abs(out[:, 2]) > 0)  # not a vacuous comparison
    # outside the map: nothing
    np.testing.assert_array_equal(interpolate(prob, np.array([[-1.0, 3.0], [11.5, 3.0]])), 0.0)


def test_gauss_newton_terms_are_the_costs_derivatives() -> None:
    rng = np.random.default_rng(2)
    prob = rng.uniform(0.0, 1.0, (40, 40)).astype(np.float32)
    points = rng.uniform(-0.5, 0.5, (30, 2))  # metres, 20 cells per metre below
    pose = (20.3, 19.6, 0.4)
    total, h, g = normal_equations(prob, points, pose, cells_per_m=20.0)
    assert total == pytest.approx(cost(prob, points, pose, cells_per_m=20.0))
    eps = np.array([1e-5, 1e-5, 1e-7])
    numeric = []
    for a in range(3):
        step = np.zeros(3)
        step[a] = eps[a]
        hi = cost(prob, points, tuple(np.add(pose, step)), cells_per_m=20.0)
        lo = cost(prob, points, tuple(np.subtract(pose, step)), cells_per_m=20.0)
        numeric.append((hi - lo) / (2 * eps[a]))
    np.testing.assert_allclose(-2.0 * g, numeric, rtol=1e-3, atol=1e-3)
    np.testing.assert_allclose(h, h.T)
    assert np.all(np.linalg.eigvalsh(h) >= -1e-9)


@pytest.fixture(scope="module")
def room_map() -> HectorSLAM:
    """A hector map of the room built from the true poses (no matching)."""
    rng = np.random.default_rng(3)
    scene = _scene()
    slam = HectorSLAM(HectorParams(map_with_known_poses=True))
    for pose in _loop(120)[::6]:
        slam.process(_scan(scene, pose, rng), BEAMS, pose)
    return slam


@pytest.mark.parametrize(
    ("offset", "params"),
    [
        ((0.15, -0.1, 0.12), {}),  # beyond a finest cell and a few degrees off
        ((-0.2, 0.2, -0.25), {}),
        ((0.04, -0.03, 0.03), PLAIN_HECTOR),  # hector's plain Gauss-Newton, near start
    ],
)
def test_matcher_converges_from_a_perturbed_start(
    room_map: HectorSLAM, offset: tuple[float, float, float], params: dict[str, object]
) -> None:
    rng = np.random.default_rng(4)
    scene = _scene()
    slam = HectorSLAM(replace(room_map.params, **params))  # type: ignore[arg-type]
    slam.grid = room_map.grid
    for truth in _loop(40)[[3, 17, 29]]:
        ranges = _scan(scene, truth, rng)
        start = SE2(*(truth + np.array(offset)))
        est = slam.match_scan(ranges, BEAMS, start).as_array()
        err_xy, err_th = _pose_errors(est[None], truth[None])
        assert err_xy[0] < 0.02 and err_th[0] < 0.005, (truth, est)


def test_plain_gauss_newton_needs_the_pre_search_for_large_turns(room_map: HectorSLAM) -> None:
    rng = np.random.default_rng(5)
    truth = _loop(40)[11]
    ranges = _scan(_scene(), truth, rng)
    start = SE2(*(truth + np.array([0.0, 0.0, 0.28])))
    plain = HectorSLAM(replace(room_map.params, **PLAIN_HECTOR))  # type: ignore[arg-type]
    plain.grid = room_map.grid
    full = HectorSLAM(room_map.params)
    full.grid = room_map.grid
    est_full = full.match_scan(ranges, BEAMS, start).as_array()
    est_plain = plain.match_scan(ranges, BEAMS, start).as_array()
    assert _pose_errors(est_full[None], truth[None])[1][0] < 0.005
    assert _pose_errors(est_plain[None], truth[None])[1][0] > 0.05


# ------------------------------------------------------------------ tracking


@pytest.fixture(scope="module")
def tracked() -> tuple[HectorSLAM, NDArray[np.float64], NDArray[np.float64]]:
    """One loop around the room without odometry: (slam, estimates, truth in map frame)."""
    rng = np.random.default_rng(6)
    scene = _scene()
    truth = _loop(360)
    slam = HectorSLAM()
    est = np.array([slam.process(_scan(scene, p, rng), BEAMS).as_array() for p in truth])
    return slam, est, _relative_to_first(truth)


def test_tracks_the_true_trajectory_without_odometry(
    tracked: tuple[HectorSLAM, NDArray[np.float64], NDArray[np.float64]],
) -> None:
    slam, est, truth = tracked
    err_xy, err_th = _pose_errors(est, truth)
    assert err_xy.max() < 0.04, err_xy.max()
    assert np.median(err_xy) < 0.015
    assert err_th.max() < 0.01
    assert slam.scans_processed == len(truth)
    # the loop is 17 m: updated every 0.4 m, or 0.9 rad of turn
    assert 30 <= slam.map_updates <= 60


def test_the_map_has_the_rooms_walls(
    tracked: tuple[HectorSLAM, NDArray[np.float64], NDArray[np.float64]], tmp_path: Path
) -> None:
    slam, est, truth = tracked
    grid = slam.occupancy()
    assert grid.data.dtype == np.int8 and grid.data.shape == (1024, 1024)
    assert grid.resolution == 0.025
    first = ~SE2(*_loop(360)[0])  # world -> map frame
    # points along the outer walls: an occupied cell within one cell of each
    s = np.linspace(0.02, 0.98, 200)[:, None]
    walls = np.concatenate([(1 - s) * seg[:2] + s * seg[2:] for seg in ROOM[:4]])
    hits = 0
    for wx, wy in first.apply(walls):
        c, r = grid.world_to_cell(wx, wy)
        hits += bool(np.any(grid.data[r - 1 : r + 2, c - 1 : c + 2] == 100))
    assert hits / len(walls) > 0.9
    # the robot's path is free, the box in the middle is not
    path_cells = [grid.world_to_cell(x, y) for x, y, _ in truth]
    assert all(grid.data[r, c] == 0 for c, r in path_cells)
    c, r = grid.world_to_cell(*first.apply([[4.3, 4.0]])[0])
    assert np.any(grid.data[r - 1 : r + 2, c - 1 : c + 2] == 100)
    # far outside the room nothing was seen
    c, r = grid.world_to_cell(*first.apply([[-3.0, -3.0]])[0])
    assert grid.data[r, c] == -1
    png = tmp_path / "hector_room.png"
    img = _save_png(png, grid, [(truth, (0, 200, 0)), (est, (255, 0, 0))])
    assert png.stat().st_size > 0 and Image.open(png).size == (img.shape[1], img.shape[0])
    # the room is 10 m x 8 m (turned by the first heading, 90 degrees): the seen part of
    # the map is about that, in cells of 2.5 cm
    assert 390 <= img.shape[0] <= 440 and 310 <= img.shape[1] <= 360


def test_runs_are_deterministic() -> None:
    rng = np.random.default_rng(7)
    scene = _scene()
    scans = [_scan(scene, p, rng) for p in _loop(200)[:60]]
    a = [HectorSLAM().process(r, BEAMS) for r in scans[:1]]
    runs = []
    for _ in range(2):
        slam = HectorSLAM()
        runs.append(np.array([slam.process(r, BEAMS).as_array() for r in scans]))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert a[0] == SE2()  # the first scan defines the map frame


def _count_updates(poses: NDArray[np.float64], dist: float, angle: float) -> int:
    last = poses[0]
    count = 1
    for p in poses[1:]:
        dth = abs((p[2] - last[2] + np.pi) % (2 * np.pi) - np.pi)
        if math.hypot(p[0] - last[0], p[1] - last[1]) > dist or dth > angle:
            last = p
            count += 1
    return count


@pytest.mark.parametrize(("dist", "angle"), [(0.4, 0.9), (0.2, 0.06), (1.0, 3.0)])
def test_map_updates_follow_the_thresholds(dist: float, angle: float) -> None:
    rng = np.random.default_rng(8)
    scene = _scene()
    # drive 2.34 m along the bottom in 6 cm steps, then turn in place by 1.5 rad
    drive = np.array([[2.0 + 0.06 * k, 2.0, 0.0] for k in range(40)])
    turn = np.array([[drive[-1, 0], 2.0, 0.05 * k] for k in range(1, 31)])
    params = HectorParams(map_update_distance_thresh=dist, map_update_angle_thresh=angle)
    slam = HectorSLAM(params)
    est = np.array(
        [slam.process(_scan(scene, p, rng), BEAMS).as_array() for p in np.vstack([drive, turn])]
    )
    expected = _count_updates(est, dist, angle)
    assert slam.map_updates == expected
    ideal = _count_updates(np.vstack([drive, turn]), dist, angle)
    assert abs(expected - ideal) <= 1
    assert {(0.4, 0.9): 7, (0.2, 0.06): 25, (1.0, 3.0): 3}[(dist, angle)] == ideal


def test_standing_still_updates_the_map_once() -> None:
    rng = np.random.default_rng(9)
    scene = _scene()
    pose = np.array([2.0, 2.0, 0.3])
    slam = HectorSLAM()
    for _ in range(20):
        est = slam.process(_scan(scene, pose, rng), BEAMS)
    assert slam.map_updates == 1
    assert math.hypot(est.x, est.y) < 0.01 and abs(est.theta) < 0.003


def test_prediction_modes_without_usable_beams() -> None:
    # beams beyond laser_max_dist leave only the prediction: it shows what each mode uses
    far = np.full(BEAMS.shape, 50.0)
    odom = [SE2(1.0, 2.0, 0.5), SE2(1.1, 2.0, 0.6), SE2(1.3, 2.1, 0.6)]
    hector = HectorSLAM()
    assert [hector.process(far, BEAMS, o) for o in odom] == [SE2()] * 3
    with_odom = HectorSLAM(HectorParams(use_odometry=True))
    poses = [with_odom.process(far, BEAMS, o).as_array() for o in odom]
    expected = [(~odom[0] * o).as_array() for o in odom]
    np.testing.assert_allclose(poses, expected, atol=1e-12)
    with pytest.raises(HectorInputError, match="odom_pose"):
        with_odom.process(far, BEAMS)
    known = HectorSLAM(HectorParams(map_with_known_poses=True))
    np.testing.assert_allclose(
        [known.process(far, BEAMS, o).as_array() for o in odom], [o.as_array() for o in odom]
    )


def test_constant_velocity_prediction_repeats_the_last_motion() -> None:
    rng = np.random.default_rng(10)
    scene = _scene()
    far = np.full(BEAMS.shape, 50.0)
    slam = HectorSLAM(HectorParams(motion_prediction="constant_velocity"))
    truth = _loop(300)[:3]
    first = SE2(*truth[0])
    slam.process(_scan(scene, truth[0], rng), BEAMS)
    moved = slam.process(_scan(scene, truth[1], rng), BEAMS).as_array()
    np.testing.assert_allclose(moved[:2], (~first * SE2(*truth[1])).as_array()[:2], atol=0.02)
    coasted = slam.process(far, BEAMS).as_array()  # no beams: the motion is repeated
    step = ~SE2(0.0, 0.0, 0.0) * SE2(*moved)
    np.testing.assert_allclose(coasted, (SE2(*moved) * step).as_array(), atol=1e-12)


def test_leaving_the_map_is_a_clear_error() -> None:
    params = HectorParams(map_with_known_poses=True, map_size=64, map_resolution=0.05)
    slam = HectorSLAM(params)  # 3.2 m across, the start in the middle
    ranges = np.full(BEAMS.shape, 1.0)
    slam.process(ranges, BEAMS, (1.0, 0.0, 0.0))
    with pytest.raises(OutOfMapError, match=r"left the map .* increase map_size"):
        slam.process(ranges, BEAMS, (1.7, 0.0, 0.0))
    assert slam.pose == SE2(1.0, 0.0, 0.0)  # the failed scan changed nothing


def _occupied_world_points(grid: MultiResGrid, level: int) -> set[tuple[int, int]]:
    """Occupied cells of ``level`` as world coordinates in millimetres."""
    m = grid.occupancy(level)
    iy, ix = np.nonzero(m.data == 100)
    x = m.origin[0] + (ix + 0.5) * m.resolution
    y = m.origin[1] + (iy + 0.5) * m.resolution
    return set(zip(np.round(x * 1000).astype(int), np.round(y * 1000).astype(int), strict=True))


def test_growing_the_grid_keeps_every_cell_where_it_is_in_the_world() -> None:
    params = HectorParams(map_size=128, map_resolution=0.05, map_start_x=0.3, map_start_y=0.6)
    grid = MultiResGrid(params)
    rng = np.random.default_rng(3)
    grid.update(np.array([0.5, -0.4, 0.3]), np.zeros(2), rng.uniform(-2.5, 2.5, (200, 2)))
    before = [_occupied_world_points(grid, level) for level in range(3)]
    probs = [grid.level_view(level).copy() for level in range(3)]
    x0, y0, x1, y1 = grid.extent()
    grid.grow()
    assert list(grid.sizes) == [256, 128, 64]
    assert [_occupied_world_points(grid, level) for level in range(3)] == before
    assert all(before)  # the scan marked cells on every level
    nx0, ny0, nx1, ny1 = grid.extent()
    w, h = x1 - x0, y1 - y0
    assert (nx0, ny0, nx1, ny1) == pytest.approx((x0 - w / 2, y0 - h / 2, x1 + w / 2, y1 + h / 2))
    for level, old in enumerate(probs):  # the old square in the middle, unknown around it
        n = old.shape[0]
        new = grid.level_view(level)
        np.testing.assert_array_equal(new[n // 2 : n // 2 + n, n // 2 : n // 2 + n], old)
        assert np.count_nonzero(new != 0.5) == np.count_nonzero(old != 0.5)


def test_a_growing_map_follows_the_robot_beyond_its_first_size() -> None:
    rng = np.random.default_rng(6)
    scene = _scene()
    truth = _loop(360)
    small = HectorParams(map_size=64, map_resolution=0.05)  # 3.2 m, the room is 10 m x 8 m
    with pytest.raises(OutOfMapError, match="increase map_size"):
        fixed = HectorSLAM(small)
        for p in truth:
            fixed.process(_scan(scene, p, rng), BEAMS)
    rng = np.random.default_rng(6)
    slam = HectorSLAM(small, grow_max_size=1024)
    est = np.array([slam.process(_scan(scene, p, rng), BEAMS).as_array() for p in truth])
    assert int(slam.grid.sizes[0]) == 512  # 25.6 m: holds the 10 m room seen from either end
    err_xy, err_th = _pose_errors(est, _relative_to_first(truth))
    assert err_xy.max() < 0.05 and err_th.max() < 0.015, (err_xy.max(), err_th.max())
    capped = HectorSLAM(small, grow_max_size=128)
    with pytest.raises(OutOfMapError, match="cannot grow beyond 128 cells"):
        for p in truth:
            capped.process(_scan(scene, p, rng), BEAMS)


def test_input_errors() -> None:
    slam = HectorSLAM()
    with pytest.raises(HectorInputError, match="angles"):
        slam.process(np.ones(10), np.zeros(9))
    with pytest.raises(HectorInputError, match="finite"):
        slam.process(np.ones(3), np.array([0.0, np.nan, 1.0]))
    with pytest.raises(HectorInputError, match="odom_pose"):
        slam.process(np.ones(3), np.zeros(3), (0.0, np.inf, 0.0))
    with pytest.raises(HectorInputError, match="level"):
        slam.occupancy(3)


def test_beam_filters() -> None:
    slam = HectorSLAM(HectorParams(laser_min_dist=0.5, laser_max_dist=4.0))
    ranges = np.array([0.3, 0.6, 2.0, 3.99, 4.0, np.inf, np.nan, 2.5])
    angles = np.zeros(ranges.size)
    pts = slam.scan_points(ranges, angles, range_min=0.1, range_max=2.2)
    np.testing.assert_allclose(pts[:, 0], [0.6, 2.0])
    pts = slam.scan_points(ranges, angles, laser_offset=SE2(0.2, 0.1, np.pi / 2))
    np.testing.assert_allclose(pts, [[0.2, 0.7], [0.2, 2.1], [0.2, 4.09], [0.2, 2.6]], atol=1e-12)
    # a laser mounted outside [laser_z_min_value, laser_z_max_value] gives nothing
    assert HectorSLAM(laser_z_m=1.5).scan_points(ranges, angles).shape == (0, 2)


def test_run_log_reports_robot_poses_with_a_mounted_laser() -> None:
    rng = np.random.default_rng(11)
    scene = _scene()
    offset = SE2(0.25, -0.05, 0.1)  # laser ahead of the robot, slightly turned
    truth = _loop(300)[:120]
    records = []
    for k, pose in enumerate(truth):
        laser = SE2(*pose) * offset
        ranges = cast_2d(scene, laser.x, laser.y, 0.5, laser.theta + BEAMS, RANGE_MAX)
        ranges = ranges + rng.normal(0.0, 0.01, ranges.shape)
        odom = SE2(*pose)  # odometry is not used by default
        records.append(
            scan_record(
                100.0 + 0.1 * k,
                ranges,
                BEAMS,
                odom,
                range_min=0.0,
                range_max=RANGE_MAX,
                laser_offset=offset,
            )
        )
    poses, grid, trajectory = run_log(records)
    assert poses.shape == (len(truth), 3)
    err_xy, err_th = _pose_errors(poses, _relative_to_first(truth))
    assert err_xy.max() < 0.04 and err_th.max() < 0.01
    assert trajectory.timestamp_texts is not None
    assert trajectory.timestamp_texts[1] == "100.100000"
    np.testing.assert_array_equal(trajectory.poses, poses)
    assert grid.data.shape == (1024, 1024)


# ------------------------------------------------------------------ real logs


def _data(name: str) -> Path:
    path = DATA / name
    if not path.exists():
        pytest.skip(f"shared benchmark data not found at {path}")
    return path


def test_intel_first_1500_scans() -> None:
    log = list(itertools.islice(iter_log(_data("intel.clf.bz2")), 1500))
    relations = read_relations(_data("intel.relations"))
    HectorSLAM().process(log[0].ranges, log[0].angles())  # compile outside the timing
    params = HectorParams(map_size=2048)  # intel is 30 m across: twice hector's default
    start = time.perf_counter()
    slam = HectorSLAM(params)
    run = slam.run_log(log)
    elapsed = time.perf_counter() - start
    metrics = evaluate(run.trajectory, relations)
    assert metrics.matched >= 150
    assert metrics.trans_mean < 0.04, str(metrics)
    assert metrics.rot_mean_deg < 0.5, str(metrics)
    data_s = log[-1].timestamp - log[0].timestamp
    assert elapsed < 20.0 and data_s / elapsed > 20.0, (elapsed, data_s)


def test_intel_default_map_is_too_small_and_says_so() -> None:
    log = iter_log(_data("intel.clf.bz2"))
    slam = HectorSLAM()  # 1024 x 2.5 cm: 25.6 m across
    with pytest.raises(OutOfMapError, match="map_size"):
        slam.run_log(log)
