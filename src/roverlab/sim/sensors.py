"""Sensor models: lidar, IMU and cameras over the shared ray-casting kernels.

Pure: each model takes poses and a seeded ``np.random.Generator`` and returns arrays.
Noise follows Gazebo's sensor noise model: Gaussian with a mean and a standard deviation,
plus (for the IMU) a constant bias drawn once per run from N(bias_mean, bias_stddev).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast import Scene
from roverlab.raycast.camera import render, render_rgb
from roverlab.raycast.lidar import Fan

__all__ = ["CameraModel", "ImuModel", "ImuNoise", "LidarModel", "LidarParams"]

F64 = NDArray[np.float64]
GRAVITY = 9.80665
_BLOCK = 1024
_SCAN_BLOCK = 64
_POOL_SIZE = 4  # camera images kept for reuse per camera


@dataclass(frozen=True, slots=True)
class LidarParams:
    """A Gazebo ``ray`` sensor's horizontal scan.

    ``samples`` beams from ``min_angle`` to ``max_angle`` inclusive (Gazebo spaces them by
    ``(max - min) / (samples - 1)``), ranges limited to [range_min, range_max], quantised to
    ``range_resolution`` (0 = none) and disturbed by N(noise_mean, noise_stddev).
    """

    samples: int
    min_angle: float
    max_angle: float
    range_min: float
    range_max: float
    range_resolution: float = 0.0
    noise_mean: float = 0.0
    noise_stddev: float = 0.0
    height_m: float = 0.2

    def __post_init__(self) -> None:
        if self.samples < 1:
            raise ValueError(f"lidar samples must be >= 1, got {self.samples}")
        if not (0 <= self.range_min < self.range_max):
            raise ValueError(
                f"lidar range must satisfy 0 <= min < max, got {self.range_min}, {self.range_max}"
            )
        if self.max_angle < self.min_angle:
            raise ValueError("lidar max_angle must be >= min_angle")

    @property
    def angle_increment(self) -> float:
        return 0.0 if self.samples == 1 else (self.max_angle - self.min_angle) / (self.samples - 1)

    def angles(self) -> F64:
        return self.min_angle + self.angle_increment * np.arange(self.samples, dtype=np.float64)


class LidarModel:
    """A 2-D scanning lidar: exact ray cast, Gaussian noise, range quantisation.

    Returned ranges follow REP 117: ``+inf`` where nothing is within ``range_max`` and
    ``-inf`` where the return is closer than ``range_min``.
    """

    def __init__(self, params: LidarParams, rng: np.random.Generator) -> None:
        self.params = params
        self.rng = rng
        self._fan = Fan(params.angles(), params.range_max)
        # noise rows drawn _SCAN_BLOCK scans at a time: the same numbers, in the same
        # order, as one draw per scan (the generator serves nobody else)
        self._noise: F64 = np.full((1, params.samples), params.noise_mean)
        self._row = 0 if params.noise_stddev <= 0 else 1

    def _noise_row(self) -> F64:
        p = self.params
        if p.noise_stddev <= 0:
            return self._noise[0]
        if self._row >= self._noise.shape[0]:
            self._noise = self.rng.normal(p.noise_mean, p.noise_stddev, (_SCAN_BLOCK, p.samples))
            self._row = 0
        row = self._noise[self._row]
        self._row += 1
        return row

    def scan(self, scene: Scene, x: float, y: float, z: float, yaw: float) -> NDArray[np.float32]:
        p = self.params
        ranges = self._fan.cast(scene, x, y, z, yaw)
        return _finish_scan(ranges, self._noise_row(), p.range_min, p.range_max, p.range_resolution)

    def scan_later(
        self, scene: Scene, x: float, y: float, z: float, yaw: float
    ) -> Callable[[], NDArray[np.float32]]:
        """:meth:`scan` with the ray cast deferred: the noise row is drawn now (the same rows
        in the same order as :meth:`scan` draws them), the pose checked now; the returned
        function gives the ranges :meth:`scan` would have given now, whenever it is called.
        """
        p = self.params
        cast = self._fan.cast_later(scene, x, y, z, yaw)
        noise = self._noise_row()  # a row of a block that is replaced, never overwritten
        rmin, rmax, res = p.range_min, p.range_max, p.range_resolution

        def ranges() -> NDArray[np.float32]:
            return _finish_scan(cast(), noise, rmin, rmax, res)

        return ranges


@numba.njit(cache=True, nogil=True)
def _finish_scan(
    exact: NDArray[np.float64],
    noise: NDArray[np.float64],
    range_min: float,
    range_max: float,
    resolution: float,
) -> NDArray[np.float32]:
    """Noise, quantisation and REP 117 infinities on exact ranges, in one pass."""
    out = np.empty(exact.shape[0], dtype=np.float32)
    for i in range(exact.shape[0]):
        r = exact[i]
        if not math.isfinite(r):
            out[i] = np.inf
            continue
        r += noise[i]
        if resolution > 0.0:
            r = round(r / resolution) * resolution
        if r > range_max:
            out[i] = np.inf
        elif r < range_min:
            out[i] = -np.inf
        else:
            out[i] = r
    return out


@dataclass(frozen=True, slots=True)
class ImuNoise:
    """Gazebo IMU noise of one quantity (angular rate or linear acceleration)."""

    mean: float = 0.0
    stddev: float = 0.0
    bias_mean: float = 0.0
    bias_stddev: float = 0.0


class ImuModel:
    """Angular velocity, linear acceleration (with gravity) and orientation of a body.

    The bias of each axis is drawn once, as Gazebo does: magnitude from
    N(bias_mean, bias_stddev) with a random sign.
    """

    def __init__(
        self,
        rate: ImuNoise,
        accel: ImuNoise,
        rng: np.random.Generator,
        *,
        gaussian_noise: float = 0.0,
    ) -> None:
        self.rate_noise = rate
        self.accel_noise = accel
        self.gaussian_noise = gaussian_noise
        self.rng = rng
        self.rate_bias = self._bias(rate)
        self.accel_bias = self._bias(accel)
        self._block: list[list[float]] = []
        self._pos = 0

    def _bias(self, n: ImuNoise) -> F64:
        mag = (
            self.rng.normal(n.bias_mean, n.bias_stddev, 3)
            if n.bias_stddev > 0
            else np.full(3, n.bias_mean)
        )
        sign = np.where(self.rng.random(3) < 0.5, -1.0, 1.0)
        return mag * sign

    def _refill(self) -> None:
        """Bias + noise of the next measurements: gyro x, y, z, accel x, y, z (gravity on
        z). Drawn in blocks of 12 standard normals per measurement (6 for the ``<noise>``
        stddevs, 6 for ``gaussianNoise``) and combined with numpy, once per block."""
        z = self.rng.standard_normal((_BLOCK, 12))
        rn, an, g = self.rate_noise, self.accel_noise, self.gaussian_noise
        rows = np.empty((_BLOCK, 6))
        rows[:, :3] = (self.rate_bias + rn.mean) + rn.stddev * z[:, 0:3] + g * z[:, 6:9]
        rows[:, 3:] = (self.accel_bias + an.mean) + an.stddev * z[:, 3:6] + g * z[:, 9:12]
        rows[:, 5] += GRAVITY
        self._block = rows.tolist()
        self._pos = 0

    def _noise_row(self) -> list[float]:
        if self._pos >= len(self._block):
            self._refill()
        row = self._block[self._pos]
        self._pos += 1
        return row

    def take_rows(self) -> list[list[float]]:
        """The noise rows :meth:`measure` would use next, as many as are drawn already
        (a whole block when none is left), in order; they count as used. For a caller
        that applies them itself: walking a list costs less than a call per row."""
        if self._pos >= len(self._block):
            self._refill()
        rows = self._block[self._pos :] if self._pos else self._block
        self._pos = len(self._block)
        return rows

    def measure(
        self, yaw: float, v: float, w: float, dv_dt: float
    ) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        """(quaternion xyzw, angular velocity, linear acceleration) in the body frame.

        ``v``/``w`` are the body's forward and yaw rates, ``dv_dt`` its forward acceleration;
        the centripetal term ``v * w`` appears on y and gravity on z, as a real IMU reads.
        Plain floats: this runs at the IMU rate.
        """
        n = self._noise_row()
        half = 0.5 * yaw
        return (
            (0.0, 0.0, math.sin(half), math.cos(half)),
            (n[0], n[1], w + n[2]),
            (dv_dt + n[3], v * w + n[4], n[5]),
        )


@dataclass(frozen=True, slots=True)
class CameraParams:
    """A pinhole camera as Gazebo's ``<camera>``: image size, fov, clip, noise."""

    width: int
    height: int
    horizontal_fov: float
    clip_near: float = 0.02
    clip_far: float = 300.0
    noise_mean: float = 0.0
    noise_stddev: float = 0.0

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1:
            raise ValueError(f"camera size must be positive, got {self.width}x{self.height}")
        if not (0 < self.horizontal_fov < math.pi):
            raise ValueError(f"camera horizontal_fov must be in (0, pi), got {self.horizontal_fov}")
        if not (0 < self.clip_near < self.clip_far):
            raise ValueError("camera clip must satisfy 0 < near < far")


