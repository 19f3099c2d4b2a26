"""2.5-D pinhole camera: RGB and depth images of a Scene, and depth back-projection.

:func:`render` casts planar rays through the scene's grid, one per image column for a level
camera, and keeps the :data:`MAX_LAYERS` nearest surfaces along each (stopping at the first
that covers the whole vertical field of view). Each pixel then takes them from near to far:
the first whose ``[zmin, zmax]`` holds the height of the pixel's ray at that distance is
what the pixel sees (a cylinder's top or bottom cap is seen between its entry and exit
distances); a ray that reaches the ground (z = 0) first sees the floor (1 m checker tiles);
a ray that meets nothing within ``far`` sees the sky. Walls are faces without thickness: a
box seen from above its top shows its inner faces, not a lid.

Camera model: square pixels, principal point at the image centre,
``fx = fy = (width / 2) / tan(hfov / 2)``, ``cx = (width - 1) / 2``,
``cy = (height - 1) / 2`` (pixel ``(u, v)`` has its centre at ``(u, v)``), so the pixel
ray in the camera body frame (x forward, y left, z up) is ``(1, (cx - u)/fx, (cy - v)/fy)``.
``pitch > 0`` tilts the camera down (a positive rotation about the body y axis, REP 103).
With ``pitch = 0`` the projection is an exact pinhole and each surface covers a span of
rows of its column (the fast path). With a pitch the pixels of a column look along
different azimuths: surfaces are gathered along azimuths spaced at most one column apart
and each pixel uses the one nearest its own ray, so the image is the tilted pinhole's to
within half a column (straight edges stay straight); this path costs 2-3 times more.

Depth is the z-depth along the optical axis (as a depth camera reports it), ``nan`` for
sky, beyond ``far`` or nearer than ``near`` (such pixels keep their colour). Colours are
flat-shaded by a fixed light and a mild distance falloff: the same inputs give the same
image, bit for bit. Noise is left to the caller.

Frames: :func:`depth_to_points` returns points in the camera's optical frame (x right,
y down, z forward, REP 103 ``_optical``); :func:`optical_to_body` and
:func:`body_to_optical` convert to and from the body frame (x forward, y left, z up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from roverlab.raycast.accel import circle_hit, grid_entry, scene_grid, segment_hit
from roverlab.raycast.errors import RaycastInputError
from roverlab.raycast.scene import Scene

__all__ = [
    "MAX_LAYERS",
    "CameraIntrinsics",
    "body_to_optical",
    "camera_intrinsics",
    "depth_to_points",
    "optical_to_body",
    "render",
]

#: Surfaces kept per image column, nearest first. Surfaces behind one that covers the
#: whole column are dropped; past this many, the farthest are (then unseen).
MAX_LAYERS = 8

_jit = numba.njit(cache=True, nogil=True)

_LIGHT_AZIMUTH = 0.9  # rad, fixed world direction of the light
_AMBIENT = 0.6
_DIFFUSE = 0.4
_FALLOFF = 0.03  # per metre: shade /= 1 + falloff * distance
_MIN_FALLOFF = 0.55
_FLOOR_DARK = 0.88  # odd checker tiles
_CAP_SHADE = 1.08
_TEX_CACHE_ATTR = "_raycast_textures"


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics of a :func:`render` image (``sensor_msgs/CameraInfo`` K)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def k(self) -> NDArray[np.float64]:
        """The 3x3 camera matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]``."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def vfov(self) -> float:
        """Vertical field of view (rad) between the outer pixel edges."""
        return 2.0 * math.atan(0.5 * self.height / self.fy)


def camera_intrinsics(width: int, height: int, hfov: float) -> CameraIntrinsics:
    """Intrinsics of a ``width`` x ``height`` image with horizontal field of view ``hfov``.

    Raises:
        RaycastInputError: non-positive size, ``hfov`` outside (0, pi).
    """
    w = int(width)
    h = int(height)
    fov = float(hfov)
    if w <= 0 or h <= 0:
        raise RaycastInputError(f"image size must be positive, got {width}x{height}")
    if not 0.0 < fov < math.pi:
        raise RaycastInputError(f"hfov must be in (0, pi) rad, got {hfov}")
    f = 0.5 * w / math.tan(0.5 * fov)
    return CameraIntrinsics(width=w, height=h, fx=f, fy=f, cx=0.5 * (w - 1), cy=0.5 * (h - 1))


@_jit
def _shade(nx: float, ny: float, dist: float) -> float:
    lx = math.cos(_LIGHT_AZIMUTH)
    ly = math.sin(_LIGHT_AZIMUTH)
    s = _AMBIENT + _DIFFUSE * abs(nx * lx + ny * ly)
    return s * max(_MIN_FALLOFF, 1.0 / (1.0 + _FALLOFF * dist))


