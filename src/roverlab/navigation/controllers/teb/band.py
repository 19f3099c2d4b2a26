"""The timed elastic band: poses and the time differences between them (TEB's
``TimedElasticBand``), with its initialisation from a plan, pruning and resizing."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import wrap_angle

__all__ = ["TimedElasticBand", "estimate_delta_t", "goal_behind"]


def estimate_delta_t(
    start: NDArray[np.float64], end: NDArray[np.float64], max_vel_x: float, max_vel_theta: float
) -> float:
    """TEB's ``estimateDeltaT``: the time to drive and turn from ``start`` to ``end`` at
    the maximum speeds (0.1 s when no speed is given)."""
    dt = 0.1
    if max_vel_x > 0:
        dt = math.hypot(end[0] - start[0], end[1] - start[1]) / max_vel_x
    if max_vel_theta > 0:
        dt = max(dt, abs(wrap_angle(float(end[2] - start[2]))) / max_vel_theta)
    return dt


def goal_behind(start: NDArray[np.float64], goal: NDArray[np.float64]) -> bool:
    """Whether ``goal`` lies behind the pose ``start`` (x, y, yaw): TEB's guess for
    ``allow_init_with_backwards_motion``."""
    d = goal[:2] - start[:2]
    return float(d @ [math.cos(start[2]), math.sin(start[2])]) < 0


def _average(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """PoseSE2::average: the mean position and the mean (wrapped) heading."""
    return np.array(
        [
            (a[0] + b[0]) / 2,
            (a[1] + b[1]) / 2,
            wrap_angle(float(a[2] + wrap_angle(float(b[2] - a[2])) / 2)),
        ]
    )


class TimedElasticBand:
    """Poses ``(n, 3)`` and time differences ``(n - 1,)``; the first and last pose are
    fixed during optimisation."""

    def __init__(self) -> None:
        self.poses: NDArray[np.float64] = np.zeros((0, 3))
        self.dts: NDArray[np.float64] = np.zeros(0)

    @property
    def is_init(self) -> bool:
        return len(self.poses) > 0

    def clear(self) -> None:
        self.poses = np.zeros((0, 3))
        self.dts = np.zeros(0)

    def init_from_plan(
        self,
        plan: NDArray[np.float64],
        max_vel_x: float,
        max_vel_theta: float,
        estimate_orient: bool,
        min_samples: int,
        guess_backwards: bool,
        min_spacing: float = 0.0,
    ) -> None:
        """TEB's ``initTrajectoryToGoal`` from a plan (start and goal poses included).

        ``min_spacing`` (m): intermediate plan points closer than this to the last pose
        taken are skipped, and the headings point at the next point taken. The planner
        passes the distance of the shortest interval ``autoResize`` keeps, so the band
        starts as it would end up after resizing, without the headings of sub-resolution
        wiggles of the plan (a gradient descent's zig-zag of a few centimetres makes every
        other heading turn by pi: seconds of rotation per interval, which ``autoResize``
        then splits into hundreds of poses). 0 takes every point, as TEB.
        """
        start = plan[0].copy()
        goal = plan[-1].copy()
        poses = [start]
        dts: list[float] = []
        backwards = guess_backwards and goal_behind(start, goal)
        taken = [0]
        for i in range(1, len(plan) - 1):
            last = plan[taken[-1]]
            if math.hypot(plan[i, 0] - last[0], plan[i, 1] - last[1]) >= min_spacing:
                taken.append(i)
        taken.append(len(plan) - 1)
        for k in range(1, len(taken) - 1):
            i, j = taken[k], (taken[k] + 1 if min_spacing <= 0 else taken[k + 1])
            if estimate_orient:
                yaw = math.atan2(plan[j, 1] - plan[i, 1], plan[j, 0] - plan[i, 0])
                if backwards:
                    yaw = wrap_angle(yaw + math.pi)
            else:
                yaw = float(plan[i, 2])
            p = np.array([plan[i, 0], plan[i, 1], yaw])
            dts.append(estimate_delta_t(poses[-1], p, max_vel_x, max_vel_theta))
            poses.append(p)
        while len(poses) < min_samples - 1:
            p = _average(poses[-1], goal)
            dts.append(estimate_delta_t(poses[-1], p, max_vel_x, max_vel_theta))
            poses.append(p)
        dts.append(estimate_delta_t(poses[-1], goal, max_vel_x, max_vel_theta))
        poses.append(goal)
        self.poses = np.array(poses)
        self.dts = np.array(dts)

    def update_and_prune(
        self, start: NDArray[np.float64], goal: NDArray[np.float64], min_samples: int
    ) -> None:
        """TEB's ``updateAndPruneTEB``: drop the poses the robot has passed (the nearest of
        the first ten, keeping ``min_samples``), then set the start and goal poses."""
        n = len(self.poses)
        if n > 0:
            d0 = math.hypot(start[0] - self.poses[0, 0], start[1] - self.poses[0, 1])
            look = min(n - min_samples, 10)
            nearest = 0
            for i in range(1, look + 1):
                d = math.hypot(start[0] - self.poses[i, 0], start[1] - self.poses[i, 1])
                if d < d0:
                    d0, nearest = d, i
                else:
                    break
            if nearest > 0:
                self.poses = np.delete(self.poses, np.s_[1 : nearest + 1], axis=0)
                self.dts = np.delete(self.dts, np.s_[1 : nearest + 1])
            self.poses[0] = start
        if len(self.poses) > 0:
            self.poses[-1] = goal

    def auto_resize(
        self, dt_ref: float, dt_hysteresis: float, min_samples: int, max_samples: int
    ) -> None:
        """TEB's ``autoResize`` (fast mode: one pass): halve an interval longer than
        ``dt_ref + dt_hysteresis`` by inserting a pose, merge one shorter than
        ``dt_ref - dt_hysteresis`` with its successor."""
        poses = [p for p in self.poses]
        dts = list(self.dts)
        i = 0
        while i < len(dts):
            if dts[i] > dt_ref + dt_hysteresis and len(dts) < max_samples:
                half = 0.5 * dts[i]
                dts[i] = half
                poses.insert(i + 1, _average(poses[i], poses[i + 1]))
                dts.insert(i + 1, half)
            elif dts[i] < dt_ref - dt_hysteresis and len(dts) > min_samples:
                if i < len(dts) - 1:
                    dts[i + 1] += dts[i]
                    del dts[i]
                    del poses[i + 1]
                else:
                    dts[i - 1] += dts[i]
                    del dts[i]
                    del poses[i]
            i += 1
        self.poses = np.array(poses)
        self.dts = np.array(dts)