def _refcount(pool: list[NDArray[np.uint8]], i: int) -> int:
    return sys.getrefcount(pool[i])


class CameraModel:
    """RGB and depth images rendered from the 2.5-D scene, with Gazebo's pixel noise."""

    def __init__(self, params: CameraParams, rng: np.random.Generator) -> None:
        self.params = params
        self.rng = rng
        self._pool: list[NDArray[np.uint8]] = []
        self._free_refs = 0

    def capture(
        self, scene: Scene, x: float, y: float, z: float, yaw: float, pitch: float = 0.0
    ) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
        rgb, depth = render(scene, x, y, z, yaw, pitch=pitch, **self._optics())
        return self._noisy(rgb), depth

    def capture_rgb(
        self, scene: Scene, x: float, y: float, z: float, yaw: float, pitch: float = 0.0
    ) -> NDArray[np.uint8]:
        """:meth:`capture`'s RGB image alone (the same pixels and noise draws).

        The image may be one this model returned before, rendered over again once
        nothing else refers to it any more (a message holding it keeps it alive), which
        saves the operating system handing out fresh pages for every frame.
        """
        out = self._free_buffer()
        return self._noisy(render_rgb(scene, x, y, z, yaw, pitch=pitch, out=out, **self._optics()))

    def _optics(self) -> dict[str, Any]:
        p = self.params
        return {
            "hfov": p.horizontal_fov,
            "width": p.width,
            "height": p.height,
            "near": p.clip_near,
            "far": p.clip_far,
        }

    def _free_buffer(self) -> NDArray[np.uint8] | None:
        """An image of the pool nobody else refers to, a new pooled one, or None."""
        pool = self._pool
        for i in range(len(pool)):
            if _refcount(pool, i) <= self._free_refs:
                return pool[i]
        if len(pool) >= _POOL_SIZE:
            return None
        pool.append(np.empty((self.params.height, self.params.width, 3), dtype=np.uint8))
        # what a buffer nobody else holds counts, measured the way the loop above does
        self._free_refs = _refcount(pool, len(pool) - 1)
        return pool[-1]

    def _noisy(self, rgb: NDArray[np.uint8]) -> NDArray[np.uint8]:
        p = self.params
        if p.noise_stddev > 0 or p.noise_mean != 0:
            noise = self.rng.normal(p.noise_mean, p.noise_stddev, rgb.shape) * 255.0
            return np.clip(rgb.astype(np.float32) + noise, 0, 255).astype(np.uint8)
        return rgb
