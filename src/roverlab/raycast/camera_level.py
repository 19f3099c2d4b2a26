"""Camera rendering, second pass for a level camera: pixels from the surfaces per column.

Part of :func:`roverlab.raycast.camera.render` (see that module for the camera model).
Each image column of a level camera is one vertical plane, so each surface it meets
covers one span of rows. Per column the spans are painted near to far as intervals of
rows (a surface only takes rows nothing nearer took) and kept as runs of rows with one
owner. The image is then written row by row from a *template row* holding, per column,
what its current run shows when that does not depend on the row (a plain wall's shaded
colour and depth, or the sky): a row starts as a copy of the template, and only the
pixels that do depend on the row are computed: the floor (its checker tiles found by
bisection along the row, as the tile index is monotonic in the column), cylinder caps
and textured walls. A column's template entry changes only where one of its runs ends.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast.camera_hits import FLOOR_DARK, MAX_LAYERS, row_ceil, row_floor, to_u8

__all__ = ["fill_level"]

_jit = numba.njit(cache=True, nogil=True)

_EMPTY = -1  # owner of rows that see the floor or the sky
# what a column's current run shows (``kind``): a row-independent pixel (template), the
# floor or sky, a cylinder cap, a textured wall
_K_TEMPLATE = 0
_K_EMPTY = 1
_K_CAP = 2
_K_TEXTURE = 3


@_jit
def _insert(
    st: NDArray[np.int32],
    en: NDArray[np.int32],
    ow: NDArray[np.int8],
    n: int,
    i: int,
    a: int,
    b: int,
    owner: int,
) -> None:
    for j in range(n, i, -1):
        st[j] = st[j - 1]
        en[j] = en[j - 1]
        ow[j] = ow[j - 1]
    st[i] = a
    en[i] = b
    ow[i] = owner


@_jit
def _paint(
    st: NDArray[np.int32],
    en: NDArray[np.int32],
    ow: NDArray[np.int8],
    n: int,
    a: int,
    b: int,
    owner: int,
    height: int,
) -> int:
    """Give ``owner`` the rows of ``[a, b]`` (clipped to the image) that no interval
    holds yet; the intervals ``st/en/ow[:n]`` are sorted and disjoint. Returns the count."""
    a = max(a, 0)
    b = min(b, height - 1)
    if a > b:
        return n
    cur = a
    i = 0
    while i < n:
        if en[i] < cur:
            i += 1
            continue
        if st[i] > b:
            break
        if st[i] > cur:
            _insert(st, en, ow, n, i, cur, st[i] - 1, owner)
            n += 1
            i += 1
        cur = en[i] + 1
        i += 1
        if cur > b:
            break
    if cur <= b:
        _insert(st, en, ow, n, i, cur, b, owner)
        n += 1
    return n


@_jit
def _emit(
    run_end: NDArray[np.int32], run_own: NDArray[np.int8], u: int, r: int, owner: int, end: int
) -> int:
    if r > 0 and run_own[u, r - 1] == owner:
        run_end[u, r - 1] = end
        return r
    run_own[u, r] = owner
    run_end[u, r] = end
    return r + 1


@_jit
def _floor_span(
    rgb: NDArray[np.uint8],
    depth: NDArray[np.float32],
    v: int,
    ua: int,
    ub: int,
    fwx: float,
    gwx: float,
    fwy: float,
    gwy: float,
    floor_cols: NDArray[np.uint8],
    fdo: np.float32,
    with_depth: bool,
) -> None:
    """Floor pixels ``ua..ub`` of row ``v``: tile ``(floor(fwx + u gwx), floor(fwy +
    u gwy))`` of pixel ``u``, each tile's extent found by doubling and bisection (both
    indices are monotonic in ``u``, so equal ends mean one tile in between)."""
    if with_depth:
        for u in range(ua, ub + 1):
            depth[v, u] = fdo
    u = ua
    kx = int(math.floor(fwx + u * gwx))
    ky = int(math.floor(fwy + u * gwy))
    while True:
        e = u
        step = 1
        more = False
        nkx = kx
        nky = ky
        while e < ub:
            j = min(e + step, ub)
            jx = int(math.floor(fwx + j * gwx))
            jy = int(math.floor(fwy + j * gwy))
            if jx == kx and jy == ky:
                e = j
                step *= 2
                continue
            hi = j
            nkx = jx
            nky = jy
            while hi - e > 1:
                mid = (e + hi) >> 1
                mx = int(math.floor(fwx + mid * gwx))
                my = int(math.floor(fwy + mid * gwy))
                if mx == kx and my == ky:
                    e = mid
                else:
                    hi = mid
                    nkx = mx
                    nky = my
            more = True
            break
        k = (kx + ky) & 1
        c0 = floor_cols[k, 0]
        c1 = floor_cols[k, 1]
        c2 = floor_cols[k, 2]
        for w in range(u, e + 1):
            rgb[v, w, 0] = c0
            rgb[v, w, 1] = c1
            rgb[v, w, 2] = c2
        if not more:
            return
        u = e + 1
        kx = nkx
        ky = nky


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
    with_depth: bool,
) -> None:
    """Level camera (see the module docstring); ``depth`` is left alone (and may be any
    array) unless ``with_depth``.

    Pixel ``(u, v)`` has slope ``s = b / L`` (``b = (cy - v) / fy``,
    ``L = sqrt(1 + a^2)``, ``a = (cx - u) / fx``): a surface at horizontal distance ``t``
    spanning ``[zlo, zmax]`` covers the rows with ``b`` in ``[(zlo - z) L / t,
    (zmax - z) L / t]``; the floor seen by row ``v`` is at depth ``-z / b``. Owners of
    rows: surface ``m``, cap ``MAX_LAYERS + m`` or ``_EMPTY`` for floor or sky.
    """
    height, width = rgb.shape[0], rgb.shape[1]
    nk = MAX_LAYERS
    floor_seen = z > 0.0
    nan32 = np.float32(np.nan)
    max_runs = 4 * nk + 4  # <= 2 spans per surface, each adding at most 2 run ends
    st = np.empty(max_runs, dtype=np.int32)  # painted intervals of one column
    en = np.empty(max_runs, dtype=np.int32)
    ow = np.empty(max_runs, dtype=np.int8)
    n_runs = np.empty(width, dtype=np.int64)
    run_end = np.empty((width, max_runs), dtype=np.int32)  # last row of each run
    run_own = np.empty((width, max_runs), dtype=np.int8)
    h_depth = np.empty((width, nk), dtype=np.float32)
    h_tex = np.full((width, nk), -1, dtype=np.int64)  # texture index of textured walls
    h_col = np.zeros((width, nk), dtype=np.int64)  # and the texture column they show
    h_zc = np.zeros((width, nk))  # height of the cap a cylinder shows

    # ---- per column: which surface each row sees, as runs ----
    for u in range(width):
        a = (cx - u) / fx
        big_l = math.sqrt(1.0 + a * a)
        invl = 1.0 / big_l
        n = 0
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
                n = _paint(st, en, ow, n, v0, v1, m, height)
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
                n = _paint(st, en, ow, n, v0, v1, nk + m, height)
            if z < zmin:
                # bottom: rows with s in [(zmin - z) / tout, (zmin - z) / t)
                v0 = row_floor(cy - fy * (zmin - z) * big_l / t, height) + 1 if t > 0.0 else 0
                v1 = row_floor(cy - fy * (zmin - z) * big_l / tout, height)
                n = _paint(st, en, ow, n, v0, v1, nk + m, height)
        r = 0
        nxt = 0
        for i in range(n):
            if st[i] > nxt:
                r = _emit(run_end, run_own, u, r, _EMPTY, st[i] - 1)
            r = _emit(run_end, run_own, u, r, ow[i], en[i])
            nxt = en[i] + 1
        if nxt <= height - 1:
            r = _emit(run_end, run_own, u, r, _EMPTY, height - 1)
        n_runs[u] = r

    # ---- where runs change: (column, run) events bucketed by their first row ----
    ev_start = np.zeros(height + 1, dtype=np.int64)
    for u in range(width):
        for r in range(1, n_runs[u]):
            ev_start[run_end[u, r - 1] + 2] += 1
    for v in range(height):
        ev_start[v + 1] += ev_start[v]
    ev_u = np.empty(ev_start[height], dtype=np.int64)
    ev_r = np.empty(ev_start[height], dtype=np.int64)
    fillp = ev_start.copy()
    for u in range(width):
        for r in range(1, n_runs[u]):
            v = run_end[u, r - 1] + 1
            ev_u[fillp[v]] = u
            ev_r[fillp[v]] = r
            fillp[v] += 1

    # ---- row by row: the template, then the row-dependent pixels ----
    wpad = (width + 7) // 8 * 8
    kind = np.zeros(wpad, dtype=np.uint8)
    kind64 = kind.view(np.uint64)
    cur_own = np.empty(width, dtype=np.int64)
    tmpl = np.empty(width * 3, dtype=np.uint8)
    tmpl_d = np.empty(width, dtype=np.float32)
    flat = rgb.reshape(-1)
    w3 = width * 3
    n_kind = np.zeros(4, dtype=np.int64)
    n_kind[_K_TEMPLATE] = wpad  # padding counts as template (never looked at)
    for u in range(width):
        n_kind[_K_TEMPLATE] -= 1
        k = _set_column(
            u, run_own[u, 0], kind, cur_own, tmpl, tmpl_d, h_tex, h_rgb, h_depth, sky_rgb
        )
        n_kind[k] += 1
    floor_cols = np.empty((2, 3), dtype=np.uint8)
    for ch in range(3):
        floor_cols[0, ch] = floor_rgb[ch]
        floor_cols[1, ch] = to_u8(floor_rgb[ch] * FLOOR_DARK)
    cyaw = math.cos(yaw)
    syaw = math.sin(yaw)
    for v in range(height):
        for e in range(ev_start[v], ev_start[v + 1]):
            u = ev_u[e]
            n_kind[kind[u]] -= 1
            k = _set_column(
                u, run_own[u, ev_r[e]], kind, cur_own, tmpl, tmpl_d, h_tex, h_rgb, h_depth, sky_rgb
            )
            n_kind[k] += 1
        b = (cy - v) / fy
        fd = -z / b if (floor_seen and b < 0.0) else math.inf
        floor_ok = fd <= far
        fdo = np.float32(fd) if (floor_ok and fd >= near) else nan32
        # the floor point of pixel u is (x, y) + fd * R(yaw) (1, a_u): linear in u
        fwx = x + fd * (cyaw - syaw * cx / fx) if floor_ok else 0.0
        fwy = y + fd * (syaw + cyaw * cx / fx) if floor_ok else 0.0
        gwx = fd * syaw / fx if floor_ok else 0.0
        gwy = -fd * cyaw / fx if floor_ok else 0.0
        row0 = v * w3
        for i in range(w3):  # an explicit loop: compiled to a vector copy
            flat[row0 + i] = tmpl[i]
        if with_depth:
            depth[v, :] = tmpl_d
        if not (
            (floor_ok and n_kind[_K_EMPTY] > 0) or n_kind[_K_CAP] > 0 or n_kind[_K_TEXTURE] > 0
        ):
            continue
        u = 0
        while u < width:
            if (u & 7) == 0 and kind64[u >> 3] == 0:
                u += 8
                continue
            k = kind[u]
            if k == _K_TEMPLATE:
                u += 1
                continue
            if k == _K_EMPTY:
                ue = u
                while ue + 1 < width and kind[ue + 1] == _K_EMPTY:
                    ue += 1
                if floor_ok:
                    _floor_span(
                        rgb, depth, v, u, ue, fwx, gwx, fwy, gwy, floor_cols, fdo, with_depth
                    )
                u = ue + 1
                continue
            o = cur_own[u]
            if k == _K_CAP:
                m = o - nk
                dc = (h_zc[u, m] - z) / b
                if dc <= far:
                    rgb[v, u, 0] = h_rgb[u, m, 3]
                    rgb[v, u, 1] = h_rgb[u, m, 4]
                    rgb[v, u, 2] = h_rgb[u, m, 5]
                    if with_depth:
                        depth[v, u] = dc if dc >= near else nan32
                else:
                    rgb[v, u, 0] = sky_rgb[0]
                    rgb[v, u, 1] = sky_rgb[1]
                    rgb[v, u, 2] = sky_rgb[2]
                    if with_depth:
                        depth[v, u] = nan32
            else:
                ti = h_tex[u, o]
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
            u += 1


@_jit
def _set_column(
    u: int,
    o: int,
    kind: NDArray[np.uint8],
    cur_own: NDArray[np.int64],
    tmpl: NDArray[np.uint8],
    tmpl_d: NDArray[np.float32],
    h_tex: NDArray[np.int64],
    h_rgb: NDArray[np.uint8],
    h_depth: NDArray[np.float32],
    sky_rgb: NDArray[np.uint8],
) -> int:
    """Column ``u`` enters a run owned by ``o``: its kind (returned) and template pixel."""
    cur_own[u] = o
    if o == _EMPTY:
        k = _K_EMPTY
        tmpl[3 * u] = sky_rgb[0]
        tmpl[3 * u + 1] = sky_rgb[1]
        tmpl[3 * u + 2] = sky_rgb[2]
        tmpl_d[u] = np.float32(np.nan)
    elif o >= MAX_LAYERS:
        k = _K_CAP
    elif h_tex[u, o] >= 0:
        k = _K_TEXTURE
        tmpl_d[u] = h_depth[u, o]
    else:
        k = _K_TEMPLATE
        tmpl[3 * u] = h_rgb[u, o, 0]
        tmpl[3 * u + 1] = h_rgb[u, o, 1]
        tmpl[3 * u + 2] = h_rgb[u, o, 2]
        tmpl_d[u] = h_depth[u, o]
    kind[u] = k
    return k
