"""amcl's compiled kernels: motion models, particle weighting, KLD resampling (clusters:
:mod:`.clusters`).

Every kernel is ``numba.njit(cache=True, nogil=True)`` over plain arrays; kernels that
draw take the caller's ``np.random.Generator`` (numba draws from its state, the same
stream numpy would give), so a seeded run is reproducible. Map lookups work in cell
units: a point ``(gx, gy)`` lies in cell ``(int(gy), int(gx))`` when ``0 <= gx < width``
and ``0 <= gy < height``.

The pose histogram (amcl's ``pf_kdtree``) has bins of 0.5 m x 0.5 m x 10 degrees; its
key packs the three bin indices into one int64. Angles are wrapped to ``[-pi, pi)``, so
the 36 angular bins close on themselves (amcl bins raw, unwrapped angles).
"""

from __future__ import annotations

import math
from typing import Final

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.raycast import grid_ray

__all__ = [
    "ANGLE_BINS",
    "BIN_ANGLE_RAD",
    "BIN_XY_M",
    "beam_weights",
    "diff_motion",
    "kld_resample",
    "likelihood_field_prob_weights",
    "likelihood_field_weights",
    "omni_motion",
]

_jit = numba.njit(cache=True, nogil=True)
_fast = numba.njit(cache=True, nogil=True, fastmath=True)

#: Histogram bin side in x and y (m), as amcl's ``pf_kdtree``.
BIN_XY_M: Final = 0.5
#: Histogram bin in yaw (rad): 10 degrees.
BIN_ANGLE_RAD: Final = math.radians(10.0)
#: Angular bins in a full turn.
ANGLE_BINS: Final = 36

_OFFSET = 1 << 20  # bin indices within +-2^20 (+-524 km) pack into 21 bits each
_MASK = (1 << 21) - 1

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


# ----------------------------------------------------------------------------- weights
@_fast
def likelihood_field_weights(
    poses: F64,
    weights: F64,
    ex: F64,
    ey: F64,
    table: F64,
    off_map: float,
    inv_res: float,
    ox: float,
    oy: float,
) -> float:
    """amcl's ``likelihood_field`` model: ``w *= 1 + sum_beams pz^3``; returns ``sum w``.

    Args:
        poses: ``(N, 3)`` particle poses (map frame).
        weights: ``(N,)`` weights, multiplied in place.
        ex: ``(B,)`` beam end points in the robot frame, x (m): the laser's offset plus
            the range along the beam's bearing.
        ey: ``(B,)`` same, y.
        table: ``(H, W)`` the per-cell ``pz^3``.
        off_map: ``pz^3`` of an end point off the map.
        inv_res: ``1 / resolution``.
        ox: map origin x (m).
        oy: map origin y (m).
    """
    h, w = table.shape
    nb = ex.shape[0]
    total = 0.0
    for j in range(poses.shape[0]):
        gx = (poses[j, 0] - ox) * inv_res
        gy = (poses[j, 1] - oy) * inv_res
        c = math.cos(poses[j, 2]) * inv_res
        s = math.sin(poses[j, 2]) * inv_res
        p = 1.0
        for i in range(nb):
            hx = gx + c * ex[i] - s * ey[i]
            hy = gy + s * ex[i] + c * ey[i]
            if hx >= 0.0 and hy >= 0.0 and hx < w and hy < h:
                p += table[int(hy), int(hx)]
            else:
                p += off_map
        weights[j] *= p
        total += weights[j]
    return total


@_fast
def likelihood_field_prob_weights(
    poses: F64,
    weights: F64,
    ex: F64,
    ey: F64,
    log_table: F64,
    off_map: float,
    distance: F64,
    inv_res: float,
    ox: float,
    oy: float,
    beamskip: bool,
    skip_distance: float,
    skip_threshold: float,
    skip_error_threshold: float,
    scratch: F64,
) -> tuple[float, float, int, bool]:
    """amcl's ``likelihood_field_prob`` model: ``w *= exp(sum_beams log pz)``, computed in
    the log domain: each particle's ``log p`` is found first and the weights are multiplied
    by ``exp(log p - max log p)``, so that a product of many small ``pz`` does not
    underflow to zero for every particle (amcl multiplies ``pz`` directly).

    With ``beamskip``, a beam is used only when more than ``skip_threshold`` of the
    particles see its end point within ``skip_distance`` of an obstacle; when at least
    ``skip_error_threshold`` of the beams would be skipped, all are used (the filter has
    probably converged to a wrong pose).

    Args:
        log_table: ``(H, W)`` per-cell ``log pz``; ``off_map`` its value off the map.
        distance: ``(H, W)`` the likelihood field (m).
        scratch: ``(N, B)`` work array (used with ``beamskip``).
        (others as :func:`likelihood_field_weights`)

    Returns:
        ``(sum of weights, max log p, beams skipped, all beams used because too many
        disagreed)``: the weights were multiplied by ``p / exp(max log p)``.
    """
    h, w = log_table.shape
    nb = ex.shape[0]
    n = poses.shape[0]
    agree = np.zeros(nb, dtype=np.int64)
    log_p = np.empty(n)
    for j in range(n):
        gx = (poses[j, 0] - ox) * inv_res
        gy = (poses[j, 1] - oy) * inv_res
        c = math.cos(poses[j, 2]) * inv_res
        s = math.sin(poses[j, 2]) * inv_res
        acc = 0.0
        for i in range(nb):
            hx = gx + c * ex[i] - s * ey[i]
            hy = gy + s * ex[i] + c * ey[i]
            if hx >= 0.0 and hy >= 0.0 and hx < w and hy < h:
                r = int(hy)
                q = int(hx)
                v = log_table[r, q]
                if beamskip and distance[r, q] < skip_distance:
                    agree[i] += 1
            else:
                v = off_map
            if beamskip:
                scratch[j, i] = v
            else:
                acc += v
        log_p[j] = acc
    skipped = 0
    too_many = False
    if beamskip:
        use = np.empty(nb, dtype=np.bool_)
        for i in range(nb):
            use[i] = agree[i] / n > skip_threshold
            if not use[i]:
                skipped += 1
        too_many = skipped >= nb * skip_error_threshold
        for j in range(n):
            acc = 0.0
            for i in range(nb):
                if too_many or use[i]:
                    acc += scratch[j, i]
            log_p[j] = acc
    top = 0.0
    found = False
    for j in range(n):
        if weights[j] > 0.0 and (not found or log_p[j] > top):
            top = log_p[j]
            found = True
    total = 0.0
    for j in range(n):
        weights[j] *= math.exp(log_p[j] - top)
        total += weights[j]
    return total, top, (0 if too_many else skipped), too_many


