"""The relative-pose SLAM metric of Kuemmerle et al. (2009) and its ``.relations`` files.

"On measuring the accuracy of SLAM algorithms" scores a trajectory by the relative poses
between pairs of scans rather than by absolute poses, so that an early small rotation
error does not dominate. A ``.relations`` file lists the true relative poses::

    timestamp1 timestamp2 x y z roll pitch yaw

-- the true pose of the scan taken at ``timestamp2`` in the frame of the scan taken at
``timestamp1`` (z, roll and pitch are 0 for planar data and are ignored here).

For each relation ``(i, j, delta*_ij)`` whose two timestamps are both in the trajectory,
with estimated poses ``x_i``, ``x_j``::

    delta_ij = x_i^-1 * x_j                      (the estimated relative pose)
    epsilon  = delta*_ij^-1 * delta_ij           (= delta_ij (-) delta*_ij)
    trans_ij = || translation(epsilon) ||         = || t(delta_ij) - t(delta*_ij) ||
    rot_ij   = | wrap(theta(delta_ij) - theta(delta*_ij)) |

The translational error is the norm of the translation of the difference transform,
which equals the distance between the estimated and the true relative translations (a
rotation does not change a norm); the rotational error is the absolute wrapped angle
difference. The paper's score is the mean of the squared errors; the published tables
(and the data README) report the mean and standard deviation of the absolute errors,
which is what :class:`Metrics` holds (standard deviation with ``ddof=0``), in m and deg.

Timestamps are matched exactly: by their text when both sides have it (a trajectory
written from the log, a TUM file), else as numbers within 1 microsecond.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import NDArray

from roverlab.slam.data._io import finite_floats, text_rows
from roverlab.slam.data.errors import EvaluationError
from roverlab.slam.data.trajectory import Trajectory

__all__ = ["TIMESTAMP_TOLERANCE_S", "Metrics", "Relations", "evaluate", "read_relations"]

FloatArray = NDArray[np.float64]

#: Two timestamps given as numbers are the same scan when this close, s.
TIMESTAMP_TOLERANCE_S: Final = 1e-6


@dataclass(frozen=True, eq=False)
class Relations:
    """True relative poses between pairs of scans.

    Attributes:
        first: ``(K,)`` time of each relation's reference scan, s.
        second: ``(K,)`` time of the other scan, s.
        poses: ``(K, 3)`` true pose ``(x, y, theta)`` of the second scan in the frame of the
            first.
        first_texts: The first timestamps as written in the file.
        second_texts: The second timestamps as written in the file.
    """

    first: FloatArray
    second: FloatArray
    poses: FloatArray
    first_texts: tuple[str, ...] | None = None
    second_texts: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        a = np.array(self.first, dtype=np.float64).reshape(-1)
        b = np.array(self.second, dtype=np.float64).reshape(-1)
        p = np.array(self.poses, dtype=np.float64)
        k = a.shape[0]
        if b.shape != (k,) or p.shape != (k, 3):
            raise EvaluationError(
                f"relations disagree: {k} first, {b.shape[0]} second timestamps, poses {p.shape}"
            )
        for texts in (self.first_texts, self.second_texts):
            if texts is not None and len(texts) != k:
                raise EvaluationError(f"{len(texts)} timestamp texts for {k} relations")
        for arr in (a, b, p):
            arr.setflags(write=False)
        object.__setattr__(self, "first", a)
        object.__setattr__(self, "second", b)
        object.__setattr__(self, "poses", p)

    def __len__(self) -> int:
        return int(self.first.shape[0])


def read_relations(path: str | Path) -> Relations:
    """Read a ``.relations`` file (``timestamp1 timestamp2 x y z roll pitch yaw`` lines).

    Blank lines and ``#`` comments are skipped; timestamp texts are kept.

    Raises:
        EvaluationError: the file cannot be read, a line is malformed (file and line are
            named), or it holds no relation.
    """
    p = Path(path)
    t1: list[str] = []
    t2: list[str] = []
    rows: list[tuple[float, float, float]] = []
    for lineno, parts in text_rows(p, EvaluationError):
        if len(parts) != 8:
            raise EvaluationError(
                f"{p}:{lineno}: expected 8 values (timestamp1 timestamp2 x y z roll pitch "
                f"yaw), got {len(parts)}"
            )
        vals = finite_floats(parts, f"{p}:{lineno}", EvaluationError)
        t1.append(parts[0])
        t2.append(parts[1])
        rows.append((vals[2], vals[3], vals[7]))
    if not rows:
        raise EvaluationError(f"{p}: no relations")
    return Relations(
        first=np.array([float(t) for t in t1]),
        second=np.array([float(t) for t in t2]),
        poses=np.array(rows),
        first_texts=tuple(t1),
        second_texts=tuple(t2),
    )


@dataclass(frozen=True, eq=False)
class Metrics:
    """Relative-pose errors of a trajectory (see the module docstring for the formula).

    Attributes:
        trans_mean: Mean translational error, m.
        trans_std: Its standard deviation, m.
        rot_mean_deg: Mean absolute rotational error, deg.
        rot_std_deg: Its standard deviation, deg.
        matched: Relations whose two scans are in the trajectory (the ones scored).
        total: Relations in the file.
        trans_errors: ``(matched,)`` translational error of each scored relation, m.
        rot_errors_deg: ``(matched,)`` absolute rotational error of each, deg.
    """

    trans_mean: float
    trans_std: float
    rot_mean_deg: float
    rot_std_deg: float
    matched: int
    total: int
    trans_errors: FloatArray
    rot_errors_deg: FloatArray

    @property
    def trans_squared_mean(self) -> float:
        """The paper's translational score: mean squared translational error, m^2."""
        return float(np.mean(self.trans_errors**2))

    @property
    def rot_squared_mean_deg2(self) -> float:
        """The paper's rotational score: mean squared rotational error, deg^2."""
        return float(np.mean(self.rot_errors_deg**2))

    def lines(self) -> tuple[str, str, str]:
        """The three lines ``roverlab slam eval`` prints."""
        return (
            f"translational error: {self.trans_mean:.4f} +- {self.trans_std:.4f} m",
            f"rotational error: {self.rot_mean_deg:.2f} +- {self.rot_std_deg:.2f} deg",
            f"relations matched: {self.matched} / {self.total}",
        )

    def __str__(self) -> str:
        return "\n".join(self.lines())


