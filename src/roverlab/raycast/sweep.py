"""Angular sweep for a fan of planar rays: each primitive tests only the beams it can hit.

The grid walk of :mod:`roverlab.raycast.lidar` pays per beam (cell steps, item lists). A
lidar's beams are one uniform fan, so for a scene of a few hundred primitives it is
cheaper to go the other way round: every segment or circle within reach subtends an arc
as seen from the sensor; only the beams in that arc (plus a margin of two beams and of
the segments' end tolerance) are tested, with the same hit functions the grid walk uses.
The nearest hit per beam is the minimum over the primitives, so the result is the grid
walk's to the bit (both equal testing every primitive).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.accel import SEGMENT_PARAM_EPS, circle_hit, segment_distance

__all__ = ["SWEEP_MAX_PRIMITIVES_PER_BEAM", "fan_step", "sweep_fan"]

_jit = numba.njit(cache=True, nogil=True)

#: The sweep is used while the scene holds at most this many primitives per beam of the
#: fan (its cost grows with the primitives, the grid walk's with the beams).
SWEEP_MAX_PRIMITIVES_PER_BEAM = 2.0

_TWO_PI = 2.0 * math.pi
# arcs are widened by this (rad) against rounding of atan2 / asin and of the hit tests
_ARC_MARGIN = 1e-6
# a sensor this close (m, per metre of its coordinates) to a segment's line or a
# circle's rim tests every beam against it: the arc's ends are ill-conditioned there
_NEAR = 1e-6
# segments are extended by this fraction of their length at both ends (>= the hit test's
# end tolerance SEGMENT_PARAM_EPS, with room for rounding)
_SEG_EXT = 4.0 * SEGMENT_PARAM_EPS + 1e-12


@_jit
def fan_step(angles: NDArray[np.float64]) -> float:
    """The spacing of a uniform increasing fan, or 0.0 when ``angles`` is not one.

    Uniform here means every angle is within a quarter of the spacing of
    ``angles[0] + i * step`` (rounding of ``min + i * increment`` stays far inside).
    """
    n = angles.shape[0]
    if n < 2:
        return 0.0
    step = (angles[n - 1] - angles[0]) / (n - 1)
    if not step > 0.0:
        return 0.0
    tol = 0.25 * step
    a0 = angles[0]
    for i in range(n):
        if abs(angles[i] - (a0 + i * step)) > tol:
            return 0.0
    return step


@_jit
def _test_range(
    k0: int,
    k1: int,
    skip: float,
    ox: float,
    oy: float,
    dxs: NDArray[np.float64],
    dys: NDArray[np.float64],
    kind: int,
    p: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Beams ``k0..k1``; those already holding a hit nearer than ``skip`` (below the
    primitive's nearest distance, with room for rounding) cannot change and are passed."""
    for k in range(max(k0, 0), min(k1, out.shape[0] - 1) + 1):
        if out[k] < skip:
            continue
        if kind == 0:
            t = segment_distance(ox, oy, dxs[k], dys[k], p[0], p[1], p[2], p[3], out[k])
        else:
            t, _ = circle_hit(ox, oy, dxs[k], dys[k], p[0], p[1], p[2])
        if t < out[k]:
            out[k] = t


