"""Pose algebra on plain floats and the per-frame time caches of the tf buffer.

A pose is ``parent_T_child`` as 7 floats ``(tx, ty, tz, qx, qy, qz, qw)``: composing tuples
of floats in Python is several times faster than going through small numpy arrays, and
lookups compose one pose per edge. A sample is ``(parent frame id, pose)``: each sample
remembers its parent, so a frame can be re-parented (tf2's TransformStorage).
"""

from __future__ import annotations

import math
from bisect import bisect_left
from typing import ClassVar, Final

from roverlab.tf.errors import (
    BackwardExtrapolationException,
    ExtrapolationException,
    ForwardExtrapolationException,
    NoDataForExtrapolationException,
)

__all__ = [
    "IDENTITY",
    "Cache",
    "Pose",
    "Sample",
    "StaticCache",
    "TimeCache",
    "display",
    "interpolate",
    "inv",
    "mul",
]

NS: Final = 1_000_000_000

Pose = tuple[float, float, float, float, float, float, float]
# A sample is (parent frame id, pose).
Sample = tuple[str, Pose]

IDENTITY: Final[Pose] = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


# --------------------------------------------------------------------------- pose algebra
def mul(a: Pose, b: Pose) -> Pose:
    """``a * b``: apply ``b`` then ``a`` (tf2::Transform product)."""
    ax, ay, az, qx, qy, qz, qw = a
    vx, vy, vz, bx, by, bz, bw = b
    # rotate v by q: v + w t + u x t, with t = 2 u x v
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        ax + vx + qw * tx + qy * tz - qz * ty,
        ay + vy + qw * ty + qz * tx - qx * tz,
        az + vz + qw * tz + qx * ty - qy * tx,
        qw * bx + qx * bw + qy * bz - qz * by,
        qw * by - qx * bz + qy * bw + qz * bx,
        qw * bz + qx * by - qy * bx + qz * bw,
        qw * bw - qx * bx - qy * by - qz * bz,
    )


def inv(a: Pose) -> Pose:
    """Inverse of a rigid transform."""
    vx, vy, vz, qx, qy, qz, qw = a
    qx, qy, qz = -qx, -qy, -qz
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        -(vx + qw * tx + qy * tz - qz * ty),
        -(vy + qw * ty + qz * tx - qx * tz),
        -(vz + qw * tz + qx * ty - qy * tx),
        qx,
        qy,
        qz,
        qw,
    )


def interpolate(a: Pose, b: Pose, r: float) -> Pose:
    """Linear translation and shortest-arc slerp rotation, ``a`` at r=0 and ``b`` at r=1."""
    ax, ay, az, aqx, aqy, aqz, aqw = a
    bx, by, bz, bqx, bqy, bqz, bqw = b
    dot = aqx * bqx + aqy * bqy + aqz * bqz + aqw * bqw
    if dot < 0.0:
        bqx, bqy, bqz, bqw, dot = -bqx, -bqy, -bqz, -bqw, -dot
    if dot > 0.9995:
        # nearly parallel: normalised lerp is exact to float precision and avoids 0/0
        wa, wb = 1.0 - r, r
        qx, qy, qz, qw = (
            wa * aqx + wb * bqx,
            wa * aqy + wb * bqy,
            wa * aqz + wb * bqz,
            wa * aqw + wb * bqw,
        )
        n = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
        qx, qy, qz, qw = qx / n, qy / n, qz / n, qw / n
    else:
        theta = math.acos(dot)
        s = math.sin(theta)
        wa = math.sin((1.0 - r) * theta) / s
        wb = math.sin(r * theta) / s
        qx, qy, qz, qw = (
            wa * aqx + wb * bqx,
            wa * aqy + wb * bqy,
            wa * aqz + wb * bqz,
            wa * aqw + wb * bqw,
        )
    return (ax + r * (bx - ax), ay + r * (by - ay), az + r * (bz - az), qx, qy, qz, qw)


def display(ns: int) -> str:
    """A time as tf2 prints it in messages (seconds, 6 decimals)."""
    return f"{ns / NS:.6f}"


# --------------------------------------------------------------------------- caches
class Cache:
    """The data of one child frame: samples (parent, pose) by time."""

    __slots__ = ("child",)
    is_static: ClassVar[bool] = False

    def __init__(self, child: str) -> None:
        self.child = child

    def insert(self, stamp_ns: int, sample: Sample) -> bool:
        raise NotImplementedError

    def sample_at(self, t_ns: int) -> Sample | None:
        """The sample at ``t_ns`` (interpolated), the latest if ``t_ns == 0``, else None."""
        raise NotImplementedError

    def extrapolation_error(self, t_ns: int) -> ExtrapolationException:
        raise NotImplementedError

    def latest(self) -> tuple[int, str | None]:
        """(latest stamp, its parent); stamp 0 for static data, parent None when empty."""
        raise NotImplementedError

    def latest_stamp(self) -> int:
        raise NotImplementedError

    def oldest_stamp(self) -> int:
        raise NotImplementedError

    def __len__(self) -> int:
        raise NotImplementedError

    def clear(self) -> None:
        raise NotImplementedError


