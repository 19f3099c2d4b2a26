"""Rigid-body geometry on numpy: angles, quaternions, SE(2) and SE(3).

Quaternions are ``(x, y, z, w)`` arrays, the ROS order. Functions are pure and work on
plain floats or numpy arrays; none of them touches messages, the bus or a clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "SE2",
    "Transform3",
    "quat_conjugate",
    "quat_from_rpy",
    "quat_from_yaw",
    "quat_multiply",
    "quat_normalize",
    "quat_rotate",
    "quat_slerp",
    "rpy_from_quat",
    "wrap_angle",
    "yaw_from_quat",
]

FloatArray = NDArray[np.float64]


@overload
def wrap_angle(angle: float) -> float: ...
@overload
def wrap_angle(angle: NDArray[np.floating[Any]]) -> FloatArray: ...
def wrap_angle(angle: float | NDArray[np.floating[Any]]) -> float | FloatArray:
    """Wrap an angle (or array of angles) to [-pi, pi)."""
    if isinstance(angle, float | int):
        return (float(angle) + math.pi) % (2.0 * math.pi) - math.pi
    a = np.asarray(angle, dtype=np.float64)
    return (a + np.pi) % (2.0 * np.pi) - np.pi


def quat_from_yaw(yaw: float) -> FloatArray:
    """Quaternion (x, y, z, w) of a rotation by ``yaw`` radians about +z."""
    half = 0.5 * yaw
    return np.array([0.0, 0.0, math.sin(half), math.cos(half)])


def yaw_from_quat(q: ArrayLike) -> float:
    """Yaw (rotation about z, radians) of quaternion (x, y, z, w), as tf's getYaw."""
    if type(q) is tuple and len(q) == 4:  # a Transform3's rotation: no array needed
        x, y, z, w = (float(v) for v in q)
    else:
        x, y, z, w = (float(v) for v in np.asarray(q, dtype=np.float64))
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quat_from_rpy(roll: float, pitch: float, yaw: float) -> FloatArray:
    """Quaternion (x, y, z, w) from fixed-axis roll, pitch, yaw (URDF ``rpy``, tf2 setRPY)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array(
        [
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy,
        ]
    )


def rpy_from_quat(q: ArrayLike) -> tuple[float, float, float]:
    """Roll, pitch, yaw of quaternion (x, y, z, w); inverse of :func:`quat_from_rpy`."""
    x, y, z, w = (float(v) for v in np.asarray(q, dtype=np.float64))
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    s = max(-1.0, min(1.0, 2 * (w * y - z * x)))
    pitch = math.asin(s)
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def quat_normalize(q: ArrayLike) -> FloatArray:
    """Unit quaternion; raises ValueError for a zero or non-finite quaternion."""
    a = np.asarray(q, dtype=np.float64)
    n = float(np.linalg.norm(a))
    if not math.isfinite(n) or n < 1e-12:
        raise ValueError(f"quaternion {a.tolist()} cannot be normalised")
    return a / n


def quat_multiply(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Hamilton product ``a * b`` of (x, y, z, w) quaternions."""
    ax, ay, az, aw = np.asarray(a, dtype=np.float64)
    bx, by, bz, bw = np.asarray(b, dtype=np.float64)
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def quat_conjugate(q: ArrayLike) -> FloatArray:
    """Conjugate (the inverse, for a unit quaternion)."""
    x, y, z, w = np.asarray(q, dtype=np.float64)
    return np.array([-x, -y, -z, w])


def quat_rotate(q: ArrayLike, v: ArrayLike) -> FloatArray:
    """Rotate vector(s) ``v`` (shape (3,) or (N, 3)) by unit quaternion ``q``."""
    x, y, z, w = np.asarray(q, dtype=np.float64)
    vv = np.asarray(v, dtype=np.float64)
    t = 2.0 * _cross(x, y, z, vv)
    return vv + w * t + _cross(x, y, z, t)


def _cross(x: np.float64, y: np.float64, z: np.float64, b: FloatArray) -> FloatArray:
    """``np.cross((x, y, z), b)`` for ``b`` of shape (3,) or (N, 3), with numpy's own
    arithmetic (same results) but without its generic axis handling, which dominated the
    cost of transforming a laser scan."""
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([y * b2 - z * b1, z * b0 - x * b2, x * b1 - y * b0], axis=-1)


