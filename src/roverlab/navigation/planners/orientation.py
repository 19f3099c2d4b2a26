"""global_planner's ``OrientationFilter``: the yaw of each pose of a plan.

``orientation_mode``: 0 none (as planned), 1 forward (along the path, over
``orientation_window_size`` poses either side), 2 interpolate (from the start's yaw to the
goal's), 3 forward then interpolate (forward, then interpolated over the final straight
stretch), 4 backward, 5 leftward, 6 rightward. The goal pose keeps its yaw.
"""

from __future__ import annotations

import math

import numpy as np

from roverlab.geometry import wrap_angle
from roverlab.navigation.planners.base import Path2D

__all__ = ["ORIENTATION_MODES", "orient_path"]

ORIENTATION_MODES = (
    "None",
    "Forward",
    "Interpolate",
    "ForwardThenInterpolate",
    "Backward",
    "Leftward",
    "Rightward",
)


def _derivative(path: Path2D, window: int) -> None:
    n = len(path)
    idx = np.arange(n - 1)
    i0 = np.maximum(0, idx - window)
    i1 = np.minimum(n - 1, idx + window)
    path[:-1, 2] = np.arctan2(path[i1, 1] - path[i0, 1], path[i1, 0] - path[i0, 0])


def _interpolate(path: Path2D, start: int, end: int) -> None:
    if end <= start:
        return
    a0 = float(path[start, 2])
    diff = wrap_angle(float(path[end, 2]) - a0)
    k = np.arange(start, end + 1) - start
    path[start : end + 1, 2] = a0 + diff / (end - start) * k


def orient_path(path: Path2D, start_yaw: float, mode: int, window: int = 1) -> Path2D:
    """Set the yaw column of ``path`` (a copy) by ``orientation_mode`` (see the module)."""
    out = np.array(path, dtype=np.float64, copy=True)
    n = len(out)
    if n == 0 or mode == 0:
        return out
    if mode in (1, 4, 5, 6):
        _derivative(out, window)
        shift = {1: 0.0, 4: math.pi, 5: -math.pi / 2, 6: math.pi / 2}[mode]
        if shift:
            out[:-1, 2] = wrap_angle(out[:-1, 2] + shift)
    elif mode == 2:
        out[0, 2] = start_yaw
        _interpolate(out, 0, n - 1)
    elif mode == 3:
        _derivative(out, window)
        i = n - 3
        if i > 0:
            last = float(out[i, 2])
            while i > 0:
                if abs(wrap_angle(last - float(out[i - 1, 2]))) > 0.35:
                    break
                i -= 1
        out[0, 2] = start_yaw
        _interpolate(out, max(i, 0), n - 1)
    out[:, 2] = wrap_angle(out[:, 2])
    return out
