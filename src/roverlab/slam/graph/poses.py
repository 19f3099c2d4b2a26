"""The keyframe record and the plain-array pose helpers of the graph mapper.

:class:`_Scan` is what :class:`~roverlab.slam.graph.slam.GraphSLAM` keeps of a scan to match
against and to render. The helpers work on ``(..., 3)`` arrays of ``(x, y, theta)`` poses:
composition, relative pose and inverse (:func:`_compose`, :func:`_relative`,
:func:`_inverse`), points moved by a pose, an odometry pose checked, the runs of a mask, an
edge's information matrix and Karto's ``ComputeWeightedMean`` (:func:`_weighted_mean`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2
from roverlab.slam.graph.errors import GraphSlamInputError

FloatArray = NDArray[np.float64]

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True, eq=False)
class _Scan:
    """What a keyframe keeps to be matched against and rendered."""

    points: FloatArray  # (N, 2) robot frame, usable for matching
    ranges: NDArray[np.float32]
    angles: FloatArray
    range_min: float
    range_max: float
    laser_offset: FloatArray  # (3,)


# ------------------------------------------------------------------------------ pose helpers


def _wrap(a: Any) -> Any:
    return (np.asarray(a) + math.pi) % _TWO_PI - math.pi


def _compose(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a * b`` row-wise for ``(..., 3)`` poses."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    return np.stack(
        [
            a[..., 0] + c * b[..., 0] - s * b[..., 1],
            a[..., 1] + s * b[..., 0] + c * b[..., 1],
            _wrap(a[..., 2] + b[..., 2]),
        ],
        axis=-1,
    )


def _relative(a: FloatArray, b: FloatArray) -> FloatArray:
    """``a^-1 * b`` row-wise."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy, _wrap(b[..., 2] - a[..., 2])], axis=-1)


def _inverse(a: FloatArray) -> FloatArray:
    return _relative(a, np.zeros_like(a))


def _transform_points(pose: FloatArray, pts: FloatArray) -> FloatArray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    out = np.empty_like(pts)
    out[:, 0] = pose[0] + c * pts[:, 0] - s * pts[:, 1]
    out[:, 1] = pose[1] + s * pts[:, 0] + c * pts[:, 1]
    return out


def _pose_array(pose: ArrayLike | SE2, what: str) -> FloatArray:
    arr = pose.as_array() if isinstance(pose, SE2) else np.asarray(pose, dtype=np.float64)
    arr = np.asarray(arr, dtype=np.float64).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise GraphSlamInputError(f"{what} must be 3 finite numbers (x, y, theta), got {arr}")
    return arr


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``[start, stop)`` of every maximal run of True."""
    m = np.concatenate([[False], mask, [False]]).astype(np.int8)
    d = np.diff(m)
    starts = np.flatnonzero(d == 1)
    stops = np.flatnonzero(d == -1)
    return list(zip(starts.tolist(), stops.tolist(), strict=True))


def _information(cov: FloatArray, heading: float) -> FloatArray:
    """Information of an edge whose target was matched with world covariance ``cov``:
    rotated into the target's frame (the frame of the g2o error)."""
    c, s = math.cos(heading), math.sin(heading)
    r = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    local = r.T @ cov @ r
    local = 0.5 * (local + local.T) + np.eye(3) * 1e-12
    info = np.linalg.inv(local)
    return np.asarray(0.5 * (info + info.T), dtype=np.float64)


def _weighted_mean(means: list[FloatArray], covs: list[FloatArray]) -> FloatArray:
    """Karto's ``ComputeWeightedMean``: positions weighted by inverse covariance, heading
    the circular mean."""
    infos = [np.linalg.inv(c + np.eye(3) * 1e-12) for c in covs]
    total = np.linalg.inv(np.sum(infos, axis=0))
    ref = means[0]
    acc = np.zeros(3)
    for m, info in zip(means, infos, strict=True):
        v = m - ref
        v[2] = _wrap(v[2])
        acc += total @ info @ v
    heading = math.atan2(
        sum(math.sin(float(m[2])) for m in means), sum(math.cos(float(m[2])) for m in means)
    )
    return np.array([ref[0] + acc[0], ref[1] + acc[1], heading])
