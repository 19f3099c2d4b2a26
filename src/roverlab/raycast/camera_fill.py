"""Camera rendering, second pass: pixels from the surfaces found along each azimuth.

Part of :func:`roverlab.raycast.camera.render` (see that module for the camera model);
the surfaces come from :func:`roverlab.raycast.camera_hits.collect_hits`.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.camera_hits import FLOOR_DARK, MAX_LAYERS, row_ceil, row_floor, to_u8

__all__ = ["fill_level", "fill_pitched"]

_jit = numba.njit(cache=True, nogil=True)


@_jit
def _put_sky(
    rgb: NDArray[np.uint8], depth: NDArray[np.float32], v: int, u: int, sky: NDArray[np.uint8]
) -> None:
    rgb[v, u, 0] = sky[0]
    rgb[v, u, 1] = sky[1]
    rgb[v, u, 2] = sky[2]
    depth[v, u] = np.nan


@_jit
def _texel(
    tex_data: NDArray[np.uint8],
    tex_off: NDArray[np.int64],
    tex_shape: NDArray[np.int64],
    ti: int,
    tu: float,
    tv: float,
) -> int:
    """Row of ``tex_data`` holding texture ``ti`` at ``(u, v)`` in [0, 1]^2."""
    th = tex_shape[ti, 0]
    tw = tex_shape[ti, 1]
    row = min(max(int(tv * th), 0), th - 1)
    col = min(max(int(tu * tw), 0), tw - 1)
    return int(tex_off[ti] + row * tw + col)


@_jit
def _floor_factor(wx: float, wy: float) -> float:
    return 1.0 if ((int(math.floor(wx)) + int(math.floor(wy))) & 1) == 0 else FLOOR_DARK


_EMPTY = -1  # owner of a pixel that sees the floor or the sky


@_jit
def fill_level(
    x: float,
    y: float,
    z: float,
    yaw: float,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    near: float,
    far: float,
    segz: NDArray[np.float64],
    segtex: NDArray[np.int32],
    circz: NDArray[np.float64],
    tex_data: NDArray[np.uint8],
    tex_off: NDArray[np.int64],
    tex_shape: NDArray[np.int64],
    floor_rgb: NDArray[np.uint8],
    sky_rgb: NDArray[np.uint8],
    nseg: int,
    n_hits: NDArray[np.int64],
    h_in: NDArray[np.float64],
    h_out: NDArray[np.float64],
    h_id: NDArray[np.int64],
    h_u: NDArray[np.float64],
    h_shade: NDArray[np.float64],
    h_rgb: NDArray[np.uint8],
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
) -> None:
    """Level camera: each column is one vertical plane, so each surface covers a row span.

    Pixel ``(u, v)`` has slope ``s = b / L`` (``b = (cy - v) / fy``,
    ``L = sqrt(1 + a^2)``, ``a = (cx - u) / fx``): a surface at horizontal distance ``t``
    spanning ``[zlo, zmax]`` covers the rows with ``b`` in ``[(zlo - z) L / t,
    (zmax - z) L / t]``; the floor seen by row ``v`` is at depth ``-z / b``. First, per
    column, the spans are painted near to far into ``own`` (surface ``m``, cap
    ``MAX_LAYERS + m`` or ``_EMPTY`` for floor or sky) and kept as runs of rows; then
    the image is written row by row, each column advancing through its runs.
    """
    height, width = depth.shape
    nk = MAX_LAYERS
    floor_seen = z > 0.0
    nan32 = np.float32(np.nan)
    own = np.empty(height, dtype=np.int8)
    max_runs = 4 * nk + 4  # <= 2 spans per surface, each splitting at most one run
    run_end = np.empty((width, max_runs), dtype=np.int32)  # last row of each run
    run_own = np.empty((width, max_runs), dtype=np.int8)
    h_depth = np.empty((width, nk), dtype=np.float32)
    h_tex = np.full((width, nk), -1, dtype=np.int64)  # texture index of textured walls
    h_col = np.zeros((width, nk), dtype=np.int64)  # and the texture column they show
    h_zc = np.zeros((width, nk))  # height of the cap a cylinder shows

    # ---- per column: which surface each row sees ----
    for u in range(width):
        a = (cx - u) / fx
        big_l = math.sqrt(1.0 + a * a)
        invl = 1.0 / big_l
        own[:] = _EMPTY
        for m in range(n_hits[u]):
            t = h_in[u, m]
            d = t * invl
            if d > far:
                break
            h_depth[u, m] = d if d >= near else nan32
            it = h_id[u, m]
            if it < nseg:
                zmin = segz[it, 0]
                zmax = segz[it, 1]
                ti = segtex[it]
                if ti >= 0:
                    tw = tex_shape[ti, 1]
                    h_tex[u, m] = ti
                    h_col[u, m] = min(max(int(h_u[u, m] * tw), 0), tw - 1)
            else:
                zmin = circz[it - nseg, 0]
                zmax = circz[it - nseg, 1]
                h_zc[u, m] = zmax if z > zmax else zmin
            zlo = max(zmin, 0.0) if floor_seen else zmin
            # side face
            if zlo <= zmax:
                if t > 0.0:
                    v0 = row_ceil(cy - fy * (zmax - z) * big_l / t, height)
                    v1 = row_floor(cy - fy * (zlo - z) * big_l / t, height)
                elif zlo <= z <= zmax:
                    v0 = 0
                    v1 = height - 1
                else:
                    v0 = 0
                    v1 = -1
                for v in range(max(v0, 0), min(v1, height - 1) + 1):
                    if own[v] == _EMPTY:
                        own[v] = m
            if it < nseg:
                continue
            # cylinder caps, seen between the entry and exit distances
            tout = h_out[u, m]
            if z > zmax and (zmax >= 0.0 or not floor_seen):
                # top: rows with s in ((zmax - z) / t, (zmax - z) / tout]
                v0 = row_ceil(cy - fy * (zmax - z) * big_l / tout, height)
                if t > 0.0:
                    v1 = row_ceil(cy - fy * (zmax - z) * big_l / t, height) - 1
                else:
                    v1 = height - 1
                for v in range(max(v0, 0), min(v1, height - 1) + 1):
                    if own[v] == _EMPTY:
                        own[v] = nk + m
            if z < zmin:
                # bottom: rows with s in [(zmin - z) / tout, (zmin - z) / t)
                v0 = row_floor(cy - fy * (zmin - z) * big_l / t, height) + 1 if t > 0.0 else 0
                v1 = row_floor(cy - fy * (zmin - z) * big_l / tout, height)
                for v in range(max(v0, 0), min(v1, height - 1) + 1):
                    if own[v] == _EMPTY:
                        own[v] = nk + m
        r = 0
        for v in range(1, height):
            if own[v] != own[v - 1]:
                run_end[u, r] = v - 1
                run_own[u, r] = own[v - 1]
                r += 1
        run_end[u, r] = height - 1
        run_own[u, r] = own[height - 1]

    # ---- row by row: colours and depths ----
    cur = np.zeros(width, dtype=np.int64)
    cur_end = np.empty(width, dtype=np.int32)
    cur_own = np.empty(width, dtype=np.int8)
    for u in range(width):
        cur_end[u] = run_end[u, 0]
        cur_own[u] = run_own[u, 0]
    floor_cols = np.empty((2, 3), dtype=np.uint8)
    for ch in range(3):
        floor_cols[0, ch] = floor_rgb[ch]
        floor_cols[1, ch] = to_u8(floor_rgb[ch] * FLOOR_DARK)
    cyaw = math.cos(yaw)
    syaw = math.sin(yaw)
    for v in range(height):
        b = (cy - v) / fy
        fd = -z / b if (floor_seen and b < 0.0) else math.inf
        floor_ok = fd <= far
        fdo = np.float32(fd) if (floor_ok and fd >= near) else nan32
        # the floor point of pixel u is (x, y) + fd * R(yaw) (1, a_u): linear in u
        fwx = x + fd * (cyaw - syaw * cx / fx) if floor_ok else 0.0
        fwy = y + fd * (syaw + cyaw * cx / fx) if floor_ok else 0.0
        gwx = fd * syaw / fx if floor_ok else 0.0
        gwy = -fd * cyaw / fx if floor_ok else 0.0
        for u in range(width):
            if v > cur_end[u]:
                k = cur[u] + 1
                cur[u] = k
                cur_end[u] = run_end[u, k]
                cur_own[u] = run_own[u, k]
            o = cur_own[u]
            if o == _EMPTY:
                if floor_ok:
                    k = (int(math.floor(fwx + u * gwx)) + int(math.floor(fwy + u * gwy))) & 1
                    rgb[v, u, 0] = floor_cols[k, 0]
                    rgb[v, u, 1] = floor_cols[k, 1]
                    rgb[v, u, 2] = floor_cols[k, 2]
                    depth[v, u] = fdo
                else:
                    rgb[v, u, 0] = sky_rgb[0]
                    rgb[v, u, 1] = sky_rgb[1]
                    rgb[v, u, 2] = sky_rgb[2]
                    depth[v, u] = nan32
            elif o < nk:
                depth[v, u] = h_depth[u, o]
                ti = h_tex[u, o]
                if ti >= 0:
                    it = h_id[u, o]
                    zmin = segz[it, 0]
                    zmax = segz[it, 1]
                    zt = z + b * h_in[u, o] / math.sqrt(1.0 + ((cx - u) / fx) ** 2)
                    th = tex_shape[ti, 0]
                    tv = (zmax - zt) / (zmax - zmin) if zmax > zmin else 0.0
                    row = min(max(int(tv * th), 0), th - 1)
                    p = tex_off[ti] + row * tex_shape[ti, 1] + h_col[u, o]
                    sh = h_shade[u, o]
                    rgb[v, u, 0] = to_u8(tex_data[p, 0] * sh)
                    rgb[v, u, 1] = to_u8(tex_data[p, 1] * sh)
                    rgb[v, u, 2] = to_u8(tex_data[p, 2] * sh)
                else:
                    rgb[v, u, 0] = h_rgb[u, o, 0]
                    rgb[v, u, 1] = h_rgb[u, o, 1]
                    rgb[v, u, 2] = h_rgb[u, o, 2]
            else:
                m = o - nk
                dc = (h_zc[u, m] - z) / b
                if dc <= far:
                    rgb[v, u, 0] = h_rgb[u, m, 3]
                    rgb[v, u, 1] = h_rgb[u, m, 4]
                    rgb[v, u, 2] = h_rgb[u, m, 5]
                    depth[v, u] = dc if dc >= near else nan32
                else:
                    rgb[v, u, 0] = sky_rgb[0]
                    rgb[v, u, 1] = sky_rgb[1]
                    rgb[v, u, 2] = sky_rgb[2]
                    depth[v, u] = nan32


@_jit
def fill_pitched(
    x: float,
    y: float,
    z: float,
    pitch: float,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    near: float,
    far: float,
    q0: float,
    dq: float,
    segz: NDArray[np.float64],
    segtex: NDArray[np.int32],
    circz: NDArray[np.float64],
    tex_data: NDArray[np.uint8],
    tex_off: NDArray[np.int64],
    tex_shape: NDArray[np.int64],
    floor_rgb: NDArray[np.uint8],
    sky_rgb: NDArray[np.uint8],
    nseg: int,
    az_dx: NDArray[np.float64],
    az_dy: NDArray[np.float64],
    n_hits: NDArray[np.int64],
    h_in: NDArray[np.float64],
    h_out: NDArray[np.float64],
    h_id: NDArray[np.int64],
    h_u: NDArray[np.float64],
    h_shade: NDArray[np.float64],
    h_rgb: NDArray[np.uint8],
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
) -> None:
    """Tilted camera: per pixel, walk the surfaces of the nearest azimuth sample."""
    height, width = depth.shape
    n_az = n_hits.shape[0]
    ct = math.cos(pitch)
    st = math.sin(pitch)
    floor_seen = z > 0.0
    nan32 = np.float32(np.nan)
    floor_cols = np.empty((2, 3), dtype=np.uint8)
    for ch in range(3):
        floor_cols[0, ch] = floor_rgb[ch]
        floor_cols[1, ch] = to_u8(floor_rgb[ch] * FLOOR_DARK)
    # per azimuth sample: 1 / sqrt(1 + q^2); the horizontal length of a pixel's ray per
    # unit depth is hx * sqrt(1 + q^2), taken at the sample the pixel uses
    inv_root = np.empty(n_az)
    root = np.empty(n_az)
    for k in range(n_az):
        q = q0 - k * dq
        root[k] = math.sqrt(1.0 + q * q)
        inv_root[k] = 1.0 / root[k]
    inv_dq = 1.0 / dq
    for v in range(height):
        b = (cy - v) / fy
        hx = ct + b * st
        vz = -st + b * ct
        inv_hx = 1.0 / hx
        slope = vz * inv_hx  # height gained per horizontal metre, times sqrt(1 + q^2)
        # the floor: same z-depth -z / vz across the row, at horizontal distance
        # (-z / vz) * hx * sqrt(1 + q^2)
        floor_row = -z / vz * hx if (floor_seen and vz < 0.0) else math.inf
        for px in range(width):
            a = (cx - px) / fx
            u = min(max(int((q0 - a * inv_hx) * inv_dq + 0.5), 0), n_az - 1)
            invl = inv_hx * inv_root[u]
            s = slope * inv_root[u]
            hfloor = floor_row * root[u]
            d = math.inf
            c0 = sky_rgb[0]
            c1 = sky_rgb[1]
            c2 = sky_rgb[2]
            for m in range(n_hits[u]):
                t = h_in[u, m]
                if t > hfloor:
                    break
                it = h_id[u, m]
                zt = z + s * t
                if it < nseg:
                    zmin = segz[it, 0]
                    zmax = segz[it, 1]
                    if zt < zmin or zt > zmax:
                        continue
                    ti = segtex[it]
                    if ti >= 0:
                        sh = h_shade[u, m]
                        tv = (zmax - zt) / (zmax - zmin) if zmax > zmin else 0.0
                        p = _texel(tex_data, tex_off, tex_shape, ti, h_u[u, m], tv)
                        c0 = to_u8(tex_data[p, 0] * sh)
                        c1 = to_u8(tex_data[p, 1] * sh)
                        c2 = to_u8(tex_data[p, 2] * sh)
                    else:
                        c0 = h_rgb[u, m, 0]
                        c1 = h_rgb[u, m, 1]
                        c2 = h_rgb[u, m, 2]
                    d = t * invl
                    break
                zmin = circz[it - nseg, 0]
                zmax = circz[it - nseg, 1]
                if zmin <= zt <= zmax:
                    d = t * invl
                    c0 = h_rgb[u, m, 0]
                    c1 = h_rgb[u, m, 1]
                    c2 = h_rgb[u, m, 2]
                    break
                if zt > zmax and s < 0.0 and (zmax - z) / s <= h_out[u, m]:
                    d = (zmax - z) / s * invl
                elif zt < zmin and s > 0.0 and (zmin - z) / s <= h_out[u, m]:
                    d = (zmin - z) / s * invl
                else:
                    continue
                c0 = h_rgb[u, m, 3]
                c1 = h_rgb[u, m, 4]
                c2 = h_rgb[u, m, 5]
                break
            if d == math.inf and hfloor < math.inf:
                k = (
                    int(math.floor(x + hfloor * az_dx[u])) + int(math.floor(y + hfloor * az_dy[u]))
                ) & 1
                c0 = floor_cols[k, 0]
                c1 = floor_cols[k, 1]
                c2 = floor_cols[k, 2]
                d = hfloor * invl
            if d <= far:
                rgb[v, px, 0] = c0
                rgb[v, px, 1] = c1
                rgb[v, px, 2] = c2
                depth[v, px] = d if d >= near else nan32
            else:
                _put_sky(rgb, depth, v, px, sky_rgb)