class TimeCache(Cache):
    """Samples sorted by stamp (oldest first), kept for ``max_age_ns`` behind the newest."""

    __slots__ = ("max_age_ns", "samples", "stamps")

    def __init__(self, child: str, max_age_ns: int) -> None:
        super().__init__(child)
        self.max_age_ns = max_age_ns
        self.stamps: list[int] = []
        self.samples: list[Sample] = []

    def insert(self, stamp_ns: int, sample: Sample) -> bool:
        stamps = self.stamps
        if not stamps or stamp_ns > stamps[-1]:
            stamps.append(stamp_ns)
            self.samples.append(sample)
        else:
            if stamp_ns < stamps[-1] - self.max_age_ns:
                return False  # TF_OLD_DATA: would be pruned at once
            i = bisect_left(stamps, stamp_ns)
            if stamps[i] == stamp_ns:
                self.samples[i] = sample  # same stamp: the latest data wins
            else:
                stamps.insert(i, stamp_ns)
                self.samples.insert(i, sample)
        cutoff = stamps[-1] - self.max_age_ns
        if stamps[0] < cutoff:
            k = bisect_left(stamps, cutoff)
            del stamps[:k]
            del self.samples[:k]
        return True

    def sample_at(self, t_ns: int) -> Sample | None:
        stamps = self.stamps
        if not stamps:
            return None
        if t_ns == 0:
            return self.samples[-1]
        i = bisect_left(stamps, t_ns)
        n = len(stamps)
        if i < n and stamps[i] == t_ns:
            return self.samples[i]
        if i == 0 or i == n:
            return None
        older = self.samples[i - 1]
        newer = self.samples[i]
        if older[0] != newer[0]:
            return older  # re-parented in between: tf2 uses the older sample
        t0 = stamps[i - 1]
        r = (t_ns - t0) / (stamps[i] - t0)
        return (older[0], interpolate(older[1], newer[1], r))

    def extrapolation_error(self, t_ns: int) -> ExtrapolationException:
        stamps = self.stamps
        if not stamps:
            return NoDataForExtrapolationException(
                f"Lookup would require extrapolation at time {display(t_ns)}, "
                f"but there is no data for frame [{self.child}] in the buffer"
            )
        if len(stamps) == 1:
            return NoDataForExtrapolationException(
                f"Lookup would require extrapolation at time {display(t_ns)}, "
                f"but only time {display(stamps[0])} is in the buffer"
            )
        if t_ns > stamps[-1]:
            return ForwardExtrapolationException(
                "Lookup would require extrapolation into the future.  Requested time "
                f"{display(t_ns)} but the latest data is at time {display(stamps[-1])}"
            )
        return BackwardExtrapolationException(
            "Lookup would require extrapolation into the past.  Requested time "
            f"{display(t_ns)} but the earliest data is at time {display(stamps[0])}"
        )

    def latest(self) -> tuple[int, str | None]:
        if not self.stamps:
            return 0, None
        return self.stamps[-1], self.samples[-1][0]

    def latest_stamp(self) -> int:
        return self.stamps[-1] if self.stamps else 0

    def oldest_stamp(self) -> int:
        return self.stamps[0] if self.stamps else 0

    def __len__(self) -> int:
        return len(self.stamps)

    def clear(self) -> None:
        self.stamps.clear()
        self.samples.clear()


class StaticCache(Cache):
    """One sample valid at every time; reported with stamp 0, as tf2's StaticCache."""

    __slots__ = ("sample",)
    is_static: ClassVar[bool] = True

    def __init__(self, child: str, sample: Sample) -> None:
        super().__init__(child)
        self.sample = sample

    def insert(self, stamp_ns: int, sample: Sample) -> bool:
        self.sample = sample
        return True

    def sample_at(self, t_ns: int) -> Sample | None:
        return self.sample

    def extrapolation_error(self, t_ns: int) -> ExtrapolationException:  # pragma: no cover
        raise AssertionError("static data never extrapolates")

    def latest(self) -> tuple[int, str | None]:
        return 0, self.sample[0]

    def latest_stamp(self) -> int:
        return 0

    def oldest_stamp(self) -> int:
        return 0

    def __len__(self) -> int:
        return 1

    def clear(self) -> None:
        """Static data survives :meth:`BufferCore.clear`, as in tf2."""
