"""amcl's clusters (``pf_cluster_stats``) and convergence test, compiled.

Particles are binned in the pose histogram of :mod:`.kernels` (0.5 m x 0.5 m x 10 degrees,
amcl's ``pf_kdtree``); bins that touch (their 26 neighbours, angles closing on themselves)
form a cluster, amcl's hypothesis. Bins are found through an open-addressing hash table,
so the cost is linear in the particles (no sort).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numpy.typing import NDArray

from roverlab.localization.amcl.kernels import ANGLE_BINS, _bin_key

__all__ = ["cluster_stats", "max_spread"]

_jit = numba.njit(cache=True, nogil=True)
_MASK = (1 << 21) - 1
_MULT = -7046029254386353131

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


@_jit
def _slot(keys: I64, key: np.int64) -> int:
    """The slot of ``key`` in an open-addressing table (``-1`` = empty), or the empty slot
    where it belongs."""
    mask = keys.shape[0] - 1
    i = ((key * np.int64(_MULT)) >> 17) & mask
    while keys[i] != key and keys[i] != -1:
        i = (i + 1) & mask
    return int(i)


@_jit
def max_spread(poses: F64) -> float:
    """The largest distance along x or along y of a particle from the particles' mean (m):
    amcl's ``pf_update_converged`` compares it with 0.5 m."""
    n = poses.shape[0]
    if n == 0:
        return 0.0
    mx = 0.0
    my = 0.0
    for j in range(n):
        mx += poses[j, 0]
        my += poses[j, 1]
    mx /= n
    my /= n
    out = 0.0
    for j in range(n):
        out = max(out, abs(poses[j, 0] - mx), abs(poses[j, 1] - my))
    return out


@_jit
def cluster_stats(
    poses: F64, weights: F64
) -> tuple[I64, F64, F64, F64, NDArray[np.int64], F64, F64]:
    """amcl's ``pf_cluster_stats``: histogram bins joined into clusters by adjacency (the
    26 neighbouring bins), then each cluster's weight, mean and covariance.

    Means of yaw are circular (``atan2`` of the weighted sines and cosines) and the yaw
    variance is ``-2 log R`` (``R``: the mean resultant length of the cluster's weights).
    Clusters are numbered in the order their first particle appears.

    Returns:
        ``(labels (N,), weight (C,), mean (C, 3), cov (C, 3, 3), count (C,),
        set mean (3,), set cov (3, 3))``.
    """
    n = poses.shape[0]
    size = 16
    while size < 2 * n:
        size *= 2
    table = np.full(size, -1, dtype=np.int64)
    bin_of_slot = np.empty(size, dtype=np.int64)
    uniq = np.empty(max(n, 1), dtype=np.int64)
    of_particle = np.empty(n, dtype=np.int64)
    nu = 0
    for j in range(n):
        key = _bin_key(poses[j, 0], poses[j, 1], poses[j, 2])
        i = _slot(table, key)
        if table[i] == -1:
            table[i] = key
            bin_of_slot[i] = nu
            uniq[nu] = key
            nu += 1
        of_particle[j] = bin_of_slot[i]
    label = np.full(nu, -1, dtype=np.int64)
    stack = np.empty(nu, dtype=np.int64)
    clusters = 0
    for b in range(nu):
        if label[b] >= 0:
            continue
        label[b] = clusters
        top = 0
        stack[top] = b
        top += 1
        while top > 0:
            top -= 1
            cur = uniq[stack[top]]
            kx = cur >> 42
            ky = (cur >> 21) & _MASK
            ka = cur & _MASK
            for dx in range(-1, 2):
                for dy in range(-1, 2):
                    for da in range(-1, 2):
                        if dx == 0 and dy == 0 and da == 0:
                            continue
                        na = (ka + da) % ANGLE_BINS
                        nk = ((kx + dx) << 42) | ((ky + dy) << 21) | na
                        i = _slot(table, nk)
                        if table[i] == -1:
                            continue
                        pos = bin_of_slot[i]
                        if label[pos] < 0:
                            label[pos] = clusters
                            stack[top] = pos
                            top += 1
        clusters += 1
    labels = np.empty(n, dtype=np.int64)
    cw = np.zeros(clusters)
    count = np.zeros(clusters, dtype=np.int64)
    m = np.zeros((clusters, 4))
    cc = np.zeros((clusters, 2, 2))
    sm = np.zeros(4)
    sc = np.zeros((2, 2))
    total = 0.0
    for j in range(n):
        c = label[of_particle[j]]
        labels[j] = c
        wj = weights[j]
        x = poses[j, 0]
        y = poses[j, 1]
        ca = math.cos(poses[j, 2])
        sa = math.sin(poses[j, 2])
        count[c] += 1
        cw[c] += wj
        total += wj
        m[c, 0] += wj * x
        m[c, 1] += wj * y
        m[c, 2] += wj * ca
        m[c, 3] += wj * sa
        sm[0] += wj * x
        sm[1] += wj * y
        sm[2] += wj * ca
        sm[3] += wj * sa
        cc[c, 0, 0] += wj * x * x
        cc[c, 0, 1] += wj * x * y
        cc[c, 1, 1] += wj * y * y
        sc[0, 0] += wj * x * x
        sc[0, 1] += wj * x * y
        sc[1, 1] += wj * y * y
    mean = np.zeros((clusters, 3))
    cov = np.zeros((clusters, 3, 3))
    for c in range(clusters):
        if cw[c] <= 0.0:
            continue
        _moments(m[c], cc[c], cw[c], mean[c], cov[c])
    set_mean = np.zeros(3)
    set_cov = np.zeros((3, 3))
    if total > 0.0:
        _moments(sm, sc, total, set_mean, set_cov)
    return labels, cw, mean, cov, count, set_mean, set_cov


@_jit
def _moments(m: F64, c: F64, w: float, mean: F64, cov: F64) -> None:
    mean[0] = m[0] / w
    mean[1] = m[1] / w
    mean[2] = math.atan2(m[3], m[2])
    cov[0, 0] = c[0, 0] / w - mean[0] * mean[0]
    cov[0, 1] = c[0, 1] / w - mean[0] * mean[1]
    cov[1, 0] = cov[0, 1]
    cov[1, 1] = c[1, 1] / w - mean[1] * mean[1]
    resultant = math.sqrt(m[2] * m[2] + m[3] * m[3]) / w
    cov[2, 2] = -2.0 * math.log(resultant) if resultant > 0.0 else math.inf
