"""When is a scan match degenerate? The scan's own geometry (hector and graph SLAM use it).

A scan of a long bare corridor fixes the robot across the corridor and its heading, but not
along it: every surface normal points across. Hector's Hessian at the converged pose does
not show this, because the edge of the mapped part of the walls (occupied cells next to
unknown ones, value 0.5) has a gradient along the corridor: the match is pulled back onto
the known walls and the estimate stalls while the robot drives on. The scan's normals do
show it, and do not depend on the map:

``I = sum_i n_i n_i^T`` over the endpoints' surface normals (point-to-line information
of the scan); the ratio of its eigenvalues ``lambda_min / lambda_max`` is near 0 in a
corridor (0.0007 in a simulated 60 m corridor, with 1 cm range noise) and rarely below
0.01 in a building (intel 0.2% of its scans, fr079 none, mit-csail 0.2%). The eigenvector
of ``lambda_min`` is the direction the scan cannot fix.

Normals come from the endpoints ``k`` beams before and after each one, with ``k`` the
smallest of 1, 2, 4, 8, 16 that spans at least ``baseline_m`` (so range noise does not
turn them), and only where the two endpoints lie on one surface (their distance below
``baseline_m`` plus what ``k`` beams can span at that range).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["NORMAL_BASELINE_M", "ScanConstraint", "odometry_along", "scan_constraint"]

#: Shortest baseline (m) of a normal: 1 cm range noise turns it by at most ~2 degrees.
NORMAL_BASELINE_M = 0.3
#: How far apart (m per m of range and per beam) two endpoints of one surface can be.
_SPREAD_PER_M_BEAM = 0.04


class ScanConstraint(NamedTuple):
    """How well a scan fixes the robot's position.

    Attributes:
        ratio: ``lambda_min / lambda_max`` of the normals' information (0: degenerate).
        weak: (2,) unit vector in the robot frame along which the scan fixes least.
    """

    ratio: float
    weak: NDArray[np.float64]


def scan_constraint(
    points: NDArray[np.float64],
    keep: NDArray[np.bool_] | None = None,
    baseline_m: float = NORMAL_BASELINE_M,
) -> ScanConstraint:
    """The constraint of a scan's endpoints (N, 2), in beam order, in the robot frame.

    Args:
        points: the endpoints.
        keep: (N,) which endpoints count (e.g. those on surfaces the map already holds: a
            wall not mapped yet cannot fix the robot against the map); None: all.
        baseline_m: the shortest baseline of a normal (m).
    """
    n = points.shape[0]
    nx = np.zeros(n)
    ny = np.zeros(n)
    done = np.zeros(n, dtype=bool)
    r = np.hypot(points[:, 0], points[:, 1])
    for k in (1, 2, 4, 8, 16):
        if n <= 2 * k:
            break
        t = np.zeros((n, 2))
        t[k:-k] = points[2 * k :] - points[: -2 * k]
        length = np.hypot(t[:, 0], t[:, 1])
        ok = ~done & (length >= baseline_m) & (length < baseline_m + _SPREAD_PER_M_BEAM * r * k)
        ok[:k] = False
        ok[n - k :] = False
        nx[ok] = -t[ok, 1] / length[ok]
        ny[ok] = t[ok, 0] / length[ok]
        done |= ok | (length >= baseline_m)
    if keep is not None:
        nx = np.where(keep, nx, 0.0)
        ny = np.where(keep, ny, 0.0)
    info = np.array([[nx @ nx, nx @ ny], [nx @ ny, ny @ ny]])
    w, v = np.linalg.eigh(info)
    if not w[1] > 0.0:
        return ScanConstraint(0.0, np.array([1.0, 0.0]))
    return ScanConstraint(float(w[0] / w[1]), v[:, 0].copy())


def odometry_along(
    matched: NDArray[np.float64], predicted: NDArray[np.float64], weak: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The match with its position along ``weak`` (robot frame, at the match's heading)
    replaced by the odometry prediction's: what the scan cannot fix, the odometry does.

    Args:
        matched: (3,) the matched pose ``(x, y, theta)``.
        predicted: (3,) the odometry's prediction.
        weak: (2,) unit vector in the robot frame (:attr:`ScanConstraint.weak`).
    """
    c, s = np.cos(matched[2]), np.sin(matched[2])
    vx, vy = c * weak[0] - s * weak[1], s * weak[0] + c * weak[1]
    along = (predicted[0] - matched[0]) * vx + (predicted[1] - matched[1]) * vy
    out = np.array(matched, dtype=np.float64, copy=True)
    out[0] += along * vx
    out[1] += along * vy
    return out
