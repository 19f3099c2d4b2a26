"""Sensor models on their own: the IMU's noise, bias, gravity and centripetal terms; the
lidar's noise blocks; the camera's reuse of images nobody holds."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from roverlab.raycast import Scene, cast_2d
from roverlab.sim.sensors import (
    GRAVITY,
    CameraModel,
    CameraParams,
    ImuModel,
    ImuNoise,
    LidarModel,
    LidarParams,
)

RATE = ImuNoise(mean=0.0, stddev=0.01, bias_mean=0.05, bias_stddev=0.0)
ACCEL = ImuNoise(mean=0.02, stddev=0.2, bias_mean=0.3, bias_stddev=0.0)


def _samples(model: ImuModel, n: int, *, yaw: float, v: float, w: float, dv: float) -> Any:
    rows = [model.measure(yaw, v, w, dv) for _ in range(n)]
    q = np.array([r[0] for r in rows])
    gyro = np.array([r[1] for r in rows])
    acc = np.array([r[2] for r in rows])
    return q, gyro, acc


def test_imu_reads_motion_gravity_bias_and_noise() -> None:
    model = ImuModel(RATE, ACCEL, np.random.default_rng(3))
    # a bias is drawn once per axis: magnitude bias_mean (stddev 0 here), random sign
    assert np.allclose(np.abs(model.rate_bias), 0.05) and np.allclose(np.abs(model.accel_bias), 0.3)
    q, gyro, acc = _samples(model, 5000, yaw=0.8, v=0.5, w=0.4, dv=0.1)
    assert np.allclose(q, [0.0, 0.0, math.sin(0.4), math.cos(0.4)])
    expected_gyro = model.rate_bias + np.array([0.0, 0.0, 0.4])
    expected_acc = model.accel_bias + 0.02 + np.array([0.1, 0.5 * 0.4, GRAVITY])
    # means within 5 standard errors, spreads within 5 %
    assert np.all(np.abs(gyro.mean(axis=0) - expected_gyro) < 5 * 0.01 / math.sqrt(5000))
    assert np.all(np.abs(acc.mean(axis=0) - expected_acc) < 5 * 0.2 / math.sqrt(5000))
    assert gyro.std(axis=0) == pytest.approx([0.01] * 3, rel=0.05)
    assert acc.std(axis=0) == pytest.approx([0.2] * 3, rel=0.05)


def test_imu_gaussian_noise_adds_to_the_noise_block() -> None:
    model = ImuModel(RATE, ACCEL, np.random.default_rng(4), gaussian_noise=0.1)
    _, gyro, acc = _samples(model, 5000, yaw=0.0, v=0.0, w=0.0, dv=0.0)
    assert gyro.std(axis=0) == pytest.approx([math.hypot(0.01, 0.1)] * 3, rel=0.05)
    assert acc.std(axis=0) == pytest.approx([math.hypot(0.2, 0.1)] * 3, rel=0.05)


def test_noiseless_imu_is_exact_and_seeded_imu_reproduces() -> None:
    exact = ImuModel(ImuNoise(), ImuNoise(), np.random.default_rng(0))
    _, gyro, acc = _samples(exact, 3000, yaw=0.0, v=1.0, w=-0.5, dv=0.25)
    assert np.all(gyro == [0.0, 0.0, -0.5]) and np.all(acc == [0.25, -0.5, GRAVITY])
    # more than one block of pre-drawn normals: the sequence goes on, seeded
    a = _samples(ImuModel(RATE, ACCEL, np.random.default_rng(9)), 3000, yaw=0, v=0, w=0, dv=0)
    b = _samples(ImuModel(RATE, ACCEL, np.random.default_rng(9)), 3000, yaw=0, v=0, w=0, dv=0)
    c = _samples(ImuModel(RATE, ACCEL, np.random.default_rng(10)), 3000, yaw=0, v=0, w=0, dv=0)
    assert np.array_equal(a[1], b[1]) and np.array_equal(a[2], b[2])
    assert not np.array_equal(a[1], c[1])
    assert len(np.unique(a[1][:, 0])) == 3000  # no block of noise repeats


def test_lidar_noise_drawn_in_blocks_is_the_per_scan_draw() -> None:
    """Scans take their noise from blocks of rows drawn ahead: the same numbers, in the
    same order, as one ``rng.normal`` per scan."""
    scene = Scene(segments=[[-2, -2, 2, -2], [2, -2, 2, 2], [2, 2, -2, 2], [-2, 2, -2, -2]])
    params = LidarParams(360, 0.0, 2 * math.pi, 0.1, 8.0, 0.0, 0.02, 0.05)
    model = LidarModel(params, np.random.default_rng(9))
    rng = np.random.default_rng(9)
    for k in range(150):  # across blocks
        yaw = 0.01 * k
        got = model.scan(scene, 0.3, -0.2, 0.2, yaw)
        exact = cast_2d(scene, 0.3, -0.2, 0.2, params.angles() + yaw, params.range_max)
        want = np.where(np.isfinite(exact), exact + rng.normal(0.02, 0.05, 360), np.inf)
        want = np.where(want > params.range_max, np.inf, want)
        want = np.where(want < params.range_min, -np.inf, want)
        np.testing.assert_array_equal(got, want.astype(np.float32))


def test_camera_reuses_only_images_nobody_holds() -> None:
    scene = Scene(segments=[[1, -1, 1, 1]])
    model = CameraModel(CameraParams(32, 24, 1.0), np.random.default_rng(0))
    first = model.capture_rgb(scene, 0, 0, 0.2, 0.0)
    second = model.capture_rgb(scene, 0, 0, 0.2, 0.5)
    assert second is not first  # first is still held here
    view = second.reshape(-1)  # as an Image message's data holds it
    del second
    third = model.capture_rgb(scene, 0, 0, 0.2, 1.0)
    assert third is not first and view.base is not third
    kept = third.copy()
    del third
    fourth = model.capture_rgb(scene, 0, 0, 0.2, 1.0)  # the third's buffer, free again
    np.testing.assert_array_equal(fourth, kept)
    rgb, _ = model.capture(scene, 0, 0, 0.2, 1.0)
    np.testing.assert_array_equal(fourth, rgb)
    np.testing.assert_array_equal(first, model.capture(scene, 0, 0, 0.2, 0.0)[0])


def test_deferred_scans_are_the_scans_read_in_any_order_and_thread() -> None:
    """``scan_later`` draws the noise at once and casts when asked: read late, out of
    order, twice or in another thread, each gives what ``scan`` gave at that pose."""
    import threading

    scene = Scene(
        segments=[[-2, -2, 2, -2], [2, -2, 2, 2], [2, 2, -2, 2], [-2, 2, -2, -2]],
        circles=[[0.8, 0.4, 0.15], [-0.5, 1.1, 0.15]],
    )
    params = LidarParams(720, -2.35, 2.35, 0.1, 3.0, 0.0, 0.01, 0.01)
    eager = LidarModel(params, np.random.default_rng(4))
    lazy = LidarModel(params, np.random.default_rng(4))
    poses = [(0.1 * k - 1.0, 0.05 * k - 0.5, 0.2, 0.3 * k) for k in range(140)]  # > 2 blocks
    want = [eager.scan(scene, *p) for p in poses]
    later = [lazy.scan_later(scene, *p) for p in poses]
    for k in reversed(range(len(poses))):
        np.testing.assert_array_equal(later[k](), want[k])
    got: list[Any] = []
    worker = threading.Thread(target=lambda: got.append(later[7]()))
    worker.start()
    worker.join()
    np.testing.assert_array_equal(got[0], want[7])
    with pytest.raises(Exception, match="lidar pose must be finite"):
        lazy.scan_later(scene, math.nan, 0.0, 0.2, 0.0)
