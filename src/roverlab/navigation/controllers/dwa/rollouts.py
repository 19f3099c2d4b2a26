"""SimpleTrajectoryGenerator's rollouts for dwa_local_planner's compiled scoring: one
velocity sample's poses (:func:`rollout`), and the same poses built from a heading
sequence shared by every sample of a cycle with the same angular velocity and step count
(:func:`shared_rollout`: the same floating-point operations, no sine or cosine per
sample)."""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

__all__ = ["rollout", "shared_rollout"]

_jit = numba.njit(cache=True, nogil=True)


@_jit
def rollout(
    pos: NDArray[np.float64],
    vel: NDArray[np.float64],
    target: NDArray[np.float64],
    sim_time: float,
    sim_granularity: float,
    angular_sim_granularity: float,
    continued_acceleration: bool,
    acc: NDArray[np.float64],
    extra_time: float,
    out: NDArray[np.float64],
) -> tuple[int, int, float]:
    """SimpleTrajectoryGenerator's ``generateTrajectory`` for one velocity sample.

    Writes the poses (from the current pose, ``num_steps`` of them) to ``out``, followed by
    the poses of ``extra_time`` more seconds at the same velocity (with five columns, each
    pose's ``cos(th)`` and ``sin(th)`` too). Returns ``(num_steps, extra_steps, dt)``;
    ``num_steps`` 0 if the sample gives no trajectory.
    """
    num, extra, dt = _steps(target, sim_time, sim_granularity, angular_sim_granularity, extra_time)
    if num == 0:
        return 0, 0, 0.0
    cap = out.shape[0]
    if num + extra > cap:
        extra = max(0, cap - num)
        num = min(num, cap)
    x = pos[0]
    y = pos[1]
    th = pos[2]
    vx = target[0]
    vy = target[1]
    vth = target[2]
    if continued_acceleration:
        vx, vy, vth = _accelerate(target, vel[0], vel[1], vel[2], acc, dt)
    trig = out.shape[1] >= 5
    for i in range(num + extra):
        c = math.cos(th)
        s = math.sin(th)
        out[i, 0] = x
        out[i, 1] = y
        out[i, 2] = th
        if trig:
            out[i, 3] = c
            out[i, 4] = s
        if continued_acceleration and i < num:
            vx, vy, vth = _accelerate(target, vx, vy, vth, acc, dt)
        if vy != 0.0:
            x += (vx * c + vy * math.cos(math.pi / 2 + th)) * dt
            y += (vx * s + vy * math.sin(math.pi / 2 + th)) * dt
        else:  # the same values (a zero's sign aside, which nothing reads)
            x += vx * c * dt
            y += vx * s * dt
        th += vth * dt
    return num, extra, dt


@_jit
def _steps(
    target: NDArray[np.float64],
    sim_time: float,
    sim_granularity: float,
    angular_sim_granularity: float,
    extra_time: float,
) -> tuple[int, int, float]:
    """A rollout's ``(num_steps, extra_steps, dt)`` (``num_steps`` 0: no trajectory)."""
    vmag = math.hypot(target[0], target[1])
    num = int(
        math.ceil(
            max(
                vmag * sim_time / sim_granularity,
                abs(target[2]) * sim_time / angular_sim_granularity,
            )
        )
    )
    if num == 0:
        return 0, 0, 0.0
    dt = sim_time / num
    extra = int(math.ceil(extra_time / dt - 1e-9)) if extra_time > 0 else 0
    return num, extra, dt


@_jit
def _accelerate1(target: float, cur: float, acc: float, dt: float) -> float:
    """One component of :func:`_accelerate`."""
    if cur < target:
        return min(target, cur + acc * dt)
    return max(target, cur - acc * dt)


