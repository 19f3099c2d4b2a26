"""Simulated laser logs with ground truth: a robot drives a :class:`Building`'s route.

The robot turns in place towards each waypoint, then drives straight to it (at
``speed_mps`` and ``turn_rate_rps``); a scan is taken every ``1 / scan_rate_hz`` seconds.
Each scan's ranges are cast through the building grid by the shared ray caster
(:func:`roverlab.raycast.cast_grid_many`) with gaussian range noise; no return is written
as the laser's maximum range, as CARMEN does.

Odometry integrates the true motion between scans with noise of an :class:`OdometryNoise`
level (:data:`NOISE_LEVELS`): a random walk in translation and heading whose variance
grows with the distance driven and the angle turned, plus a heading bias per metre.
``radish`` is the raw odometry of the Radish logs as docs/localization.md measured it on
intel: per 0.2 m update 8% of the motion in translation, 0.026 rad (std) plus a 0.012 rad
bias in heading, and 8% of a turn.

:func:`write_log` writes what ``roverlab slam run`` and ``roverlab slam eval`` read:

* ``NAME.clf``: CARMEN ``ROBOTLASER1`` lines (laser pose and noisy odometry pose; any
  field of view, so 360-degree lasers too);
* ``NAME.relations``: the true relative pose of every scan to the scan ``relation_step_s``
  later (Radish's ``timestamp1 timestamp2 x y z roll pitch yaw``), scored by the same
  relations metric as intel and fr079;
* ``NAME.gt.tum``: the true robot pose of every scan in the frame of the first one (the
  frame every SLAM trajectory is in), for an absolute error.

Every random draw comes from the ``np.random.Generator`` given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
from numpy.typing import NDArray

from roverlab.geometry import SE2, wrap_angle
from roverlab.raycast import cast_grid_many
from roverlab.slam.data._io import atomic_write_text
from roverlab.slam.data.errors import SlamError
from roverlab.slam.data.evaluation import Relations
from roverlab.slam.data.scans import LaserLog, ScanRecord
from roverlab.slam.data.trajectory import Trajectory, write_tum
from roverlab.slam.simulated.buildings import Building

__all__ = [
    "LASERS",
    "NOISE_LEVELS",
    "Laser",
    "OdometryNoise",
    "SimulatedLog",
    "simulate",
    "write_log",
]

FloatArray = NDArray[np.float64]

#: First timestamp of a simulated log (s).
_T0: Final = 1_000_000_000.0


@dataclass(frozen=True, slots=True, kw_only=True)
class OdometryNoise:
    """Odometry error per scan step: standard deviations grow with the square root of the
    distance ``d`` (m) and turn ``a`` (rad) of the step; the bias grows with ``d``.

    Attributes:
        trans_per_sqrt_m: translation std along the motion, ``* sqrt(d)`` (m).
        lateral_per_sqrt_m: translation std across the motion, ``* sqrt(d)`` (m).
        rot_per_sqrt_m: heading std from driving, ``* sqrt(d)`` (rad).
        rot_per_sqrt_rad: heading std from turning, ``* sqrt(a)`` (rad).
        rot_bias_per_m: heading bias, ``* d`` (rad).
    """

    trans_per_sqrt_m: float = 0.0
    lateral_per_sqrt_m: float = 0.0
    rot_per_sqrt_m: float = 0.0
    rot_per_sqrt_rad: float = 0.0
    rot_bias_per_m: float = 0.0


_RADISH = OdometryNoise(
    trans_per_sqrt_m=0.08 * 0.2 / math.sqrt(0.2),
    lateral_per_sqrt_m=0.01,
    rot_per_sqrt_m=0.026 / math.sqrt(0.2),
    rot_per_sqrt_rad=0.08 * 0.5 / math.sqrt(0.5),
    rot_bias_per_m=0.012 / 0.2,
)

#: Odometry noise levels by name: ``none`` (perfect), ``low`` (good wheel encoders),
#: ``radish`` (the raw odometry of the Radish logs), ``high`` (twice that).
NOISE_LEVELS: Final = {
    "none": OdometryNoise(),
    "low": OdometryNoise(
        trans_per_sqrt_m=0.01, lateral_per_sqrt_m=0.002, rot_per_sqrt_m=0.01, rot_per_sqrt_rad=0.02
    ),
    "radish": _RADISH,
    "high": OdometryNoise(
        trans_per_sqrt_m=2 * _RADISH.trans_per_sqrt_m,
        lateral_per_sqrt_m=2 * _RADISH.lateral_per_sqrt_m,
        rot_per_sqrt_m=2 * _RADISH.rot_per_sqrt_m,
        rot_per_sqrt_rad=2 * _RADISH.rot_per_sqrt_rad,
        rot_bias_per_m=2 * _RADISH.rot_bias_per_m,
    ),
}


@dataclass(frozen=True, slots=True, kw_only=True)
class Laser:
    """A planar laser scanner.

    Attributes:
        fov_rad: field of view (rad); 2 pi is a full turn (no beam repeated).
        beams: number of beams.
        range_max_m: maximum range (m); no return is written as this value.
        range_sigma_m: gaussian range noise (m).
        offset_x_m: the laser's position ahead of the robot's centre (m).
    """

    fov_rad: float
    beams: int
    range_max_m: float
    range_sigma_m: float = 0.01
    offset_x_m: float = 0.0

    def angles(self) -> FloatArray:
        """Beam angles in the laser frame (rad)."""
        if self.fov_rad >= 2 * math.pi - 1e-9:
            step = 2 * math.pi / self.beams
            return np.asarray(-math.pi + np.arange(self.beams) * step, dtype=np.float64)
        step = self.fov_rad / (self.beams - 1)
        return np.asarray(-0.5 * self.fov_rad + np.arange(self.beams) * step, dtype=np.float64)


#: Lasers by name: ``180`` a SICK LMS-like front laser (181 beams, 30 m), ``360`` a
#: rotating lidar (360 beams, 12 m, RPLIDAR-like).
LASERS: Final = {
    "180": Laser(fov_rad=math.pi, beams=181, range_max_m=30.0, offset_x_m=0.1),
    "360": Laser(fov_rad=2 * math.pi, beams=360, range_max_m=12.0),
}


@dataclass(frozen=True, eq=False)
class SimulatedLog:
    """A simulated log and its ground truth.

    Attributes:
        log: the scans with their (noisy) odometry poses.
        truth: the true robot pose of every scan, in the frame of the first one.
        relations: (K, 2) scan index pairs of the ``.relations`` file.
    """

    log: LaserLog
    truth: Trajectory
    relations: NDArray[np.int64]

    def true_relations(self) -> Relations:
        """The true relative pose of each pair, as ``read_relations`` reads them back."""
        t = self.truth
        i, j = self.relations[:, 0], self.relations[:, 1]
        poses = np.array(
            [_relative(t.se2(a), t.se2(b)).as_array() for a, b in self.relations.tolist()]
        ).reshape(-1, 3)
        texts = t.texts()
        return Relations(
            t.timestamps[i],
            t.timestamps[j],
            poses,
            tuple(texts[a] for a in i.tolist()),
            tuple(texts[b] for b in j.tolist()),
        )


def _route_poses(b: Building, speed_mps: float, turn_rate_rps: float, rate_hz: float) -> FloatArray:
    """True poses every ``1 / rate_hz`` s along the route (turn in place, then drive)."""
    segs: list[tuple[FloatArray, float, float, float]] = []  # start, heading, turn, length
    pos, heading = b.route[0].copy(), b.start_heading
    for wp in b.route[1:]:
        d = wp - pos
        length = float(np.hypot(*d))
        if length < 1e-9:
            continue
        target = math.atan2(d[1], d[0])
        segs.append((pos.copy(), heading, wrap_angle(target - heading), length))
        pos, heading = wp.astype(np.float64), target
    durations = np.array([abs(t) / turn_rate_rps + n / speed_mps for _, _, t, n in segs])
    ends = np.cumsum(durations)
    times = np.arange(0.0, float(ends[-1]) + 1e-9, 1.0 / rate_hz)
    out = np.empty((times.size, 3))
    for k, t in enumerate(times):
        i = min(int(np.searchsorted(ends, t)), len(segs) - 1)
        start, h0, turn, length = segs[i]
        local = t - (ends[i] - durations[i])
        t_turn = abs(turn) / turn_rate_rps
        if local < t_turn:
            out[k] = (
                start[0],
                start[1],
                wrap_angle(h0 + math.copysign(local * turn_rate_rps, turn)),
            )
        else:
            h = h0 + turn
            s = min((local - t_turn) * speed_mps, length)
            out[k] = (start[0] + s * math.cos(h), start[1] + s * math.sin(h), wrap_angle(h))
    return out


def _relative(a: SE2, b: SE2) -> SE2:
    return ~a * b


def _noisy_odometry(truth: FloatArray, noise: OdometryNoise, rng: np.random.Generator) -> list[SE2]:
    odom = [SE2(0.0, 0.0, 0.0)]
    for k in range(1, truth.shape[0]):
        step = _relative(SE2(*truth[k - 1]), SE2(*truth[k]))
        d = math.hypot(step.x, step.y)
        a = abs(step.theta)
        e = rng.standard_normal(3)
        fwd = d + noise.trans_per_sqrt_m * math.sqrt(d) * e[0]
        side = noise.lateral_per_sqrt_m * math.sqrt(d) * e[1]
        rot_sd = math.sqrt(noise.rot_per_sqrt_m**2 * d + noise.rot_per_sqrt_rad**2 * a)
        dth = step.theta + rot_sd * e[2] + noise.rot_bias_per_m * d
        # the true step's direction of travel, the noisy length and heading change
        mov = math.atan2(step.y, step.x) if d > 1e-12 else 0.0
        c, s = math.cos(mov), math.sin(mov)
        odom.append(odom[-1] * SE2(c * fwd - s * side, s * fwd + c * side, dth))
    return odom


def simulate(
    b: Building,
    *,
    laser: Laser,
    noise: OdometryNoise,
    rng: np.random.Generator,
    speed_mps: float = 0.5,
    turn_rate_rps: float = 0.5,
    scan_rate_hz: float = 10.0,
    relation_step_s: float = 1.0,
) -> SimulatedLog:
    """Drive the building's route and record scans, odometry and ground truth.

    Raises:
        SlamError: a non-positive speed, turn rate or scan rate.
    """
    if not (speed_mps > 0 and turn_rate_rps > 0 and scan_rate_hz > 0 and relation_step_s > 0):
        raise SlamError("speed, turn rate, scan rate and relation step must be > 0")
    truth = _route_poses(b, speed_mps, turn_rate_rps, scan_rate_hz)
    angles = laser.angles()
    c, s = np.cos(truth[:, 2]), np.sin(truth[:, 2])
    sensor = np.column_stack(
        (truth[:, 0] + laser.offset_x_m * c, truth[:, 1] + laser.offset_x_m * s, truth[:, 2])
    )
    ranges = cast_grid_many(
        b.grid, b.resolution, b.origin, sensor, angles, laser.range_max_m, occupied_value=1
    )
    hit = np.isfinite(ranges)
    ranges = np.where(
        hit, ranges + laser.range_sigma_m * rng.standard_normal(ranges.shape), laser.range_max_m
    )
    ranges = np.clip(ranges, 0.0, laser.range_max_m)
    odom = _noisy_odometry(truth, noise, rng)
    increment = float(angles[1] - angles[0])
    offset = SE2(laser.offset_x_m, 0.0, 0.0)
    stamps = _T0 + np.arange(truth.shape[0]) / scan_rate_hz
    records = [
        ScanRecord(
            float(t),
            ranges[k].astype(np.float32),
            float(angles[0]),
            increment,
            0.0,
            laser.range_max_m,
            odom[k],
            offset,
            f"{t:.6f}",
        )
        for k, t in enumerate(stamps)
    ]
    first = SE2(*truth[0])
    local = np.array([_relative(first, SE2(*p)).as_array() for p in truth])
    texts = [r.timestamp_text for r in records]
    step = max(1, round(relation_step_s * scan_rate_hz))
    idx = np.arange(truth.shape[0] - step)
    pairs = np.column_stack((idx, idx + step)).astype(np.int64)
    return SimulatedLog(
        LaserLog(records, source=b.name), Trajectory.from_poses(texts, local), pairs
    )


def _num(v: float) -> str:
    return f"{v:.6f}"


def _clf_line(rec: ScanRecord) -> str:
    n = rec.ranges.shape[0]
    fov = rec.angle_increment * (n - 1)
    laser = rec.laser_pose
    odom = rec.odom_pose
    head = (
        f"ROBOTLASER1 0 {_num(rec.angle_min)} {_num(fov)} {_num(rec.angle_increment)} "
        f"{_num(rec.range_max)} 0.010000 0 {n} "
    )
    body = " ".join(f"{v:.3f}" for v in rec.ranges.tolist())
    tail = (
        f" 0 {_num(laser.x)} {_num(laser.y)} {_num(laser.theta)} {_num(odom.x)} "
        f"{_num(odom.y)} {_num(odom.theta)} 0.000000 0.000000 0.550000 0.050000 0.000000 "
        f"{rec.timestamp_text} roverlab-sim {rec.timestamp_text}"
    )
    return head + body + tail + "\n"


def write_log(sim: SimulatedLog, directory: str | Path, name: str) -> tuple[Path, Path, Path]:
    """Write ``NAME.clf``, ``NAME.relations`` and ``NAME.gt.tum`` into ``directory``.

    Returns:
        The three paths.

    Raises:
        SlamError: a file cannot be written.
    """
    d = Path(directory)
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise SlamError(f"{d}: cannot create: {err.strerror or err}") from err
    clf, rel, gt = d / f"{name}.clf", d / f"{name}.relations", d / f"{name}.gt.tum"
    header = "# simulated by roverlab (roverlab.slam.simulated): ROBOTLASER1 scans\n"
    atomic_write_text(clf, header + "".join(_clf_line(r) for r in sim.log), SlamError)
    rel_table = sim.true_relations()
    assert rel_table.first_texts is not None and rel_table.second_texts is not None
    lines = [
        f"{a} {b} {_num(x)} {_num(y)} 0.000000 0.000000 0.000000 {_num(th)}\n"
        for a, b, (x, y, th) in zip(
            rel_table.first_texts,
            rel_table.second_texts,
            rel_table.poses.tolist(),
            strict=True,
        )
    ]
    atomic_write_text(rel, "".join(lines), SlamError)
    write_tum(gt, sim.truth)
    return clf, rel, gt