@_jit
def sweep_fan(
    ox: float,
    oy: float,
    z: float,
    phi0: float,
    step: float,
    dxs: NDArray[np.float64],
    dys: NDArray[np.float64],
    rmax: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Nearest hit per beam of a uniform fan (``phi0 + i * step``, unit directions
    ``dxs``/``dys``) into ``out`` (``inf``: none within ``rmax``), as the grid walk.

    First every primitive in the laser's plane and within reach gets its nearest
    distance and its arc (or "every beam" when the sensor is on or next to it); then the
    primitives are taken nearest first, so most beams behind a nearer hit are passed
    with one comparison.
    """
    n = dxs.shape[0]
    for k in range(n):
        out[k] = math.inf
    nseg = segs.shape[0]
    total = nseg + circs.shape[0]
    reach = rmax * (1.0 + 1e-9) + 1e-9
    near = _NEAR * (1.0 + abs(ox) + abs(oy))
    dmin = np.empty(total)
    start = np.empty(total)
    width = np.empty(total)  # < 0: every beam
    keep = np.zeros(total, dtype=np.bool_)
    for it in range(nseg):
        if z < segz[it, 0] or z > segz[it, 1]:
            continue
        x0 = segs[it, 0]
        y0 = segs[it, 1]
        x1 = segs[it, 2]
        y1 = segs[it, 3]
        ex = x1 - x0
        ey = y1 - y0
        px = x0 - _SEG_EXT * ex - ox
        py = y0 - _SEG_EXT * ey - oy
        qx = x1 + _SEG_EXT * ex - ox
        qy = y1 + _SEG_EXT * ey - oy
        # nearest point of the (extended) segment: beyond reach, no beam can see it
        wx = qx - px
        wy = qy - py
        ll = wx * wx + wy * wy
        f = 0.0
        if ll > 0.0:
            f = min(1.0, max(0.0, -(px * wx + py * wy) / ll))
        cx = px + f * wx
        cy = py + f * wy
        d = math.sqrt(cx * cx + cy * cy)
        if d > reach:
            continue
        keep[it] = True
        dmin[it] = d
        el = math.sqrt(ex * ex + ey * ey)
        if el == 0.0 or abs(ex * (oy - y0) - ey * (ox - x0)) <= near * el:
            # the sensor on (or next to) the segment's line: the arc is ill-conditioned
            width[it] = -1.0
            continue
        cross = px * qy - py * qx
        dot = px * qx + py * qy
        if cross > 0.0:
            start[it] = math.atan2(py, px)
            width[it] = math.atan2(cross, dot)
        else:
            start[it] = math.atan2(qy, qx)
            width[it] = math.atan2(-cross, dot)
    for j in range(circs.shape[0]):
        if z < circz[j, 0] or z > circz[j, 1]:
            continue
        ccx = circs[j, 0] - ox
        ccy = circs[j, 1] - oy
        r = circs[j, 2]
        dist = math.sqrt(ccx * ccx + ccy * ccy)
        if dist - r > reach:
            continue
        i = nseg + j
        keep[i] = True
        dmin[i] = max(dist - r, 0.0)
        if dist - r <= near:
            width[i] = -1.0
            continue
        half = math.asin(min(1.0, r / dist))
        start[i] = math.atan2(ccy, ccx) - half
        width[i] = 2.0 * half
    order = np.argsort(np.where(keep, dmin, math.inf))
    prim = np.empty(4)
    for idx in range(total):
        it = order[idx]
        if not keep[it]:
            break
        if it < nseg:
            kind = 0
            for c in range(4):
                prim[c] = segs[it, c]
        else:
            kind = 1
            for c in range(3):
                prim[c] = circs[it - nseg, c]
        skip = dmin[it] * (1.0 - 1e-9) - 1e-12
        if width[it] < 0.0:
            _test_range(0, n - 1, skip, ox, oy, dxs, dys, kind, prim, out)
            continue
        # the arc, brought to start in [phi0, phi0 + 2 pi), and its turns before and after
        s = start[it] - _TWO_PI * math.floor((start[it] - phi0) / _TWO_PI)
        for turn in range(-1, 2):
            lo = s + turn * _TWO_PI - _ARC_MARGIN
            hi = lo + width[it] + 2.0 * _ARC_MARGIN
            k0 = int(math.floor((lo - phi0) / step)) - 2
            k1 = int(math.ceil((hi - phi0) / step)) + 2
            _test_range(k0, k1, skip, ox, oy, dxs, dys, kind, prim, out)
    for k in range(n):
        if out[k] > rmax:
            out[k] = math.inf
