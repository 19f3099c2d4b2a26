"""gmapping's odometry motion model, vectorised over particles.

Between two scans the odometry reports a move ``u = (dx, dy, dtheta)`` in the frame of the
earlier pose. Each particle applies ``u`` plus Gaussian noise whose standard deviations grow
with the move (the ROS wiki's meaning of the four parameters):

* along-track ``sigma_x = srr |dx| + 0.3 srr |dy| + srt |dtheta|``,
* cross-track ``sigma_y = srr |dy| + 0.3 srr |dx| + srt |dtheta|``,
* heading ``sigma_theta = stt |dtheta| + str sqrt(dx^2 + dy^2)``;

the cross terms (a tenth-and-a-bit of the forward move leaking sideways) follow gmapping's
sampler. Noise is drawn for every scan, as slam_gmapping does, so the spread between two
filter updates is the sum of the per-scan spreads.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.gmapping.params import GMappingParams

__all__ = ["compose", "motion_sigmas", "relative", "sample_motion", "wrap"]

# gmapping's sideways share of the forward motion noise.
_CROSS = 0.3


def wrap(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """Angles wrapped to [-pi, pi)."""
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def compose(a: NDArray[np.float64], d: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a * d`` for poses ``(..., 3)`` (broadcasting)."""
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    out = np.empty(np.broadcast_shapes(a.shape, d.shape))
    out[..., 0] = a[..., 0] + c * d[..., 0] - s * d[..., 1]
    out[..., 1] = a[..., 1] + s * d[..., 0] + c * d[..., 1]
    out[..., 2] = wrap(a[..., 2] + d[..., 2])
    return out


def relative(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """``a^-1 * b`` for poses ``(..., 3)``: ``b`` in the frame of ``a``."""
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = c * dx + s * dy
    out[..., 1] = -s * dx + c * dy
    out[..., 2] = wrap(b[..., 2] - a[..., 2])
    return out


def motion_sigmas(u: NDArray[np.float64], params: GMappingParams) -> NDArray[np.float64]:
    """Standard deviations ``(sigma_x, sigma_y, sigma_theta)`` of the noise of move ``u``."""
    ax, ay, at = abs(float(u[0])), abs(float(u[1])), abs(float(u[2]))
    trans = float(np.hypot(ax, ay))
    srr, srt = params.srr, params.srt
    return np.array(
        [
            srr * ax + _CROSS * srr * ay + srt * at,
            srr * ay + _CROSS * srr * ax + srt * at,
            params.stt * at + params.str * trans,
        ]
    )


def sample_motion(
    poses: NDArray[np.float64],
    u: NDArray[np.float64],
    sigmas: NDArray[np.float64],
    rng: np.random.Generator,
) -> NDArray[np.float64]:
    """Move every pose by ``u`` plus noise: ``pose * (u + sigmas * N(0, I))``.

    Args:
        poses: (P, 3) poses.
        u: (3,) odometry move in the robot frame.
        sigmas: (3,) noise standard deviations (see :func:`motion_sigmas`).
        rng: the source of the noise; one ``(P, 3)`` standard-normal draw per call.
    """
    noise = rng.standard_normal(poses.shape) * sigmas
    return compose(poses, u[None, :] + noise)
