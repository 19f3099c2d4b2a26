"""One robot pose per scan of a log from the filter's poses at its updates and the odometry.

:func:`_scan_poses` is how :meth:`~roverlab.slam.gmapping.slam.GMapping.run_log` places the
scans between two filter updates: the pose of the last update moved by the odometry since,
or (``interpolate=True``) a blend of that and the next update's pose moved back by the
odometry, weighted by the progress between the two updates.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.gmapping.motion import compose, relative, wrap
from roverlab.slam.gmapping.params import GMappingParams


def _scan_poses(
    traj: NDArray[np.float64],
    odo: NDArray[np.float64],
    after: NDArray[np.int64],
    update_scans: NDArray[np.int64],
    smooth: GMappingParams | None,
) -> NDArray[np.float64]:
    """One robot pose per scan from the poses at the updates and the odometry.

    Args:
        traj: (K, 3) poses at the K updates.
        odo: (N, 3) odometry pose of each scan.
        after: (N,) the last update at or before each scan (-1: none yet).
        update_scans: (K,) the scan of each update.
        smooth: the parameters, to blend with the next update (see ``run_log``); ``None``
            for plain forward propagation.
    """
    poses = odo.copy()  # ahead of the first update the map frame is the odometry frame
    seen = after >= 0
    if not np.any(seen) or traj.shape[0] == 0:
        return poses
    k = after[seen]
    fwd = compose(traj[k], relative(odo[update_scans[k]], odo[seen]))
    poses[seen] = fwd
    if smooth is None or traj.shape[0] < 2:
        return poses
    # Progress along the odometry in units of the update thresholds.
    step = relative(odo[:-1], odo[1:])
    lin = np.hypot(step[:, 0], step[:, 1])
    ang = np.abs(step[:, 2])
    prog = np.zeros(len(step))
    if smooth.linearUpdate > 0.0:
        prog += lin / smooth.linearUpdate
    if smooth.angularUpdate > 0.0:
        prog += ang / smooth.angularUpdate
    if smooth.linearUpdate <= 0.0 and smooth.angularUpdate <= 0.0:
        prog += 1.0
    cum = np.concatenate([[0.0], np.cumsum(prog)])
    nxt = np.minimum(k + 1, traj.shape[0] - 1)
    has_next = nxt > k
    if not np.any(has_next):
        return poses
    idx = np.flatnonzero(seen)[has_next]
    k, nxt, fwd = k[has_next], nxt[has_next], fwd[has_next]
    bwd = compose(traj[nxt], relative(odo[update_scans[nxt]], odo[idx]))
    span = cum[update_scans[nxt]] - cum[update_scans[k]]
    done = cum[idx] - cum[update_scans[k]]
    alpha = np.where(span > 0.0, done / np.where(span > 0.0, span, 1.0), 0.0)
    alpha = np.clip(alpha, 0.0, 1.0)
    blend = np.empty_like(fwd)
    blend[:, :2] = (1.0 - alpha[:, None]) * fwd[:, :2] + alpha[:, None] * bwd[:, :2]
    blend[:, 2] = wrap(fwd[:, 2] + alpha * wrap(bwd[:, 2] - fwd[:, 2]))
    poses[idx] = blend
    return poses
