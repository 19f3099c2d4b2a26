"""Differential-drive dynamics (acceleration limits, arcs, slip) and footprint contacts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.raycast import Scene
from roverlab.sim.collision import Obstacles, circle_polygon, inner_radius, polygon_hits
from roverlab.sim.diff_drive import DiffDriveParams
from roverlab.sim.dynamics import (
    DRIVE_DIFF,
    S_AL,
    S_CONTACT,
    S_CONTACTS,
    S_EX,
    S_TH,
    S_TL,
    S_TR,
    S_V,
    S_VL,
    S_W,
    S_X,
    S_Y,
    STATE_SIZE,
    PhysicsPack,
    advance,
    advance_packed,
)

SEP, DIAM = 0.18, 0.05
NO_WALLS = np.zeros((0, 4))
NO_CIRCLES = np.zeros((0, 3))
FOOTPRINT = circle_polygon(0.15)


def _state(vl: float, vr: float) -> np.ndarray:
    st = np.zeros(STATE_SIZE)
    st[S_TL], st[S_TR] = vl, vr
    return st


def _params(acc: float = 0.0, slip: float = 0.0) -> np.ndarray:
    return np.array([SEP, DIAM, acc, slip, inner_radius(FOOTPRINT), DRIVE_DIFF])


def _run(
    st: np.ndarray,
    params: np.ndarray,
    steps: int,
    dt: float = 0.01,
    *,
    walls=NO_WALLS,
    circles=NO_CIRCLES,
    noise: np.ndarray | None = None,
) -> int:
    n = np.zeros((steps + 1, 2)) if noise is None else noise
    near = np.zeros(len(walls) + len(circles), dtype=np.int64)
    return advance(st, params, dt, FOOTPRINT, walls, circles, near, n, 0, steps)


def test_wheel_acceleration_limits_ramp() -> None:
    st = _state(0.5, 0.5)
    speeds = []
    for _ in range(60):
        _run(st, _params(acc=1.0), 1)
        speeds.append(st[S_VL])
    # 1 m/s^2 -> +0.01 m/s per 10 ms step, 0.5 m/s after 50 steps, then held
    assert speeds[0] == pytest.approx(0.01)
    assert speeds[49] == pytest.approx(0.5)
    assert speeds[-1] == pytest.approx(0.5)
    assert st[S_AL] != 0.0  # wheel angle integrates surface speed / radius


def test_arc_closes_a_circle_and_encoders_agree_without_slip() -> None:
    v, w = 0.5, 0.5
    st = _state(v - w * SEP / 2, v + w * SEP / 2)
    steps = round(2 * math.pi / w / 0.01)
    _run(st, _params(), steps)
    assert (st[S_X], st[S_Y]) == pytest.approx((0.0, 0.0), abs=2e-3)
    assert (st[S_V], st[S_W]) == pytest.approx((v, w))
    assert st[S_EX] == pytest.approx(st[S_X])
    straight = _state(1.0, 1.0)
    _run(straight, _params(), 50)
    assert (straight[S_X], straight[S_Y], straight[S_TH]) == pytest.approx((0.5, 0.0, 0.0))


def test_slip_moves_truth_away_from_encoders_reproducibly() -> None:
    noise = np.random.default_rng(3).standard_normal((1001, 2))
    a, b = _state(0.3, 0.3), _state(0.3, 0.3)
    _run(a, _params(slip=0.05), 1000, noise=noise)
    _run(b, _params(slip=0.05), 1000, noise=noise)
    assert np.array_equal(a, b)
    assert a[S_EX] == pytest.approx(3.0)  # encoders: 0.3 m/s for 10 s
    assert a[S_X] != pytest.approx(3.0, abs=1e-4)  # the ground slipped
    assert abs(a[S_X] - 3.0) < 0.1


def test_invalid_params_rejected() -> None:
    with pytest.raises(ValueError, match="wheel_separation_m"):
        DiffDriveParams(0.0, 0.05)
    with pytest.raises(ValueError, match="slip_stddev"):
        DiffDriveParams(0.2, 0.05, slip_stddev=float("nan"))


def _room() -> Scene:
    # a 4 m x 4 m room centred at the origin, walls 1 m high, a pillar and a 1 cm mat
    segs = [[-2, -2, 2, -2], [2, -2, 2, 2], [2, 2, -2, 2], [-2, 2, -2, -2], [0.5, 1.0, 1.0, 1.0]]
    z = [[0, 1]] * 4 + [[0, 0.01]]
    return Scene(segments=segs, segment_z=z, circles=[[1.0, -1.0, 0.2]], circle_z=[[0, 1]])


def test_polygon_hits_walls_and_circles() -> None:
    scene = _room()
    walls, pillars = scene.segments[:4], scene.circles
    box = np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]])
    assert not polygon_hits(box, walls, pillars)
    assert polygon_hits(box + np.array([1.95, 0.0]), walls, pillars)
    # the pillar's edge
    assert polygon_hits(box + np.array([1.0, -0.75]), walls, pillars)
    assert not polygon_hits(box + np.array([1.0, -0.65]), walls, pillars)
    assert polygon_hits(box * 30, walls, pillars)  # walls entirely inside still count


def test_robot_stops_at_the_wall_and_ignores_low_mats() -> None:
    obs = Obstacles(_room(), z_min=0.02, z_max=0.5)
    assert len(obs.segments) == 4  # the 1 cm mat is below the body
    assert not obs.hits(FOOTPRINT, 0.75, 1.0, 0.0)
    st = _state(1.0, 1.0)
    st[S_X] = 1.0
    _run(st, _params(), 100, walls=obs.segments, circles=obs.circles)
    assert st[S_CONTACT] == 1.0
    assert st[S_CONTACTS] == 1.0  # pushing on for many steps is one event
    assert 1.84 < st[S_X] < 1.849  # the circumscribed 0.15 m footprint touches x = 2
    assert st[S_V] == pytest.approx(0.0, abs=1e-9)
    assert not obs.hits(FOOTPRINT, st[S_X], st[S_Y], st[S_TH])
    # turning in place against the wall is still possible
    st[S_TL], st[S_TR] = -0.1, 0.1
    _run(st, _params(), 10, walls=obs.segments, circles=obs.circles)
    assert st[S_TH] > 0.05
    # backing off and driving into the wall again is a second event
    st[S_TL] = st[S_TR] = -0.5
    _run(st, _params(), 20, walls=obs.segments, circles=obs.circles)
    assert st[S_CONTACT] == 0.0
    st[S_TL] = st[S_TR] = 1.0
    _run(st, _params(), 100, walls=obs.segments, circles=obs.circles)
    assert st[S_CONTACT] == 1.0 and st[S_CONTACTS] == 2.0


def test_long_step_does_not_tunnel_through_a_wall() -> None:
    obs = Obstacles(_room())
    st = _state(200.0, 200.0)  # 2 m in one 10 ms step
    st[S_X] = 1.0
    _run(st, _params(), 1, walls=obs.segments, circles=obs.circles)
    assert st[S_CONTACT] == 1.0 and st[S_X] < 2.0


def test_packed_kernel_matches_advance() -> None:
    """advance_packed (one float64 array for the state, parameters, dt, footprint,
    walls, circles and noise) runs the same steps as advance, bit for bit."""
    walls = np.array([[0.25, -1.0, 0.25, 1.0], [-1.0, 0.5, 1.0, 0.5]])
    circles = np.array([[-0.3, -0.4, 0.05]])
    noise = np.random.default_rng(3).standard_normal((64, 2))
    params = _params(acc=2.0, slip=0.05)
    st = _state(0.3, 0.4)
    pack = PhysicsPack(st, params, 0.01, FOOTPRINT, walls, circles, noise)
    near = np.zeros(len(walls) + len(circles), dtype=np.int64)
    pos = ref_pos = 0
    for steps in (1, 5, 40, 30):
        pos = advance_packed(pack.array, near, pos, steps)
        ref_pos = advance(st, params, 0.01, FOOTPRINT, walls, circles, near, noise, ref_pos, steps)
        assert pos == ref_pos
        assert pack.state.tobytes() == st.tobytes()
    assert pack.state[S_CONTACTS] >= 1
    assert pack.noise.tobytes() == noise.tobytes()
