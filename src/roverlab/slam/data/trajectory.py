"""Planar trajectories and TUM trajectory files.

A TUM file (the TUM RGB-D benchmark format, read by ``evo`` and most SLAM evaluation
tools) has one pose per line::

    timestamp x y z qx qy qz qw

For a planar pose ``(x, y, theta)`` it is written with ``z = 0`` and the quaternion of a
rotation by ``theta`` about +z. Timestamps given as text (a CARMEN ``ipc_timestamp``, a ROS
``sec.nanosec``) are written exactly as given, so the file's timestamps match the log's
byte for byte; pose values are written with the fewest digits that read back exactly.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.slam.data._io import atomic_write_text, finite_floats, text_rows
from roverlab.slam.data.errors import TrajectoryError

__all__ = ["Trajectory", "format_timestamp", "read_tum", "write_tum"]

FloatArray = NDArray[np.float64]

#: Decimals of a timestamp given as a float (CARMEN logs have microseconds).
FLOAT_TIMESTAMP_DECIMALS: Final = 6


def format_timestamp(t: str | float, *, decimals: int = FLOAT_TIMESTAMP_DECIMALS) -> str:
    """Timestamp text for a file: a string as it is (checked), a float with ``decimals``.

    Raises:
        TrajectoryError: the text is not one number, or the value is not finite.
    """
    if isinstance(t, str):
        text = t.strip()
        if not text or len(text.split()) != 1:
            raise TrajectoryError(f"timestamp {t!r} is not one number")
        try:
            value = float(text)
        except ValueError:
            raise TrajectoryError(f"timestamp {t!r} is not a number") from None
        if not math.isfinite(value):
            raise TrajectoryError(f"timestamp {t!r} is not finite")
        return text
    value = float(t)
    if not math.isfinite(value):
        raise TrajectoryError(f"timestamp {t!r} is not finite")
    return f"{value:.{decimals}f}"


@dataclass(frozen=True, eq=False)
class Trajectory:
    """Timestamped planar poses.

    Attributes:
        timestamps: ``(M,)`` times, s.
        poses: ``(M, 3)`` poses ``(x, y, theta)``, m and rad.
        timestamp_texts: The times as text (from a log or file), kept so that matching and
            writing can be exact; None when only floats are known.
    """

    timestamps: FloatArray
    poses: FloatArray
    timestamp_texts: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        t = np.array(self.timestamps, dtype=np.float64).reshape(-1)
        p = np.array(self.poses, dtype=np.float64)
        if p.ndim != 2 or p.shape != (t.shape[0], 3):
            raise TrajectoryError(f"poses must have shape ({t.shape[0]}, 3), not {p.shape}")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(p))):
            raise TrajectoryError("timestamps and poses must be finite")
        texts = self.timestamp_texts
        if texts is not None:
            texts = tuple(texts)
            if len(texts) != t.shape[0]:
                raise TrajectoryError(f"{len(texts)} timestamp texts for {t.shape[0]} poses")
        t.setflags(write=False)
        p.setflags(write=False)
        object.__setattr__(self, "timestamps", t)
        object.__setattr__(self, "poses", p)
        object.__setattr__(self, "timestamp_texts", texts)

    def __len__(self) -> int:
        return int(self.timestamps.shape[0])

    @staticmethod
    def from_poses(
        timestamps: Sequence[str | float], poses: Iterable[SE2] | ArrayLike
    ) -> Trajectory:
        """A trajectory from timestamps (texts or floats) and SE2 poses or an ``(M, 3)``
        array.

        Raises:
            TrajectoryError: bad timestamps or pose shapes.
        """
        texts = [format_timestamp(t) for t in timestamps]
        values = np.array([float(t) for t in texts], dtype=np.float64)
        keep_texts = all(isinstance(t, str) for t in timestamps)
        return Trajectory(
            timestamps=values,
            poses=_pose_array(poses, len(texts)),
            timestamp_texts=tuple(texts) if keep_texts else None,
        )

    def texts(self) -> tuple[str, ...]:
        """The timestamp texts (formatted from the floats when none are kept)."""
        if self.timestamp_texts is not None:
            return self.timestamp_texts
        return tuple(format_timestamp(float(t)) for t in self.timestamps)

    def se2(self, k: int) -> SE2:
        """Pose ``k`` as an :class:`~roverlab.geometry.SE2`."""
        x, y, th = self.poses[k]
        return SE2(float(x), float(y), float(th))


def _pose_array(poses: Iterable[SE2] | ArrayLike, count: int) -> FloatArray:
    if isinstance(poses, np.ndarray):
        arr = np.asarray(poses, dtype=np.float64)
    else:
        items = list(poses)  # type: ignore[arg-type]
        if items and all(isinstance(p, SE2) for p in items):
            arr = np.array([(p.x, p.y, p.theta) for p in items if isinstance(p, SE2)])
        else:
            arr = np.asarray(items, dtype=np.float64)
    arr = arr.reshape(-1, 3) if arr.size == 0 else arr
    if arr.ndim != 2 or arr.shape != (count, 3):
        raise TrajectoryError(f"expected {count} poses (x, y, theta), got shape {arr.shape}")
    return arr


def _num(v: float) -> str:
    text = repr(float(v))
    return "0.0" if text == "-0.0" else text


def write_tum(
    path: str | Path,
    timestamps: Sequence[str | float] | Trajectory,
    poses: Iterable[SE2] | ArrayLike | None = None,
) -> None:
    """Write a TUM trajectory file atomically (a temporary file renamed into place).

    Args:
        path: Output file.
        timestamps: The poses' times: texts (written exactly as given, e.g. a CARMEN
            ``ipc_timestamp``) or floats (written with 6 decimals) -- or a
            :class:`Trajectory`, whose timestamp texts are used when it has them.
        poses: SE2 poses or an ``(M, 3)`` array ``(x, y, theta)`` (not with a Trajectory).

    Raises:
        TrajectoryError: bad timestamps or poses, or the file cannot be written.
    """
    if isinstance(timestamps, Trajectory):
        if poses is not None:
            raise TrajectoryError("give either a Trajectory or timestamps and poses")
        texts = list(timestamps.texts())
        arr = timestamps.poses
    else:
        if poses is None:
            raise TrajectoryError("poses are missing")
        texts = [format_timestamp(t) for t in timestamps]
        arr = _pose_array(poses, len(texts))
    if not np.all(np.isfinite(arr)):
        raise TrajectoryError("poses must be finite")
    half = 0.5 * arr[:, 2]
    qz, qw = np.sin(half), np.cos(half)
    lines = [
        f"{t} {_num(x)} {_num(y)} 0.0 0.0 0.0 {_num(z)} {_num(w)}\n"
        for t, x, y, z, w in zip(
            texts, arr[:, 0].tolist(), arr[:, 1].tolist(), qz.tolist(), qw.tolist(), strict=True
        )
    ]
    atomic_write_text(path, "".join(lines), TrajectoryError)


def read_tum(path: str | Path) -> Trajectory:
    """Read a TUM trajectory file as planar poses (yaw of each quaternion; z, roll and
    pitch are dropped). Blank lines and ``#`` comments are skipped; timestamp texts are
    kept.

    Raises:
        TrajectoryError: the file cannot be read or a line is malformed (the message names
            the file and line).
    """
    p = Path(path)
    texts: list[str] = []
    rows: list[tuple[float, float, float]] = []
    for lineno, parts in text_rows(p, TrajectoryError):
        if len(parts) != 8:
            raise TrajectoryError(f"{p}:{lineno}: expected 8 values, got {len(parts)}")
        vals = finite_floats(parts, f"{p}:{lineno}", TrajectoryError)
        qx, qy, qz, qw = vals[4:]
        if qx * qx + qy * qy + qz * qz + qw * qw < 1e-12:
            raise TrajectoryError(f"{p}:{lineno}: zero quaternion")
        # the yaw of a quaternion of any norm (TUM files are not always normalised)
        yaw = math.atan2(2.0 * (qw * qz + qx * qy), qw * qw + qx * qx - qy * qy - qz * qz)
        texts.append(parts[0])
        rows.append((vals[1], vals[2], wrap_angle(yaw)))
    return Trajectory(
        timestamps=np.array([float(t) for t in texts], dtype=np.float64),
        poses=np.array(rows, dtype=np.float64).reshape(-1, 3),
        timestamp_texts=tuple(texts),
    )
