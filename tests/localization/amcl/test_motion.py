"""amcl's odometry models: the statistics of the sampled motions (amcl_odom.cpp)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from roverlab.localization.amcl import AmclParamsError, motion_noise_sigmas, sample_motion

ALPHAS = (0.2, 0.1, 0.3, 0.05, 0.15)
N = 200_000


def _run(model: str, delta: tuple[float, float, float], old_theta: float = 0.3,
         start_theta: float = 0.3) -> np.ndarray:  # fmt: skip
    poses = np.zeros((N, 3))
    poses[:, 2] = start_theta
    sample_motion(poses, model=model, delta=delta, old_theta=old_theta, alphas=ALPHAS,
                  rng=np.random.default_rng(1))  # fmt: skip
    return poses


def _local(poses: np.ndarray, theta: float) -> tuple[np.ndarray, np.ndarray]:
    c, s = math.cos(theta), math.sin(theta)
    return c * poses[:, 0] + s * poses[:, 1], -s * poses[:, 0] + c * poses[:, 1]


@pytest.mark.parametrize("model", ["diff", "diff-corrected"])
def test_diff_models_draw_rotate_translate_rotate(model: str) -> None:
    # 0.4 m forward along the heading 0.3 + 0.1, then turn: rot1 0.1, trans 0.4, rot2 0.15
    a = 0.3 + 0.1
    delta = (0.4 * math.cos(a), 0.4 * math.sin(a), 0.25)
    s_r1, s_t, s_r2 = motion_noise_sigmas(model, delta, 0.3, ALPHAS)
    a1, a2, a3, a4, _ = ALPHAS
    var = (a1 * 0.1**2 + a2 * 0.16, a3 * 0.16 + a4 * 0.1**2 + a4 * 0.15**2,
           a1 * 0.15**2 + a2 * 0.16)  # fmt: skip
    want = [math.sqrt(v) for v in var] if model == "diff-corrected" else list(var)
    assert (s_r1, s_t, s_r2) == pytest.approx(want)
    poses = _run(model, delta)
    heading = np.angle(np.exp(1j * (poses[:, 2] - 0.3)))
    assert heading.mean() == pytest.approx(0.25, abs=2e-3)
    assert heading.std() == pytest.approx(math.hypot(s_r1, s_r2), rel=0.02)
    dist = np.hypot(poses[:, 0], poses[:, 1])
    assert np.median(dist) == pytest.approx(0.4, abs=3e-3)
    fwd, side = _local(poses, 0.3)
    shrink = math.exp(-(s_r1**2) / 2.0)  # E[cos(rot1 + e)] = cos(rot1) exp(-sigma^2 / 2)
    assert fwd.mean() == pytest.approx(0.4 * math.cos(0.1) * shrink, abs=3e-3)
    assert side.mean() == pytest.approx(0.4 * math.sin(0.1) * shrink, abs=3e-3)


def test_diff_treats_reversing_like_driving_forward() -> None:
    # backwards 0.3 m: rot1 is pi, but its noise comes from the fold (0)
    delta = (-0.3 * math.cos(0.3), -0.3 * math.sin(0.3), 0.0)
    fwd = motion_noise_sigmas("diff-corrected", (-delta[0], -delta[1], 0.0), 0.3, ALPHAS)
    back = motion_noise_sigmas("diff-corrected", delta, 0.3, ALPHAS)
    assert back == pytest.approx(fwd)
    poses = _run("diff-corrected", delta)
    f, _ = _local(poses, 0.3)
    s_r1 = back[0]
    assert f.mean() == pytest.approx(-0.3 * math.exp(-(s_r1**2) / 2.0), abs=3e-3)


def test_in_place_rotation_has_no_bearing() -> None:
    poses = _run("diff-corrected", (0.002, -0.003, 1.0))
    s_r1, _, _ = motion_noise_sigmas("diff-corrected", (0.002, -0.003, 1.0), 0.3, ALPHAS)
    assert s_r1 == pytest.approx(math.sqrt(ALPHAS[1] * (0.002**2 + 0.003**2)))
    assert np.angle(np.exp(1j * (poses[:, 2] - 0.3))).mean() == pytest.approx(1.0, abs=3e-3)


@pytest.mark.parametrize("model", ["omni", "omni-corrected"])
def test_omni_models_translate_along_the_bearing_and_strafe(model: str) -> None:
    delta = (0.0, 0.3, 0.2)  # sideways (bearing pi/2 - 0.3 from the heading 0.3)
    s_t, s_r, s_s = motion_noise_sigmas(model, delta, 0.3, ALPHAS)
    a1, a2, a3, a4, a5 = ALPHAS
    t2, r2 = 0.09, 0.04
    if model == "omni":
        want = (a3 * t2 + a1 * r2, a4 * r2 + a2 * t2, a1 * r2 + a5 * t2)
    else:
        want = tuple(math.sqrt(v) for v in (a3 * t2 + a4 * r2, a1 * r2 + a2 * t2,
                                            a4 * r2 + a5 * t2))  # fmt: skip
    assert (s_t, s_r, s_s) == pytest.approx(want)
    poses = _run(model, delta)
    assert poses[:, 0].mean() == pytest.approx(0.0, abs=3e-3)
    assert poses[:, 1].mean() == pytest.approx(0.3, abs=3e-3)
    assert poses[:, 0].std() == pytest.approx(s_s, rel=0.02)  # strafe: across the motion
    assert poses[:, 1].std() == pytest.approx(s_t, rel=0.02)  # along it
    assert np.angle(np.exp(1j * (poses[:, 2] - 0.3))).std() == pytest.approx(s_r, rel=0.02)


def test_headings_come_out_wrapped_and_draws_are_seeded() -> None:
    a = _run("diff", (0.1, 0.0, 3.0), old_theta=3.0, start_theta=3.0)
    assert a[:, 2].min() >= -math.pi and a[:, 2].max() < math.pi
    assert np.array_equal(a, _run("diff", (0.1, 0.0, 3.0), old_theta=3.0, start_theta=3.0))


def test_unknown_model() -> None:
    with pytest.raises(AmclParamsError, match="odom_model_type must be one of"):
        motion_noise_sigmas("ackermann", (0.1, 0.0, 0.0), 0.0, ALPHAS)