@_jit
def beam_weights(
    poses: F64,
    weights: F64,
    laser_x: float,
    laser_y: float,
    cos_b: F64,
    sin_b: F64,
    obs: F64,
    range_max: float,
    blocked: NDArray[np.uint8],
    resolution: float,
    ox: float,
    oy: float,
    z_hit: float,
    z_short: float,
    z_max: float,
    z_rand: float,
    sigma_hit: float,
    lambda_short: float,
) -> float:
    """amcl's ``beam`` model: ray cast each beam in the map (occupied or unknown cells stop
    it), ``w *= 1 + sum_beams pz^3`` with the hit / short / max / random mixture.

    Args:
        laser_x: the laser's x in the robot frame (m).
        laser_y: the laser's y in the robot frame (m).
        cos_b: ``(B,)`` cosine of each beam's bearing in the robot frame.
        sin_b: ``(B,)`` its sine.
        obs: ``(B,)`` observed ranges, finite and at most ``range_max`` (m).
        blocked: ``(H, W)`` 1 where a ray stops.
        (others as :func:`likelihood_field_weights`)
    """
    inv = 1.0 / resolution
    rmax_cells = range_max * inv
    denom = 2.0 * sigma_hit * sigma_hit
    nb = obs.shape[0]
    total = 0.0
    for j in range(poses.shape[0]):
        c = math.cos(poses[j, 2])
        s = math.sin(poses[j, 2])
        gx = (poses[j, 0] + c * laser_x - s * laser_y - ox) * inv
        gy = (poses[j, 1] + s * laser_x + c * laser_y - oy) * inv
        p = 1.0
        for i in range(nb):
            dx = c * cos_b[i] - s * sin_b[i]
            dy = s * cos_b[i] + c * sin_b[i]
            t = grid_ray(gx, gy, dx, dy, rmax_cells, blocked, 1)
            map_range = min(t * resolution, range_max)
            r = obs[i]
            z = r - map_range
            pz = z_hit * math.exp(-(z * z) / denom)
            if z < 0.0:
                pz += z_short * lambda_short * math.exp(-lambda_short * r)
            if r == range_max:
                pz += z_max
            else:
                pz += z_rand / range_max
            p += pz * pz * pz
        weights[j] *= p
        total += weights[j]
    return total


# ----------------------------------------------------------------------------- histogram
@_jit
def _bin_key(x: float, y: float, theta: float) -> np.int64:
    kx = int(math.floor(x / BIN_XY_M)) + _OFFSET
    ky = int(math.floor(y / BIN_XY_M)) + _OFFSET
    a = theta - 2.0 * math.pi * math.floor((theta + math.pi) / (2.0 * math.pi))
    ka = int(math.floor((a + math.pi) / BIN_ANGLE_RAD)) % ANGLE_BINS
    return np.int64((kx << 42) | (ky << 21) | ka)


@_jit
def _hash_insert(table: I64, key: np.int64) -> bool:
    """Insert ``key`` into an open-addressing set (``-1`` = empty); True if it was new."""
    mask = table.shape[0] - 1
    h = (key * np.int64(-7046029254386353131)) >> 17
    i = h & mask
    while True:
        k = table[i]
        if k == key:
            return False
        if k == -1:
            table[i] = key
            return True
        i = (i + 1) & mask


