"""Differential-drive kinematics, acceleration limits, slip and footprint collisions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.raycast import Scene
from roverlab.sim.collision import Obstacles, circle_polygon, polygon_hits
from roverlab.sim.physics import DiffDriveParams, DiffDriveState, arc_step, body_twist, step_wheels

PARAMS = DiffDriveParams(wheel_separation_m=0.18, wheel_diameter_m=0.05, wheel_acceleration=1.0)


def test_command_maps_twist_to_wheels_and_back() -> None:
    s = DiffDriveState()
    s.command(PARAMS, 0.2, 1.0)
    assert s.left_target == pytest.approx(0.2 - 0.09)
    assert s.right_target == pytest.approx(0.2 + 0.09)
    v, w = body_twist(PARAMS, s.left_target, s.right_target)
    assert (v, w) == pytest.approx((0.2, 1.0))


def test_non_finite_command_stops() -> None:
    s = DiffDriveState()
    s.command(PARAMS, 0.3, 0.0)
    s.command(PARAMS, float("nan"), 0.0)
    assert (s.left_target, s.right_target) == (0.0, 0.0)
    s.command(PARAMS, 1e9, 0.0)
    assert s.left_target == PARAMS.max_wheel_speed_mps


def test_wheel_acceleration_limits_ramp() -> None:
    s = DiffDriveState()
    s.command(PARAMS, 0.5, 0.0)
    speeds = []
    for _ in range(60):
        step_wheels(s, PARAMS, 0.01)
        speeds.append(s.left_speed)
    # 1 m/s^2 -> +0.01 m/s per 10 ms step, reaching 0.5 after 50 steps and holding it
    assert speeds[0] == pytest.approx(0.01)
    assert speeds[49] == pytest.approx(0.5)
    assert speeds[-1] == pytest.approx(0.5)
    # wheel angle integrates surface speed / radius
    assert s.left_angle != 0.0


def test_arc_step_exact_circle() -> None:
    x, y, th = 0.0, 0.0, 0.0
    for _ in range(1000):
        x, y, th = arc_step(x, y, th, 0.5, 0.5, 2 * math.pi / 0.5 / 1000)
    assert (x, y) == pytest.approx((0.0, 0.0), abs=1e-9)
    assert arc_step(1.0, 2.0, 0.0, 1.0, 0.0, 0.5) == pytest.approx((1.5, 2.0, 0.0))


def test_slip_is_seeded_and_zero_mean() -> None:
    p = DiffDriveParams(0.18, 0.05, slip_stddev=0.05)
    a = [body_twist(p, 0.2, 0.2, np.random.default_rng(3)) for _ in range(3)]
    b = [body_twist(p, 0.2, 0.2, np.random.default_rng(3)) for _ in range(3)]
    assert a == b
    rng = np.random.default_rng(0)
    vs = np.array([body_twist(p, 0.2, 0.2, rng)[0] for _ in range(4000)])
    assert vs.mean() == pytest.approx(0.2, abs=0.002) and vs.std() > 0.005


def test_invalid_params_rejected() -> None:
    with pytest.raises(ValueError, match="wheel_separation_m"):
        DiffDriveParams(0.0, 0.05)
    with pytest.raises(ValueError, match="slip_stddev"):
        DiffDriveParams(0.2, 0.05, slip_stddev=float("nan"))


def _room() -> Scene:
    # a 4 m x 4 m room centred at the origin, walls 1 m high, plus a pillar and a low mat
    segs = [[-2, -2, 2, -2], [2, -2, 2, 2], [2, 2, -2, 2], [-2, 2, -2, -2], [0.5, 1.0, 1.0, 1.0]]
    z = [[0, 1]] * 4 + [[0, 0.01]]
    return Scene(segments=segs, segment_z=z, circles=[[1.0, -1.0, 0.2]], circle_z=[[0, 1]])


def test_polygon_hits_walls_and_circles() -> None:
    scene = _room()
    box = np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]])
    assert not polygon_hits(box, scene.segments[:4], scene.circles)
    assert polygon_hits(box + np.array([1.95, 0.0]), scene.segments[:4], scene.circles)
    # the pillar edge
    assert polygon_hits(box + np.array([1.0, -0.75]), scene.segments[:4], scene.circles)
    assert not polygon_hits(box + np.array([1.0, -0.65]), scene.segments[:4], scene.circles)
    big = box * 30  # a wall entirely inside the polygon still counts
    assert polygon_hits(big, scene.segments[:4], scene.circles)


def test_obstacles_filter_height_and_stop_at_wall() -> None:
    obs = Obstacles(_room(), z_min=0.02, z_max=0.5)
    fp = circle_polygon(0.15)
    # the 1 cm mat at y=1 does not block the robot
    assert not obs.hits(fp, 0.75, 1.0, 0.0)
    (x, y, th), contact = obs.move(fp, (1.0, 0.0, 0.0), (3.0, 0.0, 0.5))
    assert contact
    assert 1.80 < x < 1.85 and y == 0.0  # stopped within a few mm of the wall at x = 2
    assert 0.0 < th <= 0.5  # it kept turning up to the contact
    assert not obs.hits(fp, x, y, th)
    (x2, _, _), contact2 = obs.move(fp, (0.0, 0.0, 0.0), (0.1, 0.0, 0.0))
    assert not contact2 and x2 == 0.1