@_jit
def _to_u8(v: float) -> np.uint8:
    return np.uint8(min(255.0, max(0.0, v + 0.5)))


@_jit
def _row_ceil(val: float, n: int) -> int:
    """``ceil(val)`` clamped to [-1, n] (safe for huge or infinite values)."""
    return int(math.ceil(min(max(val, -1.0), float(n))))


@_jit
def _row_floor(val: float, n: int) -> int:
    """``floor(val)`` clamped to [-1, n]."""
    return int(math.floor(min(max(val, -1.0), float(n))))


@_jit
def _collect_hits(
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
            stepx = 1 if dx > 0.0 else (-1 if dx < 0.0 else 0)
            stepy = 1 if dy > 0.0 else (-1 if dy < 0.0 else 0)
            offx = 1 if dx > 0.0 else 0
            offy = 1 if dy > 0.0 else 0
            invdx = 1.0 / dx if dx != 0.0 else 0.0
            invdy = 1.0 / dy if dy != 0.0 else 0.0
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
                    h_rgb[u, m, ch] = _to_u8(segrgb[it, ch] * sh)
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
                    h_rgb[u, m, ch] = _to_u8(circrgb[j, ch] * sh)
                    h_rgb[u, m, 3 + ch] = _to_u8(circrgb[j, ch] * sh * _CAP_SHADE)
            h_shade[u, m] = sh
    return az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb


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
    return 1.0 if ((int(math.floor(wx)) + int(math.floor(wy))) & 1) == 0 else _FLOOR_DARK


_EMPTY = -1  # owner of a pixel that sees the floor or the sky


@_jit
def _fill_level(
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
                    v0 = _row_ceil(cy - fy * (zmax - z) * big_l / t, height)
                    v1 = _row_floor(cy - fy * (zlo - z) * big_l / t, height)
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
                v0 = _row_ceil(cy - fy * (zmax - z) * big_l / tout, height)
                if t > 0.0:
                    v1 = _row_ceil(cy - fy * (zmax - z) * big_l / t, height) - 1
                else:
                    v1 = height - 1
                for v in range(max(v0, 0), min(v1, height - 1) + 1):
                    if own[v] == _EMPTY:
                        own[v] = nk + m
            if z < zmin:
                # bottom: rows with s in [(zmin - z) / tout, (zmin - z) / t)
                v0 = _row_floor(cy - fy * (zmin - z) * big_l / t, height) + 1 if t > 0.0 else 0
                v1 = _row_floor(cy - fy * (zmin - z) * big_l / tout, height)
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
        floor_cols[1, ch] = _to_u8(floor_rgb[ch] * _FLOOR_DARK)
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
                    rgb[v, u, 0] = _to_u8(tex_data[p, 0] * sh)
                    rgb[v, u, 1] = _to_u8(tex_data[p, 1] * sh)
                    rgb[v, u, 2] = _to_u8(tex_data[p, 2] * sh)
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
def _fill_pitched(
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
        floor_cols[1, ch] = _to_u8(floor_rgb[ch] * _FLOOR_DARK)
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
                        c0 = _to_u8(tex_data[p, 0] * sh)
                        c1 = _to_u8(tex_data[p, 1] * sh)
                        c2 = _to_u8(tex_data[p, 2] * sh)
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


@_jit
def _render_kernel(
    x: float,
    y: float,
    z: float,
    yaw: float,
    pitch: float,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    near: float,
    far: float,
    segs: NDArray[np.float64],
    segz: NDArray[np.float64],
    segrgb: NDArray[np.uint8],
    segtex: NDArray[np.int32],
    circs: NDArray[np.float64],
    circz: NDArray[np.float64],
    circrgb: NDArray[np.uint8],
    tex_data: NDArray[np.uint8],
    tex_off: NDArray[np.int64],
    tex_shape: NDArray[np.int64],
    floor_rgb: NDArray[np.uint8],
    sky_rgb: NDArray[np.uint8],
    gx0: float,
    gy0: float,
    cell: float,
    nx: int,
    ny: int,
    cstart: NDArray[np.int32],
    items: NDArray[np.int32],
    nseg: int,
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
) -> None:
    width = depth.shape[1]
    ct = math.cos(pitch)
    st = math.sin(pitch)
    # image rows in the camera's vertical plane: direction (hx, 0, vz) per unit depth
    b_top = cy / fy
    b_bot = -cy / fy
    hx_top = ct + b_top * st
    hx_bot = ct + b_bot * st
    hx_min = min(hx_top, hx_bot)
    hx_max = max(hx_top, hx_bot)
    el_top = (-st + b_top * ct) / hx_top  # tangent of the top row's elevation
    el_bot = (-st + b_bot * ct) / hx_bot
    # Azimuth samples, uniform in q = tan(azimuth - yaw), q_k = q0 - k * dq. Level camera:
    # one per column. Tilted: the pixels of a column look along different azimuths; sample
    # so that every pixel is within half a column of a sample and take the nearest.
    if pitch == 0.0:
        n_az = width
        q0 = cx / fx
        dq = 1.0 / fx
    else:
        q0 = (cx / fx) / hx_min
        n_az = min(int(math.ceil(2.0 * q0 * fx * hx_max - 1e-6)) + 1, 8 * width)
        if (n_az - width) % 2 != 0:
            n_az += 1  # same parity as the width: an odd image keeps its centre sample
        dq = 2.0 * q0 / max(n_az - 1, 1)
    az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb = _collect_hits(
        x, y, z, yaw, n_az, q0, dq, el_top, el_bot, hx_max, far,
        segs, segz, circs, circz, gx0, gy0, cell, nx, ny, cstart, items, nseg,
        segrgb, circrgb,
    )  # fmt: skip
    if pitch == 0.0:
        _fill_level(
            x, y, z, yaw, fx, fy, cx, cy, near, far,
            segz, segtex, circz, tex_data, tex_off, tex_shape,
            floor_rgb, sky_rgb, nseg,
            n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb, rgb, depth,
        )  # fmt: skip
    else:
        _fill_pitched(
            x, y, z, pitch, fx, fy, cx, cy, near, far, q0, dq,
            segz, segtex, circz, tex_data, tex_off, tex_shape,
            floor_rgb, sky_rgb, nseg,
            az_dx, az_dy, n_hits, h_in, h_out, h_id, h_u, h_shade, h_rgb, rgb, depth,
        )  # fmt: skip


def _packed_textures(
    scene: Scene,
) -> tuple[NDArray[np.uint8], NDArray[np.int64], NDArray[np.int64]]:
    """All textures as one (T, 3) texel array, per-texture offsets and (h, w); cached."""
    cached = scene.__dict__.get(_TEX_CACHE_ATTR)
    if cached is not None and cached[0] is scene.textures and cached[1] == len(scene.textures):
        return cached[2]
    chunks: list[NDArray[np.uint8]] = []
    offsets: list[int] = []
    shapes: list[tuple[int, int]] = []
    total = 0
    for i, tex in enumerate(scene.textures):
        img = np.asarray(tex)
        if img.ndim == 2:
            img = np.repeat(img[:, :, None], 3, axis=2)
        if img.ndim != 3 or img.shape[2] not in (3, 4) or img.shape[0] == 0 or img.shape[1] == 0:
            raise RaycastInputError(f"texture {i} must be an (H, W, 3) image, got {img.shape}")
        img = np.ascontiguousarray(img[:, :, :3], dtype=np.uint8)
        chunks.append(img.reshape(-1, 3))
        offsets.append(total)
        shapes.append((img.shape[0], img.shape[1]))
        total += img.shape[0] * img.shape[1]
    data = np.concatenate(chunks) if chunks else np.zeros((1, 3), dtype=np.uint8)
    off = np.array(offsets if offsets else [0], dtype=np.int64)
    shp = np.array(shapes if shapes else [(1, 1)], dtype=np.int64).reshape(-1, 2)
    packed = (np.ascontiguousarray(data), off, shp)
    scene.__dict__[_TEX_CACHE_ATTR] = (scene.textures, len(scene.textures), packed)
    return packed


def _rgb3(name: str, value: object) -> NDArray[np.uint8]:
    arr = np.asarray(value, dtype=np.int64).reshape(-1)
    if arr.shape[0] != 3 or arr.min() < 0 or arr.max() > 255:
        raise RaycastInputError(f"{name} must be three values in 0..255, got {value}")
    return arr.astype(np.uint8)


def render(
    scene: Scene,
    x: float,
    y: float,
    z: float,
    yaw: float,
    *,
    hfov: float,
    width: int,
    height: int,
    near: float,
    far: float,
    pitch: float = 0.0,
) -> tuple[NDArray[np.uint8], NDArray[np.float32]]:
    """Render the RGB and depth images seen by a pinhole camera (see the module docstring).

    Args:
        scene: the scene (its grid and packed textures are cached on it).
        x, y, z: camera centre in the world frame (m).
        yaw: heading of the optical axis (rad, world frame).
        hfov: horizontal field of view (rad), in (0, pi).
        width, height: image size (pixels).
        near, far: clip distances (m) along the optical axis, ``0 <= near < far``.
        pitch: downward tilt (rad); ``|pitch| + vfov / 2`` must stay below pi/2.

    Returns:
        ``(rgb, depth)``: (H, W, 3) uint8 image and (H, W) float32 z-depth in metres
        (``nan`` for sky, beyond ``far`` or nearer than ``near``).

    Raises:
        RaycastInputError: non-finite pose, bad size, field of view, clip range or pitch.
    """
    intr = camera_intrinsics(width, height, hfov)
    vals = [float(v) for v in (x, y, z, yaw, pitch)]
    if not all(math.isfinite(v) for v in vals):
        raise RaycastInputError(f"camera pose must be finite, got {vals}")
    x_, y_, z_, yaw_, pitch_ = vals
    near_ = float(near)
    far_ = float(far)
    if not (0.0 <= near_ < far_ and math.isfinite(far_)):
        raise RaycastInputError(f"need 0 <= near < far < inf, got near={near}, far={far}")
    if abs(pitch_) + 0.5 * intr.vfov >= 0.5 * math.pi:
        raise RaycastInputError(
            f"|pitch| + vfov/2 must be below pi/2, got pitch={pitch_}, vfov={intr.vfov}"
        )
    g = scene_grid(scene)
    tex_data, tex_off, tex_shape = _packed_textures(scene)
    rgb = np.empty((intr.height, intr.width, 3), dtype=np.uint8)
    depth = np.empty((intr.height, intr.width), dtype=np.float32)
    _render_kernel(
        x_, y_, z_, yaw_, pitch_, intr.fx, intr.fy, intr.cx, intr.cy, near_, far_,
        scene.segments, scene.segment_z, scene.segment_rgb, scene.segment_texture,
        scene.circles, scene.circle_z, scene.circle_rgb,
        tex_data, tex_off, tex_shape,
        _rgb3("floor_rgb", scene.floor_rgb), _rgb3("sky_rgb", scene.sky_rgb),
        g.x0, g.y0, g.cell, g.nx, g.ny, g.cell_start, g.items, g.n_segments,
        rgb, depth,
    )  # fmt: skip
    return rgb, depth


def depth_to_points(
    depth: ArrayLike, hfov: float, *, keep_invalid: bool = False
) -> NDArray[np.float32]:
    """Back-project a depth image into 3-D points in the camera's optical frame.

    Uses the intrinsics of :func:`camera_intrinsics` (those :func:`render` uses):
    ``X = (u - cx) * d / fx``, ``Y = (v - cy) * d / fy``, ``Z = d``.

    Args:
        depth: (H, W) z-depth image (m), ``nan``/``inf``/``<= 0`` for no return.
        hfov: horizontal field of view the image was rendered with (rad).
        keep_invalid: keep every pixel in row-major order (an organised cloud of
            ``H * W`` points, invalid ones all ``nan``) instead of dropping them.

    Returns:
        (N, 3) float32 points ``x right, y down, z forward``; row-major pixel order.

    Raises:
        RaycastInputError: ``depth`` not 2-D, bad ``hfov``.
    """
    d = np.asarray(depth, dtype=np.float32)
    if d.ndim != 2:
        raise RaycastInputError(f"depth must be an (H, W) image, got shape {d.shape}")
    intr = camera_intrinsics(d.shape[1], d.shape[0], hfov)
    xs = ((np.arange(intr.width) - intr.cx) / intr.fx).astype(np.float32)
    ys = ((np.arange(intr.height) - intr.cy) / intr.fy).astype(np.float32)
    valid = np.isfinite(d) & (d > 0)
    z = np.where(valid, d, np.float32(np.nan))
    grid = np.empty((d.shape[0], d.shape[1], 3), dtype=np.float32)
    grid[:, :, 0] = xs[None, :] * z
    grid[:, :, 1] = ys[:, None] * z
    grid[:, :, 2] = z
    pts = grid.reshape(-1, 3)
    if keep_invalid:
        return pts
    return np.ascontiguousarray(pts[valid.reshape(-1)])


def optical_to_body(points: ArrayLike) -> NDArray[np.floating]:
    """Optical-frame points (x right, y down, z forward) -> body frame (x fwd, y left, z up).

    Args:
        points: (..., 3) array.

    Returns:
        Array of the same shape and float dtype: ``(z, -x, -y)``.
    """
    p = np.asarray(points)
    if not np.issubdtype(p.dtype, np.floating):
        p = p.astype(np.float64)
    if p.shape[-1] != 3:
        raise RaycastInputError(f"points must have shape (..., 3), got {p.shape}")
    return np.stack([p[..., 2], -p[..., 0], -p[..., 1]], axis=-1)


def body_to_optical(points: ArrayLike) -> NDArray[np.floating]:
    """Body-frame points (x fwd, y left, z up) -> optical frame (x right, y down, z fwd).

    Args:
        points: (..., 3) array.

    Returns:
        Array of the same shape and float dtype: ``(-y, -z, x)``.
    """
    p = np.asarray(points)
    if not np.issubdtype(p.dtype, np.floating):
        p = p.astype(np.float64)
    if p.shape[-1] != 3:
        raise RaycastInputError(f"points must have shape (..., 3), got {p.shape}")
    return np.stack([-p[..., 1], -p[..., 2], p[..., 0]], axis=-1)
