"""Tests of :mod:`roverlab.slam.gmapping`: slam_gmapping's particle filter.

A synthetic room (exact ranges from :func:`roverlab.raycast.cast_2d`, noise added) driven
twice around with drifting odometry checks the filter end to end; smaller tests pin the
map counting, resampling, seeding and parameter rules; a slice of the Intel lab log checks
it on real data (the whole logs: ``test_real_logs.py``).
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Sequence
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest
from numpy.typing import NDArray
from PIL import Image, ImageDraw

from roverlab.geometry import SE2
from roverlab.raycast import Scene, cast_2d
from roverlab.slam.data import (
    ScanRecord,
    Trajectory,
    evaluate,
    iter_log,
    read_relations,
)
from roverlab.slam.gmapping import (
    GMapping,
    GMappingInputError,
    GMappingMap,
    GMappingParams,
    GMappingParamsError,
    GMappingRun,
    ParticleMaps,
    kernels,
)
from roverlab.slam.gmapping.motion import compose, relative
from tests.slam.synthetic import scan_record

#: ``../shared/data`` relative to the repository root (never copied into the repository).
DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"

# ------------------------------------------------------------------------ synthetic room
# A 12 m x 9 m room with a pillar, two wall stubs and two slanted cabinets.
WALLS = np.array(
    [
        (0.0, 0.0, 12.0, 0.0),
        (12.0, 0.0, 12.0, 9.0),
        (12.0, 9.0, 0.0, 9.0),
        (0.0, 9.0, 0.0, 0.0),
        (3.0, 9.0, 3.0, 7.3),
        (9.0, 0.0, 9.0, 1.6),
        (5.5, 4.0, 6.5, 4.0),
        (6.5, 4.0, 6.5, 5.0),
        (6.5, 5.0, 5.5, 5.0),
        (5.5, 5.0, 5.5, 4.0),
        (10.6, 7.2, 11.6, 8.4),
        (0.0, 4.0, 0.8, 4.6),
    ]
)
LASER_OFFSET = SE2(0.12, 0.0, 0.0)
LASER_Z_M = 0.2
RANGE_MAX_M = 10.0
BEAMS = np.radians(np.arange(-135.0, 135.5, 1.0))  # a 270 degree, 1 degree scanner


class Scenario(NamedTuple):
    records: list[ScanRecord]
    truth: NDArray[np.float64]  # (N, 3) true robot poses
    odom: NDArray[np.float64]  # (N, 3) drifting odometry poses


def _true_path(laps: int) -> NDArray[np.float64]:
    """Drive a 8 m x 4 m rectangle counter-clockwise, turning on the spot at corners."""
    corners = [(2.0, 2.5), (10.0, 2.5), (10.0, 6.5), (2.0, 6.5)]
    poses = [np.array([2.0, 2.5, 0.0])]
    for _ in range(laps):
        for k in range(4):
            x0, y0 = corners[k]
            x1, y1 = corners[(k + 1) % 4]
            heading = math.atan2(y1 - y0, x1 - x0)
            length = math.hypot(x1 - x0, y1 - y0)
            for s in np.arange(0.1, length + 1e-9, 0.1):
                poses.append(
                    np.array([x0 + s * math.cos(heading), y0 + s * math.sin(heading), heading])
                )
            turn = 0.0
            while turn < math.pi / 2 - 1e-9:
                step = min(0.15, math.pi / 2 - turn)
                turn += step
                last = poses[-1]
                poses.append(np.array([last[0], last[1], last[2] + step]))
    out = np.array(poses)
    out[:, 2] = (out[:, 2] + np.pi) % (2 * np.pi) - np.pi
    return out


def _reversing_path() -> NDArray[np.float64]:
    """Forward along y = 2.5 m from x = 2 to 6 m, back to 4.2 m, forward to 10 m."""
    xs = np.concatenate(
        [np.arange(2.0, 6.0, 0.1), np.arange(6.0, 4.2, -0.1), np.arange(4.2, 10.0, 0.1)]
    )
    return np.stack([xs, np.full_like(xs, 2.5), np.zeros_like(xs)], axis=1)


def make_scenario(
    laps: int = 2,
    seed: int = 11,
    *,
    truth: NDArray[np.float64] | None = None,
    reverse_counts_forward: bool = False,
) -> Scenario:
    """Scans of the room along the path, with odometry that over-reads distance by 3 %
    and turns by 5 %, and drifts 0.02 rad per metre; ``reverse_counts_forward`` makes it
    count reversing as driving forward (as the Freiburg 079 log's odometry does)."""
    rng = np.random.default_rng(seed)
    scene = Scene(segments=WALLS)
    truth = _true_path(laps) if truth is None else truth
    odom = np.zeros_like(truth)
    odom[0] = truth[0]
    for k in range(1, len(truth)):
        d = relative(truth[k - 1], truth[k])
        noisy = np.array(
            [
                (abs(d[0]) if reverse_counts_forward else d[0]) * 1.03 + rng.normal(0.0, 0.003),
                d[1] + rng.normal(0.0, 0.003),
                d[2] * 1.05 + 0.02 * abs(d[0]) + rng.normal(0.0, 0.003),
            ]
        )
        odom[k] = compose(odom[k - 1], noisy)
    records = []
    for k, pose in enumerate(truth):
        laser = compose(pose, LASER_OFFSET.as_array())
        r = cast_2d(scene, laser[0], laser[1], LASER_Z_M, BEAMS + laser[2], RANGE_MAX_M)
        r = r + rng.normal(0.0, 0.01, r.shape)
        odom_pose = SE2(*(float(v) for v in odom[k]))
        records.append(
            scan_record(
                0.2 * k,
                r,
                BEAMS,
                odom_pose,
                range_min=0.05,
                range_max=RANGE_MAX_M,
                laser_offset=LASER_OFFSET,
            )
        )
    return Scenario(records, truth, odom)


def room_params(**overrides: float | int) -> GMappingParams:
    base: dict[str, float | int] = {
        "particles": 10,
        "linearUpdate": 0.5,
        "angularUpdate": 0.3,
        "xmin": -2.0,
        "ymin": -2.0,
        "xmax": 14.0,
        "ymax": 11.0,
    }
    base.update(overrides)
    return GMappingParams(**base)  # type: ignore[arg-type]


def position_errors(poses: NDArray[np.float64], truth: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.hypot(poses[:, 0] - truth[:, 0], poses[:, 1] - truth[:, 1])


def cell_of(
    m: GMappingMap, x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    ix = np.floor((x - m.origin_xy[0]) / m.resolution).astype(np.int64)
    iy = np.floor((y - m.origin_xy[1]) / m.resolution).astype(np.int64)
    return ix, iy


def save_map_png(m: GMappingMap, poses: NDArray[np.float64], path: Path) -> None:
    """The map (white free, black occupied, grey unknown) with the trajectory in red."""
    img = np.full(m.data.shape, 128, dtype=np.uint8)
    img[m.data == 0] = 255
    img[m.data == 100] = 0
    rgb = Image.fromarray(img).convert("RGB")
    draw = ImageDraw.Draw(rgb)
    ix, iy = cell_of(m, poses[:, 0], poses[:, 1])
    draw.line([(int(a), int(b)) for a, b in zip(ix, iy, strict=True)], fill=(255, 0, 0), width=1)
    rgb.transpose(Image.Transpose.FLIP_TOP_BOTTOM).save(path)


@pytest.fixture(scope="module")
def room() -> Scenario:
    return make_scenario()


class RoomRun(NamedTuple):
    slam: GMapping
    run: GMappingRun
    seconds: float


@pytest.fixture(scope="module")
def room_run(room: Scenario) -> RoomRun:
    slam = GMapping(room_params(), np.random.default_rng(3))
    t0 = time.perf_counter()
    run = slam.run_log(room.records)
    return RoomRun(slam, run, time.perf_counter() - t0)


# ----------------------------------------------------------------------- end to end
def test_room_trajectory_is_much_closer_to_truth_than_odometry(
    room: Scenario, room_run: RoomRun
) -> None:
    run = room_run.run
    assert run.poses.shape == room.truth.shape
    assert np.array_equal(run.timestamps, [r.timestamp for r in room.records])
    slam_err = position_errors(run.poses, room.truth)
    odom_err = position_errors(room.odom, room.truth)
    assert odom_err.mean() > 0.5  # the odometry really drifts
    assert slam_err.mean() < 0.06
    assert slam_err.max() < 0.25
    assert slam_err.mean() < 0.1 * odom_err.mean()
    heading = np.abs((run.poses[:, 2] - room.truth[:, 2] + np.pi) % (2 * np.pi) - np.pi)
    assert np.degrees(heading.mean()) < 1.5
    assert room_run.slam.updates > 50


def test_room_map_has_the_walls_and_the_free_space(room: Scenario, room_run: RoomRun) -> None:
    m = room_run.run.map
    assert m.resolution == pytest.approx(0.05)
    # The published map covers at least the configured xmin .. ymax box.
    assert m.origin_xy[0] <= -2.0 + 1e-9 and m.origin_xy[1] <= -2.0 + 1e-9
    assert m.origin_xy[0] + m.width * m.resolution >= 14.0 - 1e-9
    # Points along every wall: an occupied cell within one cell of each.
    pts = []
    for x0, y0, x1, y1 in WALLS:
        n = max(2, int(math.hypot(x1 - x0, y1 - y0) / 0.1))
        t = np.linspace(0.05, 0.95, n)
        pts.append(np.stack([x0 + t * (x1 - x0), y0 + t * (y1 - y0)], axis=1))
    wall = np.concatenate(pts)
    ix, iy = cell_of(m, wall[:, 0], wall[:, 1])
    near = np.zeros(len(wall), dtype=bool)
    for dx, dy in itertools.product((-1, 0, 1), repeat=2):
        near |= m.data[iy + dy, ix + dx] == 100
    assert near.mean() > 0.9
    # The cells the robot drove through are free, and few cells far from walls are occupied.
    px, py = cell_of(m, room.truth[:, 0], room.truth[:, 1])
    assert (m.data[py, px] == 0).mean() > 0.97
    inner_x, inner_y = np.meshgrid(np.arange(1.0, 5.0, 0.05), np.arange(1.5, 3.5, 0.05))
    ix, iy = cell_of(m, inner_x.ravel(), inner_y.ravel())
    assert (m.data[iy, ix] == 100).mean() < 0.01
    # Outside the room nothing was seen.
    ix, iy = cell_of(m, np.array([-1.5, 13.5]), np.array([-1.5, 10.5]))
    assert np.all(m.data[iy, ix] == -1)


def test_room_png_with_trajectory(room: Scenario, room_run: RoomRun, tmp_path: Path) -> None:
    path = tmp_path / "room_map.png"
    save_map_png(room_run.run.map, room_run.run.poses, path)
    img = np.asarray(Image.open(path))
    m = room_run.run.map
    assert img.shape == (m.height, m.width, 3)
    red = (img[..., 0] == 255) & (img[..., 1] == 0) & (img[..., 2] == 0)
    black = np.all(img == 0, axis=-1)

    def centres(mask: NDArray[np.bool_]) -> NDArray[np.float64]:
        rows, cols = np.nonzero(mask[::-1])  # the PNG has north up: row 0 is the top
        return np.stack(
            [m.origin_xy[0] + (cols + 0.5) * m.resolution,
             m.origin_xy[1] + (rows + 0.5) * m.resolution], axis=1,
        )  # fmt: skip

    # Against the room's true geometry: the red line follows the true path (the estimate
    # is within 0.25 m of it), the black pixels are the walls (within two cells of one).
    truth = room.truth[:, :2]
    reds = centres(red)
    to_path = np.hypot(*(reds[:, None, :] - truth[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert len(reds) > 200 and np.all(to_path < 0.3)
    along = np.hypot(*(truth[:, None, :] - reds[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert np.mean(along < 0.1) > 0.95  # the whole path is drawn
    blacks = centres(black)
    a, b = WALLS[:, :2], WALLS[:, 2:]
    t = np.clip(
        np.einsum("pwk,wk->pw", blacks[:, None, :] - a[None], b - a) / np.sum((b - a) ** 2, 1),
        0.0, 1.0,
    )  # fmt: skip
    nearest = a[None] + t[..., None] * (b - a)[None]
    to_wall = np.hypot(*(blacks[:, None, :] - nearest).transpose(2, 0, 1)).min(axis=1)
    assert len(blacks) > 500 and np.quantile(to_wall, 0.99) <= 2 * m.resolution


def test_best_particle_and_map_to_odom(room: Scenario, room_run: RoomRun) -> None:
    slam = room_run.slam
    best = slam.best_particle()
    assert best.index == slam.best_index()
    assert best.trajectory.shape == (slam.updates, 3)
    assert best.weight_sum == max(slam.particle(i).weight_sum for i in range(10))
    # The last update pose is the last scan's pose of the run (the run ended on an update
    # or the scans since were propagated by odometry from it).
    last = best.trajectory[-1]
    assert np.hypot(*(last[:2] - room.truth[-1][:2])) < 0.25
    # map -> odom times the odometry at the last update is that update's pose.
    mo = slam.map_to_odom() * slam.update_odom
    assert np.allclose([mo.x, mo.y], last[:2], atol=1e-9)
    assert slam.occupancy(best.index).data.shape == room_run.run.map.data.shape


def test_interpolated_poses_keep_the_update_poses(room: Scenario, room_run: RoomRun) -> None:
    records = room.records[:250]
    fwd = GMapping(room_params(), np.random.default_rng(3)).run_log(records)
    smooth = GMapping(room_params(), np.random.default_rng(3)).run_log(records, interpolate=True)
    same = np.all(fwd.poses == smooth.poses, axis=1)
    # Update scans (and scans after the last update) agree; scans in between differ.
    assert 20 < same.sum() < len(records) - 50
    assert np.array_equal(fwd.map.data, smooth.map.data)
    truth = room.truth[:250]
    assert (
        position_errors(smooth.poses, truth).mean()
        <= position_errors(fwd.poses, truth).mean() + 0.005
    )


def test_recovers_when_odometry_counts_reversing_as_forward() -> None:
    truth = _reversing_path()
    sc = make_scenario(seed=4, truth=truth, reverse_counts_forward=True)
    odom_end = np.hypot(*(sc.odom[-1, :2] - truth[-1, :2]))
    assert odom_end > 3.0  # 1.8 m of reversing counted forward
    params = room_params(linearUpdate=1.0, angularUpdate=0.5)
    on = GMapping(params, np.random.default_rng(2))
    off = GMapping(params, np.random.default_rng(2), recover_odometry_failures=False)
    run_on = on.run_log(sc.records)
    run_off = off.run_log(sc.records)
    assert on.recoveries >= 1 and off.recoveries == 0
    assert np.hypot(*(run_on.poses[-1, :2] - truth[-1, :2])) < 0.1
    assert np.hypot(*(run_off.poses[-1, :2] - truth[-1, :2])) > 0.5


# ------------------------------------------------------------------------ resampling
@pytest.mark.parametrize("threshold", [0.0, 0.5, 1.0])
def test_resampling_happens_only_when_neff_is_below_threshold(
    room: Scenario, threshold: float
) -> None:
    params = room_params(particles=8, resampleThreshold=threshold)
    slam = GMapping(params, np.random.default_rng(5))
    uniform_after_resampling = []
    for rec in room.records[:260]:
        updated = slam.process(
            rec.ranges,
            rec.angle_min + rec.angle_increment * np.arange(rec.ranges.size),
            rec.odom_pose,
            rec.timestamp,
            range_min=rec.range_min,
            range_max=rec.range_max,
            laser_offset=rec.laser_offset,
        )
        if updated and slam.history[-1].resampled:
            uniform_after_resampling.append(np.allclose(slam.weights(), 1.0 / 8))
    weighted = slam.history[1:]  # the first scan only seeds the maps
    assert len(weighted) > 20
    for info in weighted:
        assert info.resampled == (info.neff < threshold * 8)
        assert 1.0 - 1e-9 <= info.neff <= 8.0 + 1e-9
    assert slam.resamples == sum(info.resampled for info in weighted)
    assert all(uniform_after_resampling)
    if threshold == 0.0:
        assert slam.resamples == 0
    if threshold == 1.0:
        assert slam.resamples > 0


def test_particle_maps_resample_copies_in_place() -> None:
    maps = ParticleMaps(4, 0.1, (0.0, 0.0))
    maps.ensure(0.0, 0.0, 1.0, 1.0)
    for i in range(4):
        maps.cells[i] = i + 1
    source = maps.resample(np.array([0, 3, 0, 1]))
    assert sorted(source.tolist()) == [1, 1, 1, 3]
    assert source[1] == 1 and source[3] == 3  # survivors keep their slot
    for j in range(4):
        assert np.all(maps.cells[j] == source[j] + 1)
    with pytest.raises(GMappingInputError):
        maps.resample(np.array([1, 1, 1, 0, 0]))


def test_particle_maps_grow_keeping_cells_in_place() -> None:
    maps = ParticleMaps(2, 0.05, (-100.0, -100.0))
    assert maps.ensure(0.0, 0.0, 1.0, 1.0)
    ox, oy = maps.origin_xy
    ix, iy = int(round((0.52 - ox) / 0.05 - 0.5)), int(round((0.33 - oy) / 0.05 - 0.5))
    maps.cells[1, iy, ix] = (7, 9, 100, 200)
    assert not maps.ensure(0.1, 0.1, 0.9, 0.9)
    assert maps.ensure(-20.0, 0.0, 30.0, 1.0)
    nx, ny = maps.origin_xy
    # Cell boundaries stay on the lattice anchored at (xmin, ymin).
    assert ((nx + 100.0) / 0.05) == pytest.approx(round((nx + 100.0) / 0.05))
    jx, jy = int(round((0.52 - nx) / 0.05 - 0.5)), int(round((0.33 - ny) / 0.05 - 0.5))
    assert tuple(maps.cells[1, jy, jx]) == (7, 9, 100, 200)
    assert int(maps.cells.sum()) == 7 + 9 + 100 + 200
    with pytest.raises(GMappingInputError, match="non-finite"):
        maps.ensure(0.0, 0.0, math.inf, 1.0)


# ------------------------------------------------------------------ map counting rules
def test_register_counts_visits_hits_and_the_mean_hit_point() -> None:
    maps = ParticleMaps(1, 0.1, (0.0, 0.0))
    maps.ensure(0.0, 0.0, 3.0, 1.0)
    ox, oy = maps.origin_xy
    # Two beams along +x from (0.55, 0.55): one ends at x = 1.26 (a hit), one is cropped
    # at the usable range (clears, no hit).
    pose = np.array([[0.55, 0.55, 0.0]])
    ends = np.array([[0.71, 0.0], [1.5, 0.0]])
    kernels.register_all(maps.cells, ox, oy, 0.1, pose, np.zeros(2), ends, np.array([True, False]))
    row = int((0.55 - oy) / 0.1)
    c0 = int((0.55 - ox) / 0.1)
    hit_cell = int((1.26 - ox) / 0.1)
    end_cell = int((2.05 - ox) / 0.1)
    hits = maps.cells[0, row, :, kernels.HITS]
    visits = maps.cells[0, row, :, kernels.VISITS]
    assert hits[hit_cell] == 1 and hits.sum() == 1
    assert np.all(visits[c0:hit_cell] == 2)  # both beams passed through
    assert visits[hit_cell] == 2  # one passed through, one ended (hit) there
    assert np.all(visits[hit_cell + 1 : end_cell] == 1)
    assert visits[end_cell] == 0  # the cropped beam's last cell is not touched
    mean_x = ox + hit_cell * 0.1 + maps.cells[0, row, hit_cell, kernels.MEAN_X] * 0.1 / 65536
    assert mean_x == pytest.approx(1.26, abs=1e-5)
    occ = maps.occupancy(0, occ_thresh=0.25)
    assert occ.data[row, hit_cell] == 100  # 1 / 2 > 0.25
    assert occ.data[row, c0] == 0 and occ.data[row, end_cell] == -1


def test_occupancy_extent_and_message() -> None:
    maps = ParticleMaps(1, 0.05, (-1.0, -1.0))
    maps.ensure(0.0, 0.0, 0.2, 0.2)
    # The explored block (the box plus a growth margin) lies inside the requested extent.
    m = maps.occupancy(0, 0.25, (-10.0, -10.0, 10.0, 10.0))
    assert m.origin_xy == pytest.approx((-10.0, -10.0))
    assert m.data.shape == (400, 400)
    assert np.all(m.data == -1)
    # Without an extent, just the block; with a small one, still the whole block.
    block = maps.occupancy(0, 0.25)
    assert block.data.shape == maps.cells.shape[1:3]
    assert maps.occupancy(0, 0.25, (0.0, 0.0, 0.1, 0.1)).data.shape == block.data.shape
    msg = m.to_msg(frame_id="map")
    assert (msg.info.width, msg.info.height) == (m.width, m.height)
    assert msg.info.resolution == pytest.approx(0.05)


# ----------------------------------------------------------------------- determinism
def test_same_seed_same_result_other_seed_other_result(room: Scenario) -> None:
    records = room.records[:200]
    params = room_params(particles=6)
    a = GMapping(params, np.random.default_rng(7)).run_log(records)
    b = GMapping(params, np.random.default_rng(7)).run_log(records)
    c = GMapping(params, np.random.default_rng(8)).run_log(records)
    assert np.array_equal(a.poses, b.poses)
    assert np.array_equal(a.map.data, b.map.data)
    assert not np.array_equal(a.poses, c.poses)


# ------------------------------------------------------------------- update schedule
def test_updates_only_after_linear_angular_or_temporal_motion() -> None:
    ranges = np.full(90, 2.0)
    angles = np.linspace(-1.5, 1.5, 90)
    slam = GMapping(GMappingParams(particles=2, linearUpdate=1.0, angularUpdate=0.5), 0)
    assert slam.process(ranges, angles, (0.0, 0.0, 0.0), 0.0)  # the first scan seeds
    assert not slam.process(ranges, angles, (0.6, 0.0, 0.0), 1.0)
    assert slam.process(ranges, angles, (1.0, 0.0, 0.0), 2.0)  # 1.0 m travelled
    assert not slam.process(ranges, angles, (1.0, 0.0, 0.3), 3.0)
    assert slam.process(ranges, angles, (1.0, 0.0, 0.0), 4.0)  # 0.6 rad turned (0.3 + 0.3)
    assert slam.updates == 3
    timed = GMapping(GMappingParams(particles=2, temporalUpdate=2.0), 0)
    assert timed.process(ranges, angles, (0.0, 0.0, 0.0), 0.0)
    assert not timed.process(ranges, angles, (0.0, 0.0, 0.0), 1.5)
    assert timed.process(ranges, angles, (0.0, 0.0, 0.0), 2.5)


def test_throttle_scans_drops_scans() -> None:
    ranges = np.full(90, 2.0)
    angles = np.linspace(-1.5, 1.5, 90)
    slam = GMapping(GMappingParams(particles=2, throttle_scans=2, linearUpdate=0.0), 0)
    results = [slam.process(ranges, angles, (0.1 * k, 0.0, 0.0), float(k)) for k in range(6)]
    assert results == [False, True, False, True, False, True]


def test_scan_and_pose_input_errors() -> None:
    slam = GMapping(GMappingParams(particles=2), 0)
    angles = np.linspace(-1.0, 1.0, 10)
    with pytest.raises(GMappingInputError, match="10 ranges but 9 angles"):
        slam.process(np.ones(10), angles[:9], (0.0, 0.0, 0.0), 0.0)
    with pytest.raises(GMappingInputError, match="odom_pose"):
        slam.process(np.ones(10), angles, (0.0, math.nan, 0.0), 0.0)
    with pytest.raises(GMappingInputError, match="odom_pose"):
        slam.process(np.ones(10), angles, (0.0, 0.0), 0.0)
    with pytest.raises(GMappingInputError, match="timestamp"):
        slam.process(np.ones(10), angles, (0.0, 0.0, 0.0), math.inf)
    with pytest.raises(GMappingInputError, match="angles"):
        slam.process(np.ones(10), np.full(10, math.nan), (0.0, 0.0, 0.0), 0.0)
    with pytest.raises(GMappingInputError, match="no particle"):
        slam.trajectory(5)
    # Bad readings are dropped, not errors.
    assert slam.process(
        np.array([math.nan, -1.0, 0.0, math.inf] + [1.0] * 6), angles, (0, 0, 0), 0.0
    )


# ------------------------------------------------------------------------ parameters
ROS_WIKI_DEFAULTS = {
    "throttle_scans": 1,
    "base_frame": "base_link",
    "map_frame": "map",
    "odom_frame": "odom",
    "map_update_interval": 5.0,
    "maxRange": None,
    "maxUrange": 80.0,
    "sigma": 0.05,
    "kernelSize": 1,
    "lstep": 0.05,
    "astep": 0.05,
    "iterations": 5,
    "lsigma": 0.075,
    "ogain": 3.0,
    "lskip": 0,
    "minimumScore": 0.0,
    "srr": 0.1,
    "srt": 0.2,
    "str": 0.1,
    "stt": 0.2,
    "linearUpdate": 1.0,
    "angularUpdate": 0.5,
    "temporalUpdate": -1.0,
    "resampleThreshold": 0.5,
    "particles": 30,
    "xmin": -100.0,
    "ymin": -100.0,
    "xmax": 100.0,
    "ymax": 100.0,
    "delta": 0.05,
    "llsamplerange": 0.01,
    "llsamplestep": 0.01,
    "lasamplerange": 0.005,
    "lasamplestep": 0.005,
    "transform_publish_period": 0.05,
    "occ_thresh": 0.25,
    "tf_delay": None,
}

# The <param> set of the seed's gmapping.launch, as roslaunch types it.
SEED_LAUNCH = {
    "odom_frame": "odom",
    "map_update_interval": 5.0,
    "maxRange": 5.0,
    "maxUrange": 4.5,
    "sigma": 0.05,
    "kernelSize": 1,
    "lstep": 0.05,
    "astep": 0.05,
    "iterations": 5,
    "lsigma": 0.075,
    "ogain": 3.0,
    "lskip": 0,
    "srr": 0.01,
    "srt": 0.02,
    "str": 0.01,
    "stt": 0.02,
    "linearUpdate": 0.5,
    "angularUpdate": 0.436,
    "temporalUpdate": -1.0,
    "resampleThreshold": 0.5,
    "particles": 80,
    "xmin": -1.0,
    "ymin": -1.0,
    "xmax": 1.0,
    "ymax": 1.0,
    "delta": 0.05,
    "llsamplerange": 0.01,
    "llsamplestep": 0.01,
    "lasamplerange": 0.005,
    "lasamplestep": 0.005,
}


def test_params_have_the_ros_names_and_defaults() -> None:
    p = GMappingParams()
    for name, value in ROS_WIKI_DEFAULTS.items():
        assert getattr(p, name) == value, name
    assert p.proposal_samples == 27
    assert p.max_range(80.0) == pytest.approx(79.99)
    assert p.max_range(math.inf) == math.inf
    assert GMappingParams(maxRange=5.0).max_range(80.0) == 5.0


def test_params_from_the_seed_launch_file() -> None:
    p = GMappingParams.from_ros(SEED_LAUNCH)
    for name, value in SEED_LAUNCH.items():
        assert getattr(p, name) == value, name
    # roslaunch may give integers for floats and vice versa; deprecated names are dropped.
    q = GMappingParams.from_ros({"maxUrange": 4, "particles": 80.0, "inverted_laser": "false"})
    assert q.maxUrange == 4.0 and isinstance(q.maxUrange, float)
    assert q.particles == 80 and isinstance(q.particles, int)
    with pytest.raises(GMappingParamsError, match="unknown slam_gmapping parameter 'particle'"):
        GMappingParams.from_ros({"particle": 30})


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"particles": 0}, "particles must be >= 1"),
        ({"particles": 2.5}, "particles must be an int"),
        ({"delta": -0.05}, "delta must be > 0"),
        ({"delta": 0.0}, "delta must be > 0"),
        ({"xmin": 5.0, "xmax": 1.0}, "xmin must be < xmax"),
        ({"ymin": 1.0, "ymax": 1.0}, "ymin must be < ymax"),
        ({"resampleThreshold": 1.5}, "resampleThreshold must be in"),
        ({"sigma": math.nan}, "sigma must be finite"),
        ({"lsigma": 0.0}, "lsigma must be > 0"),
        ({"srr": -0.1}, "srr must be >= 0"),
        ({"str": True}, "str must be a number"),
        ({"kernelSize": 1.0}, "kernelSize must be an int"),
        ({"kernelSize": 99}, "kernelSize must be in"),
        ({"llsamplestep": 0.0}, "llsamplestep must be > 0"),
        ({"lasamplerange": 1.0, "lasamplestep": 0.0001}, "proposal samples"),
        ({"maxUrange": 0.0}, "maxUrange must be > 0"),
        ({"maxRange": -1.0}, "maxRange must be > 0"),
        ({"odom_frame": ""}, "odom_frame must be a non-empty string"),
        ({"throttle_scans": 0}, "throttle_scans must be >= 1"),
        ({"occ_thresh": 2.0}, "occ_thresh must be in"),
        ({"ogain": "3"}, "ogain must be a number"),
    ],
)
def test_bad_params_are_rejected(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(GMappingParamsError, match=message):
        GMappingParams(**kwargs)  # type: ignore[arg-type]


# ----------------------------------------------------------------------- real logs
def _radish(name: str) -> Path:
    path = DATA / "radish" / f"{name}.clf.bz2"
    if not path.is_file():
        pytest.skip(f"shared benchmark data not found at {path} (see shared/data/README.md)")
    return path


def _score(
    name: str, records: Sequence[ScanRecord], poses: NDArray[np.float64]
) -> tuple[float, float]:
    """Kuemmerle translational error (m) of ``poses`` and of the raw odometry."""
    relations = read_relations(DATA / "radish" / f"{name}.relations")
    stamps = np.array([r.timestamp for r in records])
    texts = tuple(r.timestamp_text for r in records)
    odom = np.array([r.odom_pose.as_array() for r in records])
    slam = evaluate(Trajectory(stamps, poses, texts), relations)
    raw = evaluate(Trajectory(stamps, odom, texts), relations)
    assert slam.matched == raw.matched > 0
    return slam.trans_mean, raw.trans_mean


def test_intel_slice_beats_raw_odometry(tmp_path: Path) -> None:
    """Scans 9000-10000 of the Intel lab (200 s, 142 relations, a loop) with 10 particles."""
    path = _radish("intel")
    records = list(itertools.islice(iter_log(path), 9000, 10000))
    slam = GMapping(GMappingParams(particles=10), np.random.default_rng(1))
    run = slam.run_log(records)
    err, odo = _score("intel", records, run.poses)
    assert err < 0.06
    assert err < 0.6 * odo
    save_map_png(run.map, run.poses, tmp_path / "intel_slice.png")
    assert (tmp_path / "intel_slice.png").stat().st_size > 1000
