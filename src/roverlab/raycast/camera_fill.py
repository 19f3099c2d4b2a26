"""Camera rendering, second pass for a tilted camera: pixels from the surfaces per azimuth.

Part of :func:`roverlab.raycast.camera.render` (see that module for the camera model);
the surfaces come from :func:`roverlab.raycast.camera_hits.collect_hits`.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.camera_hits import FLOOR_DARK, to_u8

__all__ = ["fill_pitched"]

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