def _match(
    trajectory: Trajectory,
    values: FloatArray,
    texts: tuple[str, ...] | None,
) -> NDArray[np.intp]:
    """Trajectory index of each timestamp (-1 when absent): exact text, else within 1 us."""
    out = np.full(values.shape[0], -1, dtype=np.intp)
    if texts is not None and trajectory.timestamp_texts is not None:
        where: dict[str, int] = {}
        for k, t in enumerate(trajectory.timestamp_texts):
            where.setdefault(t, k)
        out[:] = [where.get(t, -1) for t in texts]
    todo = np.flatnonzero(out < 0)
    if todo.size and len(trajectory):
        ts = trajectory.timestamps
        order = np.argsort(ts, kind="stable")
        sorted_ts = ts[order]
        v = values[todo]
        pos = np.searchsorted(sorted_ts, v)
        lo = np.clip(pos - 1, 0, sorted_ts.shape[0] - 1)
        hi = np.clip(pos, 0, sorted_ts.shape[0] - 1)
        near = np.where(np.abs(sorted_ts[hi] - v) < np.abs(sorted_ts[lo] - v), hi, lo)
        ok = np.abs(sorted_ts[near] - v) <= TIMESTAMP_TOLERANCE_S
        out[todo[ok]] = order[near[ok]]
    return out


def evaluate(trajectory: Trajectory, relations: Relations) -> Metrics:
    """Score ``trajectory`` against true relative poses (Kuemmerle et al. 2009).

    Relations with a timestamp the trajectory lacks are left out (see
    :attr:`Metrics.matched`).

    Raises:
        EvaluationError: no relation has both of its timestamps in the trajectory.
    """
    i = _match(trajectory, relations.first, relations.first_texts)
    j = _match(trajectory, relations.second, relations.second_texts)
    ok = (i >= 0) & (j >= 0)
    total = len(relations)
    if not np.any(ok):
        raise EvaluationError(
            f"none of the {total} relations has both timestamps in the trajectory "
            f"({len(trajectory)} poses): is it the trajectory of the same log?"
        )
    xi = trajectory.poses[i[ok]]
    xj = trajectory.poses[j[ok]]
    truth = relations.poses[ok]
    c, s = np.cos(xi[:, 2]), np.sin(xi[:, 2])
    dx, dy = xj[:, 0] - xi[:, 0], xj[:, 1] - xi[:, 1]
    est_x = c * dx + s * dy  # translation of x_i^-1 * x_j
    est_y = -s * dx + c * dy
    trans = np.hypot(est_x - truth[:, 0], est_y - truth[:, 1])
    rot = np.abs((xj[:, 2] - xi[:, 2] - truth[:, 2] + np.pi) % (2.0 * np.pi) - np.pi)
    rot_deg = np.degrees(rot)
    return Metrics(
        trans_mean=float(trans.mean()),
        trans_std=float(trans.std()),
        rot_mean_deg=float(rot_deg.mean()),
        rot_std_deg=float(rot_deg.std()),
        matched=int(ok.sum()),
        total=total,
        trans_errors=trans,
        rot_errors_deg=rot_deg,
    )
