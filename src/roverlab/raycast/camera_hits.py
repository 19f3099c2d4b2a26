"""Camera rendering, first pass: the nearest surfaces along each image column's azimuth.

Part of :func:`roverlab.raycast.camera.render` (see that module for the camera model);
:mod:`roverlab.raycast.camera_fill` turns the surfaces into pixels.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.accel import circle_hit, dda_steps, grid_entry, segment_hit

__all__ = ["FLOOR_DARK", "MAX_LAYERS", "collect_hits", "row_ceil", "row_floor", "to_u8"]

#: Surfaces kept per image column, nearest first. Surfaces behind one that covers the
#: whole column are dropped; past this many, the farthest are (then unseen).
MAX_LAYERS = 8

_jit = numba.njit(cache=True, nogil=True)

_LIGHT_AZIMUTH = 0.9  # rad, fixed world direction of the light
_AMBIENT = 0.6
_DIFFUSE = 0.4
_FALLOFF = 0.03  # per metre: shade /= 1 + falloff * distance
_MIN_FALLOFF = 0.55
FLOOR_DARK = 0.88  # odd checker tiles
_CAP_SHADE = 1.08


@_jit
def _shade(nx: float, ny: float, dist: float) -> float:
    lx = math.cos(_LIGHT_AZIMUTH)
    ly = math.sin(_LIGHT_AZIMUTH)
    s = _AMBIENT + _DIFFUSE * abs(nx * lx + ny * ly)
    return s * max(_MIN_FALLOFF, 1.0 / (1.0 + _FALLOFF * dist))


@_jit
def to_u8(v: float) -> np.uint8:
    return np.uint8(min(255.0, max(0.0, v + 0.5)))


@_jit
def row_ceil(val: float, n: int) -> int:
    """``ceil(val)`` clamped to [-1, n] (safe for huge or infinite values)."""
    return int(math.ceil(min(max(val, -1.0), float(n))))


@_jit
def row_floor(val: float, n: int) -> int:
    """``floor(val)`` clamped to [-1, n]."""
    return int(math.floor(min(max(val, -1.0), float(n))))


@_jit
def collect_hits(
    x: float,
    y: float,
    z: float,
    yaw: float,
    n_az: int,
    q0: float,
    dq: float,
    el_top: float,
    el_bot: float,
    hx_max: float,
    far: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    cstart: NDArray[np.int32],
    items: NDArray[np.int32],
    nseg: int,
    segrgb: NDArray[np.uint8],
    circrgb: NDArray[np.uint8],
) -> tuple[
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.int64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.int64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.uint8],
]:
    """The MAX_LAYERS nearest surfaces along each azimuth sample ``q_k = q0 - k * dq``.

    ``q`` is the tangent of the azimuth relative to ``yaw``; ``el_top``/``el_bot`` the
    tangents of the elevations of the top and bottom image rows in the camera's vertical
    plane; ``hx_max`` the largest horizontal ray length per unit depth at ``q = 0``.
    Per surface: entry and exit distances, primitive item, texture ``u``, shade and the
    shaded colours of its side (``[..., 0:3]``) and cap (``[..., 3:6]``).
    """
    nk = MAX_LAYERS
    floor_seen = z > 0.0
    az_dx = np.empty(n_az)
    az_dy = np.empty(n_az)
    n_hits = np.zeros(n_az, dtype=np.int64)
    h_in = np.empty((n_az, nk))
    h_out = np.empty((n_az, nk))
    h_id = np.empty((n_az, nk), dtype=np.int64)
    h_u = np.empty((n_az, nk))
    h_shade = np.empty((n_az, nk))
    h_rgb = np.empty((n_az, nk, 6), dtype=np.uint8)
    for u in range(n_az):
        q = q0 - u * dq
        root = math.sqrt(1.0 + q * q)
        psi = yaw + math.atan(q)
        dx = math.cos(psi)
        dy = math.sin(psi)
        az_dx[u] = dx
        az_dy[u] = dy
        # height slopes (dz per horizontal metre) of the highest and lowest rows, and the
        # horizontal distance beyond which every pixel's depth exceeds far
        s_top = max(el_top, el_bot) / root
        s_bot = min(el_top, el_bot) / root
        hmax = far * hx_max * root

        t0, ix, iy = grid_entry(x, y, dx, dy, gx0, gy0, cell, nx, ny)
        n = 0
        block = math.inf
        if t0 <= hmax:
            stepx, stepy, offx, offy, invdx, invdy = dda_steps(dx, dy)
            while True:
                tmx = (gx0 + (ix + offx) * cell - x) * invdx if stepx != 0 else math.inf
                tmy = (gy0 + (iy + offy) * cell - y) * invdy if stepy != 0 else math.inf
                texit = min(tmx, tmy)
                c = iy * nx + ix
                for k in range(cstart[c], cstart[c + 1]):
                    it = items[k]
                    if it < nseg:
                        t, su = segment_hit(
                            x, y, dx, dy, segs[it, 0], segs[it, 1], segs[it, 2], segs[it, 3]
                        )
                        tout = t
                        zmin = segz[it, 0]
                        zmax = segz[it, 1]
                    else:
                        j = it - nseg
                        t, tout = circle_hit(x, y, dx, dy, circs[j, 0], circs[j, 1], circs[j, 2])
                        su = 0.0
                        zmin = circz[j, 0]
                        zmax = circz[j, 1]
                    if t > hmax or t > block or (n == nk and t >= h_in[u, nk - 1]):
                        continue
                    dup = False
                    for m in range(n):
                        if h_id[u, m] == it:
                            dup = True
                            break
                    if dup:
                        continue
                    # insertion into the sorted list (the farthest drops out when full)
                    pos = n if n < nk else nk - 1
                    while pos > 0 and h_in[u, pos - 1] > t:
                        h_in[u, pos] = h_in[u, pos - 1]
                        h_out[u, pos] = h_out[u, pos - 1]
                        h_id[u, pos] = h_id[u, pos - 1]
                        h_u[u, pos] = h_u[u, pos - 1]
                        pos -= 1
                    h_in[u, pos] = t
                    h_out[u, pos] = tout
                    h_id[u, pos] = it
                    h_u[u, pos] = su
                    if n < nk:
                        n += 1
                    # covers every row of the image at this distance: nothing behind shows
                    zhi = z + s_top * t
                    zlo = z + s_bot * t
                    if floor_seen:
                        zlo = max(zlo, 0.0)
                    if zmin <= zlo and zmax >= zhi:
                        block = t
                        n = pos + 1
                if block <= texit or (n == nk and h_in[u, nk - 1] <= texit) or texit > hmax:
                    break
                if tmx < tmy:
                    ix += stepx
                    if ix < 0 or ix >= nx:
                        break
                else:
                    iy += stepy
                    if iy < 0 or iy >= ny:
                        break
        n_hits[u] = n
        for m in range(n):
            it = h_id[u, m]
            t = h_in[u, m]
            if it < nseg:
                ex = segs[it, 2] - segs[it, 0]
                ey = segs[it, 3] - segs[it, 1]
                el = math.sqrt(ex * ex + ey * ey)
                sh = _shade(-ey / el, ex / el, t) if el > 0.0 else _shade(-dx, -dy, t)
                for ch in range(3):
                    h_rgb[u, m, ch] = to_u8(segrgb[it, ch] * sh)
                    h_rgb[u, m, 3 + ch] = h_rgb[u, m, ch]
            else:
                j = it - nseg
                r = circs[j, 2]
                if t > 0.0 and r > 0.0:
                    px = x + t * dx - circs[j, 0]
                    py = y + t * dy - circs[j, 1]
                    sh = _shade(px / r, py / r, t)
                else:
                    sh = _shade(-dx, -dy, t)
                for ch in range(3):
                    h_rgb[u, m, ch] = to_u8(circrgb[j, ch] * sh)
                    h_rgb[u, m, 3 + ch] = to_u8(circrgb[j, ch] * sh * _CAP_SHADE)
            h_shade[u, m] = sh
    return az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb
