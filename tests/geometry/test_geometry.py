"""Angles, quaternions, SE(2) and SE(3) transforms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.geometry import (
    SE2,
    Transform3,
    quat_from_rpy,
    quat_from_yaw,
    quat_multiply,
    quat_rotate,
    quat_slerp,
    rpy_from_quat,
    wrap_angle,
    yaw_from_quat,
)


def test_wrap_angle_scalar_and_array() -> None:
    assert wrap_angle(math.pi + 0.1) == pytest.approx(-math.pi + 0.1)
    assert wrap_angle(-3 * math.pi / 2) == pytest.approx(math.pi / 2)
    arr = wrap_angle(np.array([0.0, 2 * math.pi, 7.0]))
    assert np.allclose(arr, [0.0, 0.0, 7.0 - 2 * math.pi])


@pytest.mark.parametrize("rpy", [(0.1, -0.2, 0.3), (0.0, 0.0, -3.0), (-1.57, 0.0, -1.57)])
def test_rpy_round_trip(rpy: tuple[float, float, float]) -> None:
    q = quat_from_rpy(*rpy)
    assert np.linalg.norm(q) == pytest.approx(1.0)
    assert rpy_from_quat(q) == pytest.approx(rpy, abs=1e-9)


def test_yaw_quaternion_and_rotation() -> None:
    q = quat_from_yaw(math.pi / 2)
    assert yaw_from_quat(q) == pytest.approx(math.pi / 2)
    assert np.allclose(quat_rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0])
    both = quat_multiply(q, q)
    assert yaw_from_quat(both) == pytest.approx(math.pi)


def test_slerp_takes_short_arc_across_pi() -> None:
    a, b = quat_from_yaw(3.0), quat_from_yaw(-3.0)
    mid = quat_slerp(a, b, 0.5)
    assert abs(abs(yaw_from_quat(mid)) - math.pi) < 1e-9


def test_se2_compose_invert_apply() -> None:
    a = SE2(1.0, 2.0, math.pi / 2)
    b = SE2(0.5, 0.0, 0.1)
    ab = a * b
    assert (ab.x, ab.y, ab.theta) == pytest.approx((1.0, 2.5, math.pi / 2 + 0.1))
    ident = a * ~a
    assert (ident.x, ident.y, ident.theta) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    assert np.allclose(a.apply([[1.0, 0.0]]), [[1.0, 3.0]])


def test_transform3_matches_se2_and_inverts() -> None:
    a = SE2(1.0, -2.0, 0.7)
    b = SE2(-0.3, 0.4, -2.0)
    t = Transform3.from_se2(a) * Transform3.from_se2(b)
    assert t.to_se2().as_array() == pytest.approx((a * b).as_array())
    full = Transform3.from_arrays([1, 2, 3], quat_from_rpy(0.2, -0.1, 1.0))
    back = (full * ~full).apply([0.3, -0.2, 0.5])
    assert np.allclose(back, [0.3, -0.2, 0.5])
    half = Transform3().interpolate(Transform3.from_se2(SE2(2.0, 0.0, 1.0)), 0.5)
    assert half.translation == pytest.approx((1.0, 0.0, 0.0))
    assert half.yaw == pytest.approx(0.5)


def test_yaw_from_quat_of_a_tuple_matches_the_array_path() -> None:
    """A tuple (a Transform3's rotation) skips numpy: the same yaw, bit for bit."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        as_tuple = tuple(float(v) for v in q)
        assert yaw_from_quat(as_tuple) == yaw_from_quat(q) == yaw_from_quat(list(as_tuple))
    assert yaw_from_quat((0, 0, 0, 1)) == 0.0