@_jit
def kld_resample(
    poses: F64,
    weights: F64,
    rng: np.random.Generator,
    w_diff: float,
    free_cells: I64,
    resolution: float,
    ox: float,
    oy: float,
    limits: I64,
    out: F64,
    hash_table: I64,
) -> tuple[int, int]:
    """KLD-adaptive low-variance resampling with random-particle injection.

    A low-variance (systematic) sample of ``M = out.shape[0]`` draws is taken from the
    weights (one uniform offset); its draws are then visited in a random order (a lazy
    Fisher-Yates shuffle), and each visited draw is replaced, with probability
    ``w_diff``, by a random pose on a free cell (amcl's ``drand48() < w_diff``). Each
    sample's histogram bin is counted, and sampling stops once the count exceeds
    ``limits[bins]`` (amcl's ``pf_resample_limit``) or reaches M. Visiting the
    systematic sample in random order keeps its low variance while letting the KLD rule
    stop at any count (amcl falls back to independent draws, its comment says, because
    the two do not combine easily).

    Args:
        poses: ``(N, 3)`` current particles.
        weights: ``(N,)`` their weights, normalised.
        rng: every draw.
        w_diff: the injection probability.
        free_cells: ``(K, 2)`` ``(row, col)`` of the map's free cells.
        resolution: map cell side (m).
        ox: map origin x (m).
        oy: map origin y (m).
        limits: ``(M + 1,)`` the KLD sample bound for ``k`` occupied bins.
        out: ``(M, 3)`` receives the new particles.
        hash_table: work array, a power-of-two size above ``2 M``.

    Returns:
        ``(new particle count (the first rows of out), random particles among them)``.
    """
    m = out.shape[0]
    n = poses.shape[0]
    idx = np.empty(m, dtype=np.int64)
    u0 = rng.random()
    cum = 0.0
    i = 0
    for k in range(m):
        u = (u0 + k) / m
        while i < n - 1 and cum + weights[i] <= u:
            cum += weights[i]
            i += 1
        idx[k] = i
    hash_table[:] = -1
    bins = 0
    injected = 0
    count = 0
    nfree = free_cells.shape[0]
    for k in range(m):
        j = k + int(rng.random() * (m - k))
        if j >= m:
            j = m - 1
        t = idx[k]
        idx[k] = idx[j]
        idx[j] = t
        if w_diff > 0.0 and rng.random() < w_diff:
            c = free_cells[min(int(rng.random() * nfree), nfree - 1)]
            out[k, 0] = ox + (c[1] + rng.random()) * resolution
            out[k, 1] = oy + (c[0] + rng.random()) * resolution
            out[k, 2] = rng.random() * 2.0 * math.pi - math.pi
            injected += 1
        else:
            src = idx[k]
            out[k, 0] = poses[src, 0]
            out[k, 1] = poses[src, 1]
            out[k, 2] = poses[src, 2]
        if _hash_insert(hash_table, _bin_key(out[k, 0], out[k, 1], out[k, 2])):
            bins += 1
        count = k + 1
        if count > limits[bins]:
            break
    return count, injected


# ----------------------------------------------------------------------------- motion
@_fast
def diff_motion(
    poses: F64,
    rot1: float,
    trans: float,
    rot2: float,
    sd_rot1: float,
    sd_trans: float,
    sd_rot2: float,
    rng: np.random.Generator,
) -> None:
    """amcl's ``diff`` models per particle: rotate by ``rot1``, translate by ``trans``,
    rotate by ``rot2``, each with a Gaussian of the given standard deviation; headings
    are wrapped to ``[-pi, pi)``."""
    for j in range(poses.shape[0]):
        r1 = _wrap(rot1 - sd_rot1 * rng.standard_normal())
        t = trans - sd_trans * rng.standard_normal()
        r2 = _wrap(rot2 - sd_rot2 * rng.standard_normal())
        th = poses[j, 2]
        poses[j, 0] += t * math.cos(th + r1)
        poses[j, 1] += t * math.sin(th + r1)
        poses[j, 2] = _wrap(th + r1 + r2)


@_fast
def omni_motion(
    poses: F64,
    bearing: float,
    trans: float,
    rot: float,
    sd_trans: float,
    sd_rot: float,
    sd_strafe: float,
    rng: np.random.Generator,
) -> None:
    """amcl's ``omni`` models per particle: translate along ``bearing`` (relative to the
    particle's heading) by ``trans`` with noise along and across (strafe), rotate by
    ``rot``; headings are wrapped to ``[-pi, pi)``."""
    for j in range(poses.shape[0]):
        th = poses[j, 2]
        b = bearing + th
        cb = math.cos(b)
        sb = math.sin(b)
        t = trans + sd_trans * rng.standard_normal()
        r = rot + sd_rot * rng.standard_normal()
        st = sd_strafe * rng.standard_normal()
        poses[j, 0] += t * cb + st * sb
        poses[j, 1] += t * sb - st * cb
        poses[j, 2] = _wrap(th + r)


@_jit
def _wrap(a: float) -> float:
    """``a`` in ``[-pi, pi)`` (as it is when it already lies there: no floating-point
    modulo on the common path)."""
    if -math.pi <= a < math.pi:
        return a
    return (a + math.pi) % (2.0 * math.pi) - math.pi
