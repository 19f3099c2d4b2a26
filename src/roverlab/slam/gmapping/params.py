"""Parameters of slam_gmapping, with the ROS names and defaults of the ROS wiki.

Every ``<param>`` a ``gmapping.launch`` sets is a field of :class:`GMappingParams`, named as
ROS names it (``maxUrange``, ``srr``, ``linearUpdate``, ...), so a launch file's whole set
can be passed to :meth:`GMappingParams.from_ros`; a misspelt name is an error, not silently
ignored. The node-level ones (frames, publishing periods) are fields too: the algorithm does
not use them, the node does.

Units are SI: metres, radians, seconds.
"""

from __future__ import annotations

import builtins
import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from roverlab.core.rosparams import FieldKinds
from roverlab.slam.gmapping.errors import GMappingParamsError

__all__ = ["DEPRECATED_PARAMETERS", "NODE_PARAMETERS", "GMappingParams"]

#: Fields of :class:`GMappingParams` that only the node uses (frames, periods, TF).
NODE_PARAMETERS = frozenset(
    {
        "base_frame",
        "map_frame",
        "odom_frame",
        "map_update_interval",
        "transform_publish_period",
        "tf_delay",
    }
)

#: Names slam_gmapping once read and now ignores; accepted and dropped by ``from_ros``.
DEPRECATED_PARAMETERS = frozenset({"inverted_laser"})

_KINDS = FieldKinds(
    ints=frozenset({"throttle_scans", "kernelSize", "iterations", "lskip", "particles"}),
    strs=frozenset({"base_frame", "map_frame", "odom_frame"}),
    optional=frozenset({"maxRange", "tf_delay"}),
)

# Upper bounds that keep a typo from allocating gigabytes or running for hours.
_MAX_KERNEL = 10
_MAX_PROPOSAL_SAMPLES = 10_000


