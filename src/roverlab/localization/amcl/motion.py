"""amcl's odometry motion models (``amcl_odom.cpp``), vectorised over the particles.

The odometry change between two filter updates is given in the odometry frame:
``delta = (x1 - x0, y1 - y0, wrap(theta1 - theta0))`` with ``theta0`` the old heading.
Each model turns it into noisy per-particle motions with ``odom_alpha1..5``:

* ``diff`` / ``diff-corrected``: rotate, translate, rotate (Probabilistic Robotics'
  ``sample_motion_model_odometry``), the rotation noise taken from the smaller angle to
  the forward or backward direction so that reversing is treated like driving forward.
  ``diff`` passes each variance expression to the Gaussian as its *standard deviation*
  (ROS 1's original model); ``diff-corrected`` takes its square root.
* ``omni`` / ``omni-corrected``: translate along the bearing of the motion with noise
  along it and across it (strafe), rotate. ``omni`` uses ROS 1's original expressions as
  standard deviations; ``omni-corrected`` the square roots of the noetic ones.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import wrap_angle
from roverlab.localization.amcl.errors import AmclParamsError
from roverlab.localization.amcl.kernels import diff_motion, omni_motion
from roverlab.localization.amcl.params import ODOM_MODELS

__all__ = ["motion_noise_sigmas", "sample_motion"]

# below this translation (m) the bearing of a motion is meaningless (in-place rotation)
_MIN_BEARING_TRANSLATION_M = 0.01


def _fold(angle: float) -> float:
    """The smaller angle to the forward or the backward direction."""
    return min(abs(float(wrap_angle(angle))), abs(float(wrap_angle(angle - math.pi))))


def _diff_terms(delta: tuple[float, float, float], old_theta: float) -> tuple[float, float, float]:
    dx, dy, dth = delta
    trans = math.hypot(dx, dy)
    if trans < _MIN_BEARING_TRANSLATION_M:
        rot1 = 0.0
    else:
        rot1 = float(wrap_angle(math.atan2(dy, dx) - old_theta))
    rot2 = float(wrap_angle(dth - rot1))
    return rot1, trans, rot2


def motion_noise_sigmas(
    model: str,
    delta: tuple[float, float, float],
    old_theta: float,
    alphas: tuple[float, float, float, float, float],
) -> tuple[float, float, float]:
    """The three Gaussian standard deviations a model draws with for one odometry change.

    Returns:
        ``diff`` models: ``(rot1, trans, rot2)``; ``omni`` models: ``(trans, rot, strafe)``.

    Raises:
        AmclParamsError: an unknown model.
    """
    a1, a2, a3, a4, a5 = alphas
    if model in ("diff", "diff-corrected"):
        rot1, trans, rot2 = _diff_terms(delta, old_theta)
        n1, n2 = _fold(rot1), _fold(rot2)
        t2 = trans * trans
        v = (
            a1 * n1 * n1 + a2 * t2,
            a3 * t2 + a4 * n1 * n1 + a4 * n2 * n2,
            a1 * n2 * n2 + a2 * t2,
        )
    elif model in ("omni", "omni-corrected"):
        dx, dy, dth = delta
        t2 = dx * dx + dy * dy
        r2 = dth * dth
        if model == "omni":
            v = (a3 * t2 + a1 * r2, a4 * r2 + a2 * t2, a1 * r2 + a5 * t2)
        else:
            v = (a3 * t2 + a4 * r2, a1 * r2 + a2 * t2, a4 * r2 + a5 * t2)
    else:
        raise AmclParamsError(f"odom_model_type must be one of {', '.join(ODOM_MODELS)}")
    if model.endswith("-corrected"):
        return (math.sqrt(v[0]), math.sqrt(v[1]), math.sqrt(v[2]))
    return v


def sample_motion(
    poses: NDArray[np.float64],
    *,
    model: str,
    delta: tuple[float, float, float],
    old_theta: float,
    alphas: tuple[float, float, float, float, float],
    rng: np.random.Generator,
) -> None:
    """Move every particle by one noisy draw of the odometry change (in place).

    Args:
        poses: ``(N, 3)`` particle poses ``(x, y, theta)`` in the map frame; headings come
            out wrapped to ``[-pi, pi)``.
        model: ``odom_model_type``.
        delta: the odometry change ``(dx, dy, dtheta)`` in the odometry frame.
        old_theta: the odometry heading before the change (rad).
        alphas: ``odom_alpha1..5``.
        rng: the random source (three standard normal draws per particle, drawn in the
            compiled kernel).

    Raises:
        AmclParamsError: an unknown model.
    """
    s0, s1, s2 = motion_noise_sigmas(model, delta, old_theta, alphas)
    if model.startswith("diff"):
        rot1, trans, rot2 = _diff_terms(delta, old_theta)
        diff_motion(poses, rot1, trans, rot2, s0, s1, s2, rng)
        return
    dx, dy, dth = delta
    bearing = float(wrap_angle(math.atan2(dy, dx) - old_theta))
    omni_motion(poses, bearing, math.hypot(dx, dy), dth, s0, s1, s2, rng)