def quat_slerp(a: ArrayLike, b: ArrayLike, t: float) -> FloatArray:
    """Spherical linear interpolation from ``a`` (t=0) to ``b`` (t=1), shortest arc."""
    qa = np.asarray(a, dtype=np.float64)
    qb = np.asarray(b, dtype=np.float64)
    dot = float(np.dot(qa, qb))
    if dot < 0.0:
        qb = -qb
        dot = -dot
    if dot > 0.9995:
        return quat_normalize(qa + t * (qb - qa))
    theta = math.acos(dot)
    s = math.sin(theta)
    return (math.sin((1.0 - t) * theta) / s) * qa + (math.sin(t * theta) / s) * qb


@dataclass(frozen=True, slots=True)
class SE2:
    """Planar pose / transform ``(x, y, theta)``; ``a * b`` composes, ``~a`` inverts."""

    x: float = 0.0
    y: float = 0.0
    theta: float = 0.0

    def __mul__(self, other: SE2) -> SE2:
        c, s = math.cos(self.theta), math.sin(self.theta)
        return SE2(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            wrap_angle(self.theta + other.theta),
        )

    def __invert__(self) -> SE2:
        c, s = math.cos(self.theta), math.sin(self.theta)
        return SE2(-c * self.x - s * self.y, s * self.x - c * self.y, wrap_angle(-self.theta))

    def apply(self, points: ArrayLike) -> FloatArray:
        """Transform (N, 2) points from this frame to the parent frame."""
        p = np.asarray(points, dtype=np.float64)
        c, s = math.cos(self.theta), math.sin(self.theta)
        r = np.array([[c, -s], [s, c]])
        return p @ r.T + np.array([self.x, self.y])

    def as_array(self) -> FloatArray:
        return np.array([self.x, self.y, self.theta])


@dataclass(frozen=True, slots=True)
class Transform3:
    """Rigid 3-D transform: translation (3,) and unit quaternion (x, y, z, w).

    ``a * b`` composes (apply ``b`` then ``a``), ``~a`` inverts, as tf2::Transform.
    """

    translation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rotation: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    @staticmethod
    def from_arrays(translation: ArrayLike, rotation: ArrayLike) -> Transform3:
        t = np.asarray(translation, dtype=np.float64).reshape(3)
        q = np.asarray(rotation, dtype=np.float64).reshape(4)
        return Transform3((float(t[0]), float(t[1]), float(t[2])), _q4(q))

    def __mul__(self, other: Transform3) -> Transform3:
        # plain float arithmetic: this sits on every TF and robot_state_publisher path,
        # where numpy's per-call overhead on 3- and 4-vectors dominates
        ax, ay, az, aw = self.rotation
        bx, by, bz, bw = other.rotation
        tx, ty, tz = _rotate(self.rotation, other.translation)
        sx, sy, sz = self.translation
        return Transform3(
            (sx + tx, sy + ty, sz + tz),
            (
                aw * bx + ax * bw + ay * bz - az * by,
                aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw,
                aw * bw - ax * bx - ay * by - az * bz,
            ),
        )

    def __invert__(self) -> Transform3:
        x, y, z, w = self.rotation
        qi = (-x, -y, -z, w)
        tx, ty, tz = _rotate(qi, self.translation)
        return Transform3((-tx, -ty, -tz), qi)

    def apply(self, points: ArrayLike) -> FloatArray:
        """Transform (3,) or (N, 3) points from the child frame into the parent frame."""
        return quat_rotate(self.rotation, points) + np.asarray(self.translation)

    @property
    def yaw(self) -> float:
        return yaw_from_quat(self.rotation)

    def to_se2(self) -> SE2:
        return SE2(self.translation[0], self.translation[1], self.yaw)

    @staticmethod
    def from_se2(p: SE2) -> Transform3:
        return Transform3((p.x, p.y, 0.0), _q4(quat_from_yaw(p.theta)))

    def interpolate(self, other: Transform3, t: float) -> Transform3:
        """Linear translation and slerp rotation between self (t=0) and other (t=1)."""
        a = np.asarray(self.translation)
        b = np.asarray(other.translation)
        return Transform3.from_arrays(a + t * (b - a), quat_slerp(self.rotation, other.rotation, t))


def _rotate(
    q: tuple[float, float, float, float], v: tuple[float, float, float]
) -> tuple[float, float, float]:
    """Rotate vector ``v`` by unit quaternion ``q`` (floats, no numpy)."""
    qx, qy, qz, qw = q
    vx, vy, vz = v
    # t = 2 * cross(q.xyz, v); v' = v + w * t + cross(q.xyz, t)
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + (qy * tz - qz * ty),
        vy + qw * ty + (qz * tx - qx * tz),
        vz + qw * tz + (qx * ty - qy * tx),
    )


def _q4(q: FloatArray) -> tuple[float, float, float, float]:
    return (float(q[0]), float(q[1]), float(q[2]), float(q[3]))
