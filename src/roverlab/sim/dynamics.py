"""The compiled physics loop: wheel ramps, slip, arcs and wall contacts, step by step.

The simulator advances the robot lazily: when a sensor samples, a command arrives or
odometry is published, it runs every fixed physics step (``1 / physics_rate``) up to that
moment in one call of :func:`advance`. The result is identical to ticking a 100 Hz
physics timer, without a Python callback per step.

State vector layout (float64, see ``S_*``): ground-truth pose, wheel surface speeds and
targets, wheel angles, encoder-odometry pose, body twist and forward acceleration, the
contact flag of the last step and the number of contact events so far (a step in contact
after one that was not), the broad phase's anchor, then the lateral velocity, the body's
lateral acceleration and a holonomic drive's commanded body twist.

Two drive kinds (``params[P_KIND]``): the differential drive (:data:`DRIVE_DIFF`: wheel
speeds ramp to their targets, the body follows the wheels' arc; its lateral velocity is
zero) and the holonomic base of gazebo_ros_planar_move (:data:`DRIVE_HOLONOMIC`: the
commanded body twist ``(vx, vy, wz)`` is the body's velocity at once, as the plugin sets
the model's velocity every update; no wheels, no slip, no encoders).

Broad phase: the contact test only looks at the walls and posts within the footprint's
circumscribed radius plus a margin of an anchor point, gathered again whenever a step
could leave that disc; the obstacles it skips cannot touch the body, so every result is
the same as testing them all (60 walls in the maze, a handful near the robot).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, TypeVar

import numba
import numpy as np

from roverlab.sim.collision import any_near, gather_near, polygon_hits_near

F = TypeVar("F", bound=Callable[..., Any])

__all__ = [
    "DRIVE_DIFF",
    "DRIVE_HOLONOMIC",
    "N_PARAMS",
    "STATE_SIZE",
    "PhysicsPack",
    "advance",
    "advance_packed",
    "compiled_entry",
]

S_X, S_Y, S_TH = 0, 1, 2
S_VL, S_VR, S_TL, S_TR = 3, 4, 5, 6
S_AL, S_AR = 7, 8
S_EX, S_EY, S_ETH = 9, 10, 11
S_V, S_W, S_DV = 12, 13, 14
S_CONTACT = 15
S_CONTACTS = 16
# broad phase: the obstacles near an anchor point (indices in the ``near`` work array)
S_AX, S_AY, S_AREACH, S_NSEG, S_NCIRC, S_RADIUS = 17, 18, 19, 20, 21, 22
# body-frame lateral velocity, the body's lateral (y) acceleration as an IMU at the origin
# feels it (the centripetal v w for the diff drive), a holonomic drive's command (vx, vy, wz)
S_VY, S_LAT = 23, 24
S_CVX, S_CVY, S_CW = 25, 26, 27
STATE_SIZE = 28

BROAD_MARGIN_M = 0.25  # how far the body may move from its anchor before a new gather

P_SEP, P_DIAM, P_ACC, P_SLIP, P_INNER, P_KIND = 0, 1, 2, 3, 4, 5
N_PARAMS = 6
DRIVE_DIFF, DRIVE_HOLONOMIC = 0.0, 1.0


@numba.njit(cache=True, nogil=True)
def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@numba.njit(cache=True, nogil=True)
def _approach(cur: float, target: float, max_delta: float) -> float:
    if max_delta <= 0.0:
        return target
    if target > cur:
        return min(target, cur + max_delta)
    return max(target, cur - max_delta)


@numba.njit(cache=True, nogil=True)
def _arc(
    x: float, y: float, th: float, v: float, w: float, dt: float
) -> tuple[float, float, float]:
    if abs(w) < 1e-9:
        return x + v * dt * math.cos(th), y + v * dt * math.sin(th), th
    th2 = th + w * dt
    r = v / w
    return (
        x + r * (math.sin(th2) - math.sin(th)),
        y - r * (math.cos(th2) - math.cos(th)),
        _wrap(th2),
    )


@numba.njit(cache=True, nogil=True)
def _glide(
    x: float, y: float, th: float, vx: float, vy: float, w: float, dt: float
) -> tuple[float, float, float]:
    """The pose after ``dt`` at a constant body twist ``(vx, vy, w)`` (exact)."""
    if abs(w) < 1e-9:
        c, s = math.cos(th), math.sin(th)
        return x + dt * (vx * c - vy * s), y + dt * (vx * s + vy * c), th
    th2 = th + w * dt
    ds = math.sin(th2) - math.sin(th)
    dc = math.cos(th2) - math.cos(th)
    return x + (vx * ds + vy * dc) / w, y + (vy * ds - vx * dc) / w, _wrap(th2)


@numba.njit(cache=True, nogil=True)
def _hits(
    fp: np.ndarray,
    x: float,
    y: float,
    th: float,
    segs: np.ndarray,
    circles: np.ndarray,
    buf: np.ndarray,
    near: np.ndarray,
    state: np.ndarray,
) -> bool:
    ns, nc = int(state[S_NSEG]), int(state[S_NCIRC])
    # nothing within the footprint's circumscribed circle (rounding margin): no contact
    if not any_near(x, y, state[S_RADIUS] + 1e-9, segs, circles, near, ns, nc):
        return False
    c, s = math.cos(th), math.sin(th)
    for i in range(fp.shape[0]):
        buf[i, 0] = x + c * fp[i, 0] - s * fp[i, 1]
        buf[i, 1] = y + s * fp[i, 0] + c * fp[i, 1]
    return polygon_hits_near(buf, segs, circles, near, ns, nc)


@numba.njit(cache=True, nogil=True)
def _circumradius(fp: np.ndarray) -> float:
    r = 0.0
    for i in range(fp.shape[0]):
        r = max(r, math.hypot(fp[i, 0], fp[i, 1]))
    return r


@numba.njit(cache=True, nogil=True)
def _cover(
    state: np.ndarray,
    x: float,
    y: float,
    travel: float,
    fp: np.ndarray,
    segs: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
) -> None:
    """Make sure the anchor's gathered obstacles hold every one the body can touch while
    its origin moves up to ``travel`` from ``(x, y)``; gather anew around ``(x, y)`` if
    not."""
    if (
        state[S_AREACH] > 0.0
        and math.hypot(x - state[S_AX], y - state[S_AY]) + travel <= (state[S_AREACH])
    ):
        return
    reach = max(BROAD_MARGIN_M, 2.0 * travel)
    radius = _circumradius(fp)
    ns, nc = gather_near(x, y, radius + reach + 1e-9, segs, circles, near)
    state[S_AX], state[S_AY], state[S_AREACH], state[S_RADIUS] = x, y, reach, radius
    state[S_NSEG], state[S_NCIRC] = ns, nc


@numba.njit(cache=True, nogil=True)
def advance(
    state: np.ndarray,
    params: np.ndarray,
    dt: float,
    footprint: np.ndarray,
    segments: np.ndarray,
    circles: np.ndarray,
    near: np.ndarray,
    noise: np.ndarray,
    noise_pos: int,
    steps: int,
) -> int:
    """Run ``steps`` physics steps of ``dt`` on ``state`` in place.

    ``noise`` holds pre-drawn standard normals (N, 2) for the wheel slip, consumed from
    ``noise_pos`` on (two per step while a wheel turns); returns the new position. A
    motion that would put the footprint into an obstacle stops at the contact (bisection
    of the last clear sub-step) and sets ``state[S_CONTACT]``; a contact after a step
    without one counts one event in ``state[S_CONTACTS]``. ``near`` is the broad phase's
    work array (int64, at least as long as ``segments`` and ``circles`` together).
    ``params`` without ``P_KIND`` (five entries) is a differential drive.
    """
    sep = params[P_SEP]
    radius = 0.5 * params[P_DIAM]
    acc = params[P_ACC]
    slip = params[P_SLIP]
    inner = params[P_INNER]
    holonomic = params.shape[0] > P_KIND and params[P_KIND] == DRIVE_HOLONOMIC
    buf = np.empty_like(footprint)
    max_delta = acc * dt if acc > 0.0 else 0.0
    for _ in range(steps):
        x0, y0, th0 = state[S_X], state[S_Y], state[S_TH]
        if holonomic:
            v, vy, w = state[S_CVX], state[S_CVY], state[S_CW]
            gx, gy, gth = _glide(x0, y0, th0, v, vy, w, dt)
        else:
            vl = _approach(state[S_VL], state[S_TL], max_delta)
            vr = _approach(state[S_VR], state[S_TR], max_delta)
            state[S_VL] = vl
            state[S_VR] = vr
            state[S_AL] = _wrap(state[S_AL] + vl * dt / radius)
            state[S_AR] = _wrap(state[S_AR] + vr * dt / radius)
            # encoders integrate what the wheels turned
            ev = 0.5 * (vl + vr)
            ew = (vr - vl) / sep
            state[S_EX], state[S_EY], state[S_ETH] = _arc(
                state[S_EX], state[S_EY], state[S_ETH], ev, ew, dt
            )
            # the ground moves the body by slightly different amounts (slip)
            tl, tr = vl, vr
            if slip > 0.0 and (vl != 0.0 or vr != 0.0):
                if noise_pos >= noise.shape[0]:
                    noise_pos = 0
                tl = vl * (1.0 + slip * noise[noise_pos, 0])
                tr = vr * (1.0 + slip * noise[noise_pos, 1])
                noise_pos += 1
            v = 0.5 * (tl + tr)
            w = (tr - tl) / sep
            vy = 0.0
            gx, gy, gth = _arc(x0, y0, th0, v, w, dt)
        contact = False
        if v != 0.0 or w != 0.0 or vy != 0.0:
            dist = math.hypot(gx - x0, gy - y0)
            dth = _wrap(gth - th0)
            if abs(w * dt) >= math.pi:  # more than half a turn in one step: not wrapped
                dth = w * dt
            _cover(state, x0, y0, dist, footprint, segments, circles, near)
            # sub-steps: the origin moves at most half the inscribed radius in each, and
            # the farthest footprint point (state[S_RADIUS] from the origin) turns at most
            # as far, so a fast spin cannot sweep a corner through a wall
            sweep = max(dist, state[S_RADIUS] * abs(dth))
            n = 1
            if inner > 0.0:
                n = max(1, int(math.ceil(sweep / (0.5 * inner))))
            px, py, pth = x0, y0, th0
            for k in range(1, n + 1):
                f = k / n
                cx = x0 + f * (gx - x0)
                cy = y0 + f * (gy - y0)
                cth = _wrap(th0 + f * dth)
                if _hits(footprint, cx, cy, cth, segments, circles, buf, near, state):
                    contact = True
                    th = cth
                    if _hits(footprint, px, py, cth, segments, circles, buf, near, state):
                        th = pth  # the last clear sub-step's heading (clear at px, py)
                    lo, hi = 0.0, 1.0
                    for _ in range(8):
                        mid = 0.5 * (lo + hi)
                        if _hits(
                            footprint,
                            px + mid * (cx - px),
                            py + mid * (cy - py),
                            th,
                            segments,
                            circles,
                            buf,
                            near,
                            state,
                        ):
                            hi = mid
                        else:
                            lo = mid
                    gx = px + lo * (cx - px)
                    gy = py + lo * (cy - py)
                    gth = th
                    break
                px, py, pth = cx, cy, cth
        if contact:
            if holonomic:  # what the body did move, in its frame at the step's start
                c, s = math.cos(th0), math.sin(th0)
                v = (c * (gx - x0) + s * (gy - y0)) / dt
                vy = (c * (gy - y0) - s * (gx - x0)) / dt
            else:
                moved = math.hypot(gx - x0, gy - y0)
                v = math.copysign(moved / dt, v) if v != 0.0 else 0.0
            w = _wrap(gth - th0) / dt
        state[S_X], state[S_Y], state[S_TH] = gx, gy, gth
        if holonomic:  # the body frame turns: a = dv/dt + w x v
            state[S_DV] = (v - state[S_V]) / dt - w * vy
            state[S_LAT] = (vy - state[S_VY]) / dt + w * v
        else:
            state[S_DV] = (v - state[S_V]) / dt
            state[S_LAT] = v * w
        state[S_V] = v
        state[S_VY] = vy
        state[S_W] = w
        if contact and state[S_CONTACT] == 0.0:
            state[S_CONTACTS] += 1.0
        state[S_CONTACT] = 1.0 if contact else 0.0
    return noise_pos


# the packed arguments' header, after the state: dt, then rows and columns of the
# footprint, the segments, the circles and the noise
_H = STATE_SIZE
_PARAMS = _H + 9


@numba.njit(cache=True)
def advance_packed(pack: np.ndarray, near: np.ndarray, noise_pos: int, steps: int) -> int:
    """:func:`advance` with its float64 arrays and ``dt`` in one array (see
    :class:`PhysicsPack`): the compiled entry unboxes two arrays per call, not seven."""
    dt = pack[_H]
    o = _PARAMS + N_PARAMS
    n, c = int(pack[_H + 1]), int(pack[_H + 2])
    footprint = pack[o : o + n * c].reshape((n, c))
    o += n * c
    n, c = int(pack[_H + 3]), int(pack[_H + 4])
    segments = pack[o : o + n * c].reshape((n, c))
    o += n * c
    n, c = int(pack[_H + 5]), int(pack[_H + 6])
    circles = pack[o : o + n * c].reshape((n, c))
    o += n * c
    n, c = int(pack[_H + 7]), int(pack[_H + 8])
    noise = pack[o : o + n * c].reshape((n, c))
    return advance(
        pack[:STATE_SIZE],
        pack[_PARAMS : _PARAMS + N_PARAMS],
        dt,
        footprint,
        segments,
        circles,
        near,
        noise,
        noise_pos,
        steps,
    )


class PhysicsPack:
    """One float64 array holding :func:`advance`'s state, parameters, ``dt``, footprint,
    segments, circles and slip noise, for :func:`advance_packed`; ``state`` and
    ``noise`` are views into it (the state updated in place, the noise refilled in
    place). ``params`` without ``P_KIND`` (five entries) is a differential drive.

    Raises:
        ValueError: ``state`` or ``params`` of the wrong size.
    """

    def __init__(
        self,
        state: np.ndarray,
        params: np.ndarray,
        dt: float,
        footprint: np.ndarray,
        segments: np.ndarray,
        circles: np.ndarray,
        noise: np.ndarray,
    ) -> None:
        params = np.asarray(params, dtype=np.float64).reshape(-1)
        if params.size == P_KIND:
            params = np.append(params, DRIVE_DIFF)
        if params.size != N_PARAMS or np.size(state) != STATE_SIZE:
            raise ValueError(
                f"need {STATE_SIZE} state entries and {N_PARAMS} parameters, got "
                f"{np.size(state)} and {params.size}"
            )
        parts = [np.asarray(a, dtype=np.float64) for a in (footprint, segments, circles, noise)]
        shapes = [(a.shape[0], a.shape[1]) for a in parts]
        head = np.array([float(dt)] + [float(v) for shape in shapes for v in shape])
        pieces = [np.asarray(state, dtype=np.float64), head, params]
        self.array = np.concatenate(pieces + [a.reshape(-1) for a in parts])
        self.state = self.array[:STATE_SIZE]
        self.noise = self.array[self.array.size - parts[3].size :].reshape(shapes[3])


def compiled_entry(kernel: F, *args: Any) -> F:
    """``kernel``'s machine code for the types of ``args``, callable without numba's
    per-call type dispatch (a few hundred ns per call, which the simulator pays at the
    physics rate); ``kernel`` itself when numba offers no such entry.

    ``kernel(*args)`` is called once (compiling or loading it); the result must then only
    be called with arguments of those same types.
    """
    kernel(*args)
    overloads = getattr(kernel, "overloads", None)
    if overloads is None:
        return kernel
    key = tuple(numba.typeof(a) for a in args)
    cres = overloads.get(key)
    entry = getattr(cres, "entry_point", None)
    return entry if callable(entry) else kernel