@_jit
def _headings(
    th0: float,
    vth0: float,
    target_vth: float,
    num: int,
    steps: int,
    dt: float,
    continued_acceleration: bool,
    acc_th: float,
    out: NDArray[np.float64],
) -> None:
    """``th``, ``cos th``, ``sin th`` of the first ``steps`` poses of :func:`rollout` for a
    sample of angular velocity ``target_vth`` in ``num`` steps of ``dt`` (the headings do
    not depend on the linear velocity: the same floating-point operations as there)."""
    th = th0
    vth = target_vth
    if continued_acceleration:
        vth = _accelerate1(target_vth, vth0, acc_th, dt)
    for i in range(steps):
        out[i, 0] = th
        out[i, 1] = math.cos(th)
        out[i, 2] = math.sin(th)
        if continued_acceleration and i < num:
            vth = _accelerate1(target_vth, vth, acc_th, dt)
        th += vth * dt


@_jit
def _roll_headed(
    pos: NDArray[np.float64],
    vel: NDArray[np.float64],
    target_vx: float,
    num: int,
    steps: int,
    dt: float,
    continued_acceleration: bool,
    acc_x: float,
    heads: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """The first ``steps`` poses of :func:`rollout` (five columns) of a sample with no
    lateral velocity (``vy`` 0 throughout), from its headings (:func:`_headings`): the
    same values, bit for bit, with no sine or cosine computed."""
    x = pos[0]
    y = pos[1]
    vx = target_vx
    if continued_acceleration:
        vx = _accelerate1(target_vx, vel[0], acc_x, dt)
    for i in range(steps):
        c = heads[i, 1]
        s = heads[i, 2]
        out[i, 0] = x
        out[i, 1] = y
        out[i, 2] = heads[i, 0]
        out[i, 3] = c
        out[i, 4] = s
        if continued_acceleration and i < num:
            vx = _accelerate1(target_vx, vx, acc_x, dt)
        x += vx * c * dt
        y += vx * s * dt


@_jit
def shared_rollout(
    k: int,
    samples: NDArray[np.float64],
    pos: NDArray[np.float64],
    vel: NDArray[np.float64],
    gen: NDArray[np.float64],
    acc: NDArray[np.float64],
    continued_acceleration: bool,
    extra_time: float,
    keys: NDArray[np.float64],
    nkeys: NDArray[np.int64],
    heads: NDArray[np.float64],
    traj: NDArray[np.float64],
) -> tuple[int, int]:
    """:func:`rollout` of sample ``k`` into ``traj`` (``(num, extra)``), its headings
    computed once per ``(vth, num)`` for every sample of :func:`score_rollouts` that has
    them (``keys``: vth, num and the heading row of each computed so far, ``nkeys[0]`` of
    them; ``heads``: one ``(cap, 3)`` block each, with the steps of ``gen[6]`` more
    seconds). A sample with a lateral velocity is rolled out plainly."""
    target = samples[k]
    if target[1] != 0.0 or (continued_acceleration and vel[1] != 0.0):
        num, extra, _dt = rollout(
            pos, vel, target, gen[0], gen[1], gen[2], continued_acceleration, acc, extra_time,
            traj,
        )  # fmt: skip
        return num, extra
    num, extra, dt = _steps(target, gen[0], gen[1], gen[2], extra_time)
    if num == 0:
        return 0, 0
    row = -1
    for j in range(nkeys[0]):
        if keys[j, 0] == target[2] and keys[j, 1] == num:
            row = j
            break
    if row < 0:
        row = nkeys[0]
        nkeys[0] += 1
        full, _e, _d = _steps(target, gen[0], gen[1], gen[2], gen[6])
        keys[row, 0] = target[2]
        keys[row, 1] = num
        _headings(
            pos[2], vel[2], target[2], num, full + _e, dt, continued_acceleration, acc[2],
            heads[row],
        )  # fmt: skip
    _roll_headed(pos, vel, target[0], num, num + extra, dt, continued_acceleration, acc[0],
                 heads[row], traj)  # fmt: skip
    return num, extra


@_jit
def _accelerate(
    target: NDArray[np.float64],
    vx: float,
    vy: float,
    vth: float,
    acc: NDArray[np.float64],
    dt: float,
) -> tuple[float, float, float]:
    return (
        _accelerate1(target[0], vx, acc[0], dt),
        _accelerate1(target[1], vy, acc[1], dt),
        _accelerate1(target[2], vth, acc[2], dt),
    )
