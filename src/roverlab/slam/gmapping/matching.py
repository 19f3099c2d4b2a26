"""The particles' scan matching: gmapping's hill climbing and the odometry-failure recovery.

:class:`ScanMatching`, a base class of :class:`~roverlab.slam.gmapping.slam.GMapping`, climbs
every particle's pose on its own map (:meth:`ScanMatching._match`, gmapping's
``ScanMatcher::optimize`` over the compiled kernels) and, when even the best particle
matches poorly, searches widely around the odometry sample (:meth:`ScanMatching._recover`,
see :mod:`roverlab.slam.gmapping.slam`). :class:`_Beams` is a scan as the matcher and the
map update use it (:func:`scan_beams`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2
from roverlab.slam.gmapping import kernels
from roverlab.slam.gmapping.grid import ParticleMaps
from roverlab.slam.gmapping.motion import compose, relative
from roverlab.slam.gmapping.params import GMappingParams

__all__ = ["ScanMatching", "scan_beams"]

# Odometry-failure recovery (see GMapping._recover): triggered when the best particle's
# matcher score is below this fraction of the beams; searches +-(0.5 m + twice the odometry
# travel since the last update, at most 3 m) and +-45 degrees with about this many beams,
# a kernel of this many cells, 2 degree steps; keeps a result that beats the local match by
# this fraction of the beams.
_RECOVER_BELOW = 0.7
_RECOVER_LINEAR_M = 0.5
_RECOVER_LINEAR_MAX_M = 3.0
_RECOVER_ANGULAR_RAD = math.pi / 4.0
_RECOVER_ANGULAR_STEP = math.radians(2.0)
_RECOVER_BEAMS = 90
_RECOVER_KERNEL = 2
_RECOVER_CANDIDATES = 8
_RECOVER_MARGIN = 0.15
# Recovered poses within this fraction of the beams of the best one count as equally good;
# the one nearest the odometry wins (a radian of heading counts as this many metres).
_RECOVER_TIE = 0.03
_RECOVER_RAD_TO_M = 1.0


class _Beams(NamedTuple):
    hit: NDArray[np.float64]  # (B, 2) matcher endpoints, robot frame
    free: NDArray[np.float64]  # (B, 2) one cell back along each matcher beam
    origin: NDArray[np.float64]  # (2,) laser position, robot frame
    ends: NDArray[np.float64]  # (M, 2) map-update end points (cropped), robot frame
    is_hit: NDArray[np.bool_]  # (M,) whether each map-update beam hit an obstacle


def scan_beams(
    r: NDArray[np.float64],
    a: NDArray[np.float64],
    range_min: float,
    range_max: float,
    off: SE2,
    p: GMappingParams,
) -> _Beams:
    """A scan (ranges ``r``, beam angles ``a`` in the laser frame, laser pose ``off`` on the
    robot) as gmapping's matcher and map update use it: readings below ``range_min`` count
    as no return, beyond ``maxRange`` are dropped, are cropped to ``maxUrange`` for the
    map, and every ``lskip + 1``-th beam that hit something within it is matched."""
    r = r.copy()
    r[r < range_min] = range_max
    max_range = p.max_range(range_max)
    usable = min(p.maxUrange, max_range)
    with np.errstate(invalid="ignore"):
        keep = np.isfinite(r) & (r > 0.0) & (r <= max_range)
        hit = keep & (r < usable)
    ang = a + off.theta
    cos, sin = np.cos(ang), np.sin(ang)
    origin = np.array([off.x, off.y])
    d = np.minimum(r[keep], usable)
    ends = np.stack([off.x + d * cos[keep], off.y + d * sin[keep]], axis=1)
    step = p.lskip + 1
    matched = hit & (np.arange(r.size) % step == step - 1)
    rm = r[matched]
    cm, sm = cos[matched], sin[matched]
    hit_pts = np.stack([off.x + rm * cm, off.y + rm * sm], axis=1)
    back = rm - p.delta
    free_pts = np.stack([off.x + back * cm, off.y + back * sm], axis=1)
    return _Beams(
        hit=np.ascontiguousarray(hit_pts),
        free=np.ascontiguousarray(free_pts),
        origin=origin,
        ends=np.ascontiguousarray(ends),
        is_hit=np.ascontiguousarray(hit[keep]),
    )


class ScanMatching:
    """Scan matching of the particle filter; the subclass
    (:class:`~roverlab.slam.gmapping.slam.GMapping`) provides the state below."""

    params: GMappingParams
    maps: ParticleMaps
    _poses: NDArray[np.float64]
    _linear: float
    recoveries: int

    def _match(
        self, starts: NDArray[np.float64], owners: NDArray[np.int64], beams: _Beams
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        p = self.params
        ox, oy = self.maps.origin_xy
        return kernels.match_all(
            self.maps.cells,
            np.ascontiguousarray(owners, dtype=np.int64),
            ox,
            oy,
            p.delta,
            np.ascontiguousarray(starts),
            beams.hit,
            beams.free,
            p.kernelSize,
            1.0 / p.sigma,
            p.lstep,
            p.astep,
            p.iterations,
        )

    def _recover(
        self,
        beams: _Beams,
        best: int,
        matched: NDArray[np.float64],
        scores: NDArray[np.float64],
    ) -> None:
        """Odometry-failure recovery: a wide search on the best particle's map.

        Run when even the best particle matched less than half of the beams (a push, wheel
        slip, odometry that counts reversing as driving forward): a window around its
        odometry sample, as wide as twice the odometry travel since the last update plus
        half a metre, and +-45 degrees, is scored on a coarse lattice (every few beams, a
        wider kernel),
        the best lattice poses are hill-climbed, and if one scores clearly better the same
        correction is applied to every particle's odometry sample and climbed again;
        each particle keeps whichever of its two matches scores higher.
        """
        p = self.params
        n_beams = beams.hit.shape[0]
        step = max(1, n_beams // _RECOVER_BEAMS)
        pred = self._poses[best]
        ox, oy = self.maps.origin_xy
        lin_step = 2.0 * p.delta * _RECOVER_KERNEL
        travelled = self._linear  # the odometry path since the last update
        lin_half = min(_RECOVER_LINEAR_MAX_M, _RECOVER_LINEAR_M + 2.0 * travelled)
        grid = kernels.search_window(
            self.maps.cells,
            best,
            ox,
            oy,
            p.delta,
            float(pred[0]),
            float(pred[1]),
            float(pred[2]),
            np.ascontiguousarray(beams.hit[::step]),
            np.ascontiguousarray(beams.free[::step]),
            _RECOVER_KERNEL,
            1.0 / p.sigma,
            lin_half,
            lin_step,
            _RECOVER_ANGULAR_RAD,
            _RECOVER_ANGULAR_STEP,
        )
        na = (grid.shape[0] - 1) // 2
        nl = (grid.shape[1] - 1) // 2
        a, i, j = _peaks(grid, _RECOVER_CANDIDATES)
        starts = np.stack(
            [
                pred[0] + (i - nl) * lin_step,
                pred[1] + (j - nl) * lin_step,
                pred[2] + (a - na) * _RECOVER_ANGULAR_STEP,
            ],
            axis=1,
        )
        cand, cand_scores = self._match(starts, np.full(len(starts), best), beams)
        need = max(scores[best] + _RECOVER_MARGIN * n_beams, _RECOVER_BELOW * n_beams)
        if cand_scores.max() <= need:
            return
        # Among the (near) best, the smallest correction: in a corridor the position along
        # it is ambiguous, and the odometry is the better guess there.
        near_best = cand_scores >= cand_scores.max() - _RECOVER_TIE * n_beams
        shift = relative(np.broadcast_to(pred, cand.shape), cand)
        cost = np.hypot(shift[:, 0], shift[:, 1]) + np.abs(shift[:, 2]) * _RECOVER_RAD_TO_M
        k = int(np.argmin(np.where(near_best, cost, np.inf)))
        correction = shift[k]
        starts = compose(self._poses, correction[None, :])
        again, again_scores = self._match(starts, np.arange(p.particles), beams)
        better = again_scores > scores
        matched[better] = again[better]
        scores[better] = again_scores[better]
        self.recoveries += 1


def _peaks(grid: NDArray[np.float64], k: int) -> tuple[NDArray[np.intp], ...]:
    """Indices of up to ``k`` best cells of ``grid``, no two within one cell of each other."""
    order = np.argsort(grid, axis=None)[::-1]
    chosen: list[NDArray[np.intp]] = []
    for flat in order[: 64 * k]:
        idx = np.array(np.unravel_index(flat, grid.shape))
        if all(np.abs(idx - c).max() > 1 for c in chosen):
            chosen.append(idx)
            if len(chosen) == k:
                break
    arr = np.array(chosen).reshape(-1, grid.ndim)
    return tuple(arr[:, d] for d in range(grid.ndim))
