"""The most used functions of ``tf.transformations``, quaternions as ``[x, y, z, w]``.

Euler angles are ``sxyz`` (static axes, roll-pitch-yaw), tf's default; other axis
conventions are an error rather than a silently wrong answer.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import (
    quat_conjugate,
    quat_from_rpy,
    quat_multiply,
    rpy_from_quat,
)

__all__ = [
    "euler_from_quaternion",
    "quaternion_conjugate",
    "quaternion_from_euler",
    "quaternion_inverse",
    "quaternion_multiply",
    "unit_vector",
]


def _axes(axes: str) -> None:
    if axes != "sxyz":
        raise ValueError(f"axes {axes!r}: roverlab's tf.transformations supports 'sxyz' only")


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: str = "sxyz") -> NDArray[Any]:
    _axes(axes)
    return np.asarray(quat_from_rpy(ai, aj, ak), dtype=np.float64)


def euler_from_quaternion(quaternion: Any, axes: str = "sxyz") -> tuple[float, float, float]:
    _axes(axes)
    return rpy_from_quat(np.asarray(quaternion, dtype=np.float64))


def quaternion_multiply(quaternion1: Any, quaternion0: Any) -> NDArray[Any]:
    return np.asarray(quat_multiply(quaternion1, quaternion0), dtype=np.float64)


def quaternion_conjugate(quaternion: Any) -> NDArray[Any]:
    return np.asarray(quat_conjugate(quaternion), dtype=np.float64)


def quaternion_inverse(quaternion: Any) -> NDArray[Any]:
    q = np.asarray(quaternion, dtype=np.float64)
    return quaternion_conjugate(q) / float(np.dot(q, q))


def unit_vector(data: Any) -> NDArray[Any]:
    v = np.asarray(data, dtype=np.float64)
    return v / float(np.linalg.norm(v))