@dataclass(frozen=True, slots=True, kw_only=True)
class GMappingParams:
    """slam_gmapping's parameters (ROS names and defaults; metres, radians, seconds).

    Attributes:
        throttle_scans: process one scan in this many (the others are dropped).
        base_frame: the robot frame (node only).
        map_frame: the map frame (node only).
        odom_frame: the odometry frame (node only).
        map_update_interval: seconds between two map publications (node only).
        maxRange: the sensor's maximum range; readings beyond it are discarded entirely.
            ``None``: the scan's ``range_max`` minus 1 cm, as slam_gmapping does.
        maxUrange: the usable range: beams are cropped to it; readings at or beyond it
            clear the cells up to it and mark no obstacle, and the scan matcher ignores them.
        sigma: the spread of the endpoint match used by the hill-climbing scan matcher's
            score ``exp(-d^2 / sigma)`` (d: distance from an endpoint to the nearest
            occupied cell's mean hit point within the kernel).
        kernelSize: the search window (cells either side) for that correspondence.
        lstep: the initial translational step of the hill climbing (m).
        astep: the initial rotational step of the hill climbing (rad).
        iterations: how many times the hill climbing halves its steps.
        lsigma: the spread of the beam likelihood ``-d^2 / lsigma`` used for the weights.
        ogain: the gain smoothing the weights: a particle's normalised weight is
            ``exp((log w - max log w) / (ogain * particles))``.
        lskip: use one beam in ``lskip + 1`` for matching and weighting.
        minimumScore: below (or at) this matcher score the scan-matched pose is rejected
            and the odometry sample is kept.
        srr: odometry error in translation as a function of translation (m/m).
        srt: odometry error in translation as a function of rotation (m/rad).
        str: odometry error in rotation as a function of translation (rad/m).
        stt: odometry error in rotation as a function of rotation (rad/rad).
        linearUpdate: a scan is processed once the robot has travelled this far (m) ...
        angularUpdate: ... or turned this much (rad) since the last processed scan ...
        temporalUpdate: ... or this much time has passed (s); negative: never by time.
        resampleThreshold: resample when ``Neff < resampleThreshold * particles``.
        particles: number of particles.
        xmin: the map's initial extent (m, map frame); it grows as the robot explores.
        ymin: see ``xmin``.
        xmax: see ``xmin``.
        ymax: see ``xmin``.
        delta: the map resolution (m per cell).
        llsamplerange: half-width of the translational sampling grid of the improved
            proposal around the scan-matched pose (m).
        llsamplestep: its step (m).
        lasamplerange: half-width of the rotational sampling grid (rad).
        lasamplestep: its step (rad).
        transform_publish_period: seconds between two ``map -> odom`` TF (node only).
        occ_thresh: a cell whose hit ratio exceeds this is occupied (100) in the map.
        tf_delay: TF future-dating (s, node only); ``None``: ``transform_publish_period``.

    Raises:
        GMappingParamsError: a value of the wrong type or out of range.
    """

    throttle_scans: int = 1
    base_frame: builtins.str = "base_link"
    map_frame: builtins.str = "map"
    odom_frame: builtins.str = "odom"
    map_update_interval: float = 5.0
    maxRange: float | None = None
    maxUrange: float = 80.0
    sigma: float = 0.05
    kernelSize: int = 1
    lstep: float = 0.05
    astep: float = 0.05
    iterations: int = 5
    lsigma: float = 0.075
    ogain: float = 3.0
    lskip: int = 0
    minimumScore: float = 0.0
    srr: float = 0.1
    srt: float = 0.2
    str: float = 0.1
    stt: float = 0.2
    linearUpdate: float = 1.0
    angularUpdate: float = 0.5
    temporalUpdate: float = -1.0
    resampleThreshold: float = 0.5
    particles: int = 30
    xmin: float = -100.0
    ymin: float = -100.0
    xmax: float = 100.0
    ymax: float = 100.0
    delta: float = 0.05
    llsamplerange: float = 0.01
    llsamplestep: float = 0.01
    lasamplerange: float = 0.005
    lasamplestep: float = 0.005
    transform_publish_period: float = 0.05
    occ_thresh: float = 0.25
    tf_delay: float | None = None

    def __post_init__(self) -> None:
        _KINDS.check(self, GMappingParamsError)
        _check(self.throttle_scans >= 1, "throttle_scans must be >= 1")
        _check(self.map_update_interval >= 0.0, "map_update_interval must be >= 0")
        _check(self.maxRange is None or self.maxRange > 0.0, "maxRange must be > 0")
        _check(self.maxUrange > 0.0, "maxUrange must be > 0")
        _check(self.sigma > 0.0, "sigma must be > 0")
        _check(0 <= self.kernelSize <= _MAX_KERNEL, f"kernelSize must be in [0, {_MAX_KERNEL}]")
        _check(self.lstep > 0.0, "lstep must be > 0")
        _check(self.astep > 0.0, "astep must be > 0")
        _check(0 <= self.iterations <= 50, "iterations must be in [0, 50]")
        _check(self.lsigma > 0.0, "lsigma must be > 0")
        _check(self.ogain > 0.0, "ogain must be > 0")
        _check(self.lskip >= 0, "lskip must be >= 0")
        for name in ("srr", "srt", "str", "stt"):
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0")
        _check(self.linearUpdate >= 0.0, "linearUpdate must be >= 0")
        _check(self.angularUpdate >= 0.0, "angularUpdate must be >= 0")
        _check(0.0 <= self.resampleThreshold <= 1.0, "resampleThreshold must be in [0, 1]")
        _check(self.particles >= 1, "particles must be >= 1")
        _check(self.xmin < self.xmax, "xmin must be < xmax")
        _check(self.ymin < self.ymax, "ymin must be < ymax")
        _check(self.delta > 0.0, "delta must be > 0")
        _check(self.llsamplerange >= 0.0, "llsamplerange must be >= 0")
        _check(self.llsamplestep > 0.0, "llsamplestep must be > 0")
        _check(self.lasamplerange >= 0.0, "lasamplerange must be >= 0")
        _check(self.lasamplestep > 0.0, "lasamplestep must be > 0")
        n = self.proposal_samples
        _check(
            n <= _MAX_PROPOSAL_SAMPLES,
            f"llsamplerange/llsamplestep and lasamplerange/lasamplestep give {n} proposal "
            f"samples per particle (at most {_MAX_PROPOSAL_SAMPLES})",
        )
        _check(self.transform_publish_period >= 0.0, "transform_publish_period must be >= 0")
        _check(0.0 <= self.occ_thresh <= 1.0, "occ_thresh must be in [0, 1]")
        _check(self.tf_delay is None or self.tf_delay >= 0.0, "tf_delay must be >= 0")

    @classmethod
    def from_ros(cls, params: Mapping[builtins.str, Any]) -> GMappingParams:
        """Build from a slam_gmapping ``<param>`` set (names as in a ``.launch`` file).

        Integers given for float parameters are accepted (``value="1"``), and integral
        floats for integer ones; deprecated names (:data:`DEPRECATED_PARAMETERS`) are
        dropped; any other unknown name is an error.

        Raises:
            GMappingParamsError: an unknown name or a bad value.
        """
        names = {f.name for f in dataclasses.fields(cls)}
        kwargs = _KINDS.kwargs(
            params,
            names,
            ignored=DEPRECATED_PARAMETERS,
            unknown=lambda key: GMappingParamsError(f"unknown slam_gmapping parameter {key!r}"),
        )
        return cls(**kwargs)

    @property
    def proposal_samples(self) -> int:
        """Poses the improved proposal evaluates per particle (its sampling grid size)."""
        nl = _half_count(self.llsamplerange, self.llsamplestep)
        na = _half_count(self.lasamplerange, self.lasamplestep)
        return (2 * nl + 1) ** 2 * (2 * na + 1)

    def max_range(self, sensor_range_max: float) -> float:
        """The effective ``maxRange`` for a sensor whose ``range_max`` is given (m)."""
        if self.maxRange is not None:
            return float(self.maxRange)
        if math.isfinite(sensor_range_max):
            return float(sensor_range_max) - 0.01
        return math.inf


def _half_count(rng: float, step: float) -> int:
    """Grid points on one side of zero: ``0, step, 2 step, ... <= rng`` (float-safe)."""
    return int(math.floor(rng / step + 1e-9))


def _check(ok: bool, msg: builtins.str) -> None:
    if not ok:
        raise GMappingParamsError(msg)
