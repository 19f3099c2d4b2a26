"""Parameters of ROS 1 ``amcl``, with its names and the defaults of its wiki page (except
where roverlab chose better ones; see :class:`AmclParams`).

Every ``<param>`` an amcl ``.launch`` or ``amcl_params.yaml`` sets is a field of
:class:`AmclParams`, named as ROS names it (``min_particles``, ``laser_z_hit``,
``odom_alpha1``, ...), so a launch file's whole set can be passed to
:meth:`AmclParams.from_ros`; a name amcl does not read is ignored, as ROS does, with a
warning naming it (and the closest known name, for a misspelling). The
node-level ones (frames, rates, map source, TF) are fields too: the filter does not use
them, the node does.

Units are SI: metres, radians, seconds, hertz.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final

from roverlab.core.rosparams import FieldKinds, unknown_warning
from roverlab.localization.amcl.errors import AmclParamsError

__all__ = [
    "IGNORED_PARAMETERS",
    "LASER_MODELS",
    "MODEL_DEFAULT",
    "NODE_PARAMETERS",
    "ODOM_ALPHA_DEFAULTS",
    "ODOM_MODELS",
    "AmclParams",
]

#: ``laser_model_type`` values.
LASER_MODELS: Final = ("likelihood_field", "beam", "likelihood_field_prob")
#: ``odom_model_type`` values.
ODOM_MODELS: Final = ("diff", "omni", "diff-corrected", "omni-corrected")

#: ``odom_alpha1..5`` value that stands for the odometry model's default.
MODEL_DEFAULT: Final = -1.0
#: The default ``odom_alpha1..5`` of each ``odom_model_type``: ROS's 0.2 for the original
#: models, whose noise is ``alpha * motion^2`` used as a standard deviation; 0.02 for the
#: corrected ones, whose standard deviation is ``sqrt(alpha) * motion`` (ROS keeps 0.2,
#: a 45% error on every motion; its wiki says to lower them).
ODOM_ALPHA_DEFAULTS: Final = {
    "diff": 0.2,
    "omni": 0.2,
    "diff-corrected": 0.02,
    "omni-corrected": 0.02,
}

#: Fields of :class:`AmclParams` that only the node uses.
NODE_PARAMETERS: Final = frozenset(
    {
        "transform_tolerance",
        "gui_publish_rate",
        "save_pose_rate",
        "use_map_topic",
        "first_map_only",
        "tf_broadcast",
        "odom_frame_id",
        "base_frame_id",
        "global_frame_id",
        "std_warn_level_x",
        "std_warn_level_y",
        "std_warn_level_yaw",
    }
)

#: Names ROS 1 amcl reads that have no effect here; accepted and dropped by ``from_ros``.
#: (``restore_defaults`` is dynamic_reconfigure's; ``bag_scan_period`` paces amcl's
#: ``--run-from-bag`` mode, which ``roverlab amcl run`` replaces.)
IGNORED_PARAMETERS: Final = frozenset({"restore_defaults", "bag_scan_period"})

_KINDS = FieldKinds(
    ints=frozenset({"min_particles", "max_particles", "resample_interval", "laser_max_beams"}),
    bools=frozenset(
        {"use_map_topic", "first_map_only", "selective_resampling", "tf_broadcast", "do_beamskip"}
    ),
    strs=frozenset(
        {"laser_model_type", "odom_model_type", "odom_frame_id", "base_frame_id", "global_frame_id"}
    ),
)
# a typo must not allocate gigabytes
_MAX_PARTICLES = 1_000_000


@dataclass(frozen=True, slots=True, kw_only=True)
class AmclParams:
    """amcl's parameters (ROS names and defaults; metres, radians, seconds, hertz).

    roverlab's defaults differ from ROS's in five places (docs/localization.md gives the
    evidence): ``odom_model_type`` ``diff-corrected`` (ROS ``diff``, which uses variances
    as standard deviations), ``odom_alpha1..5`` the model's default from
    :data:`ODOM_ALPHA_DEFAULTS` (ROS 0.2 for every model), ``laser_model_type``
    ``likelihood_field_prob`` (ROS ``likelihood_field``, whose ``1 + sum pz^3`` barely
    tells poses apart), ``laser_sigma_hit`` 0.1 (ROS 0.2) and ``resample_interval`` 1
    (ROS 2: the pose is published only after resampling). A value given is always used.

    Attributes:
        min_particles: fewest particles KLD sampling keeps.
        max_particles: most particles (and the count after (re)initialisation).
        kld_err: the KLD bound's error between the true and estimated distribution.
        kld_z: the upper standard normal quantile of the KLD bound (used as is, as amcl).
        update_min_d: a filter update needs this much travel along x or y (m) ...
        update_min_a: ... or this much rotation (rad) since the last one.
        resample_interval: resample after this many filter updates.
        transform_tolerance: how far the ``map -> odom`` TF is future-dated (s, node).
        recovery_alpha_slow: decay of the slow average of the weights (0: no recovery).
        recovery_alpha_fast: decay of the fast average (0: no recovery).
        initial_pose_x: initial pose mean, x (m).
        initial_pose_y: initial pose mean, y (m).
        initial_pose_a: initial pose mean, yaw (rad).
        initial_cov_xx: initial covariance of x (m^2).
        initial_cov_yy: initial covariance of y (m^2).
        initial_cov_aa: initial covariance of yaw (rad^2).
        gui_publish_rate: most ``particlecloud`` messages per second (-1: every update).
        save_pose_rate: how often the pose is written to ``initial_pose_*`` (Hz, -1: never).
        use_map_topic: subscribe ``map`` instead of calling the ``static_map`` service.
        first_map_only: keep the first map received on ``map``.
        selective_resampling: resample only when the effective sample size falls below
            half the particles.
        tf_broadcast: broadcast ``map -> odom``.
        laser_min_range: shorter readings count as max range (-1: the scan's range_min).
        laser_max_range: the range limit (-1: the scan's range_max).
        laser_max_beams: beams used per scan, evenly spread.
        laser_z_hit: weight of the hit part of the model.
        laser_z_short: weight of short readings (beam model).
        laser_z_max: weight of max-range readings (beam model).
        laser_z_rand: weight of random readings.
        laser_sigma_hit: standard deviation of the hit part (m).
        laser_lambda_short: decay of the short part (beam model, 1/m).
        laser_likelihood_max_dist: the likelihood field's distance cap (m).
        laser_model_type: ``likelihood_field``, ``beam`` or ``likelihood_field_prob``.
        do_beamskip: ``likelihood_field_prob``: skip beams most particles disagree on.
        beam_skip_distance: a beam agrees with the map when its end point lies this close
            to an obstacle (m).
        beam_skip_threshold: share of particles that must agree for a beam to be used.
        beam_skip_error_threshold: when this share of beams is skipped, use them all.
        odom_model_type: ``diff``, ``omni``, ``diff-corrected`` or ``omni-corrected``.
        odom_alpha1: rotation noise from rotation (-1: the model's default, see
            :data:`ODOM_ALPHA_DEFAULTS`).
        odom_alpha2: rotation noise from translation (-1: the model's default).
        odom_alpha3: translation noise from translation (-1: the model's default).
        odom_alpha4: translation noise from rotation (-1: the model's default).
        odom_alpha5: strafe noise from translation, omni models (-1: the model's default).
        odom_frame_id: the odometry frame (node).
        base_frame_id: the robot frame (node).
        global_frame_id: the map frame (node).

    Raises:
        AmclParamsError: a value of the wrong type or out of range.
    """

    min_particles: int = 100
    max_particles: int = 5000
    kld_err: float = 0.01
    kld_z: float = 0.99
    update_min_d: float = 0.2
    update_min_a: float = math.pi / 6.0
    resample_interval: int = 1
    transform_tolerance: float = 0.1
    std_warn_level_x: float = 0.2
    std_warn_level_y: float = 0.2
    std_warn_level_yaw: float = 0.1
    recovery_alpha_slow: float = 0.0
    recovery_alpha_fast: float = 0.0
    initial_pose_x: float = 0.0
    initial_pose_y: float = 0.0
    initial_pose_a: float = 0.0
    initial_cov_xx: float = 0.5 * 0.5
    initial_cov_yy: float = 0.5 * 0.5
    initial_cov_aa: float = (math.pi / 12.0) * (math.pi / 12.0)
    gui_publish_rate: float = -1.0
    save_pose_rate: float = 0.5
    use_map_topic: bool = False
    first_map_only: bool = False
    selective_resampling: bool = False
    tf_broadcast: bool = True
    laser_min_range: float = -1.0
    laser_max_range: float = -1.0
    laser_max_beams: int = 30
    laser_z_hit: float = 0.95
    laser_z_short: float = 0.1
    laser_z_max: float = 0.05
    laser_z_rand: float = 0.05
    laser_sigma_hit: float = 0.1
    laser_lambda_short: float = 0.1
    laser_likelihood_max_dist: float = 2.0
    laser_model_type: str = "likelihood_field_prob"
    do_beamskip: bool = False
    beam_skip_distance: float = 0.5
    beam_skip_threshold: float = 0.3
    beam_skip_error_threshold: float = 0.9
    odom_model_type: str = "diff-corrected"
    odom_alpha1: float = MODEL_DEFAULT
    odom_alpha2: float = MODEL_DEFAULT
    odom_alpha3: float = MODEL_DEFAULT
    odom_alpha4: float = MODEL_DEFAULT
    odom_alpha5: float = MODEL_DEFAULT
    odom_frame_id: str = "odom"
    base_frame_id: str = "base_link"
    global_frame_id: str = "map"

    def __post_init__(self) -> None:
        _KINDS.check(self, AmclParamsError)
        _check(self.min_particles >= 1, "min_particles must be >= 1")
        _check(
            self.min_particles <= self.max_particles <= _MAX_PARTICLES,
            f"need 1 <= min_particles <= max_particles <= {_MAX_PARTICLES}, got "
            f"min_particles {self.min_particles} and max_particles {self.max_particles}",
        )
        _check(0.0 < self.kld_err < 1.0, "kld_err must be in (0, 1)")
        _check(self.kld_z > 0.0, "kld_z must be > 0")
        _check(self.update_min_d >= 0.0, "update_min_d must be >= 0")
        _check(self.update_min_a >= 0.0, "update_min_a must be >= 0")
        _check(self.resample_interval >= 1, "resample_interval must be >= 1")
        _check(self.transform_tolerance >= 0.0, "transform_tolerance must be >= 0")
        for name in ("std_warn_level_x", "std_warn_level_y", "std_warn_level_yaw"):
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0")
        for name in ("recovery_alpha_slow", "recovery_alpha_fast"):
            _check(0.0 <= getattr(self, name) <= 1.0, f"{name} must be in [0, 1]")
        for name in ("initial_cov_xx", "initial_cov_yy", "initial_cov_aa"):
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0")
        _check(self.laser_max_beams >= 2, "laser_max_beams must be >= 2")
        for name in ("laser_z_hit", "laser_z_short", "laser_z_max", "laser_z_rand"):
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0")
        _check(self.laser_sigma_hit > 0.0, "laser_sigma_hit must be > 0")
        _check(self.laser_lambda_short > 0.0, "laser_lambda_short must be > 0")
        _check(self.laser_likelihood_max_dist > 0.0, "laser_likelihood_max_dist must be > 0")
        _check(
            self.laser_model_type in LASER_MODELS,
            f"laser_model_type must be one of {', '.join(LASER_MODELS)}, "
            f"got {self.laser_model_type!r}",
        )
        _check(
            self.odom_model_type in ODOM_MODELS,
            f"odom_model_type must be one of {', '.join(ODOM_MODELS)}, "
            f"got {self.odom_model_type!r}",
        )
        _check(self.beam_skip_distance >= 0.0, "beam_skip_distance must be >= 0")
        _check(0.0 <= self.beam_skip_threshold <= 1.0, "beam_skip_threshold must be in [0, 1]")
        _check(
            0.0 <= self.beam_skip_error_threshold <= 1.0,
            "beam_skip_error_threshold must be in [0, 1]",
        )
        for i in range(1, 6):
            name = f"odom_alpha{i}"
            if getattr(self, name) == MODEL_DEFAULT:
                object.__setattr__(self, name, ODOM_ALPHA_DEFAULTS[self.odom_model_type])
            _check(getattr(self, name) >= 0.0, f"{name} must be >= 0 (or -1: the model's default)")

    @classmethod
    def from_ros(
        cls, params: Mapping[str, Any], *, warnings: list[str] | None = None
    ) -> AmclParams:
        """Build from an amcl ``<param>`` set (names as in a ``.launch`` file).

        Integers given for float parameters are accepted (``value="1"``), and integral
        floats for integer ones; :data:`IGNORED_PARAMETERS` are dropped; any other unknown
        name is ignored, as ROS ignores a parameter amcl does not read, with a warning
        naming it (and the closest known name) appended to ``warnings``. An unknown
        ``laser_model_type`` is replaced by ``likelihood_field`` with a warning, as amcl
        does ("Unknown laser model type ...; defaulting to likelihood_field model").

        Raises:
            AmclParamsError: a bad value.
        """
        names = [f.name for f in dataclasses.fields(cls)]
        told = warnings if warnings is not None else []

        def unknown(key: str) -> None:
            told.append(unknown_warning("amcl", key, names))

        kwargs = _KINDS.kwargs(params, names, ignored=IGNORED_PARAMETERS, unknown=unknown)
        model = kwargs.get("laser_model_type")
        if isinstance(model, str) and model not in LASER_MODELS:
            kwargs["laser_model_type"] = "likelihood_field"
            if warnings is not None:
                warnings.append(
                    f'Unknown laser model type "{model}"; defaulting to likelihood_field model'
                )
        return cls(**kwargs)

    @staticmethod
    def default_of(name: str, odom_model_type: str) -> Any:
        """The default of parameter ``name`` when ``odom_model_type`` is set (the alphas
        depend on it; what a node declares)."""
        field = next(f for f in dataclasses.fields(AmclParams) if f.name == name)
        if field.default == MODEL_DEFAULT and name.startswith("odom_alpha"):
            return ODOM_ALPHA_DEFAULTS.get(odom_model_type, MODEL_DEFAULT)
        return field.default

    def to_ros(self) -> dict[str, Any]:
        """The parameters as a ``{ROS name: value}`` dict (what a node declares)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}

    @property
    def odom_alphas(self) -> tuple[float, float, float, float, float]:
        """``(odom_alpha1, ..., odom_alpha5)``."""
        return (
            self.odom_alpha1,
            self.odom_alpha2,
            self.odom_alpha3,
            self.odom_alpha4,
            self.odom_alpha5,
        )


def _check(ok: bool, msg: str) -> None:
    if not ok:
        raise AmclParamsError(msg)
