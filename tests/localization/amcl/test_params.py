"""amcl's parameters: ROS names and defaults, from_ros, validation."""

from __future__ import annotations

import dataclasses
import math

import pytest

from roverlab.localization.amcl import AmclParams, AmclParamsError


def test_defaults_are_the_ros_wiki_values_except_five() -> None:
    p = AmclParams()
    expected = {
        "min_particles": 100, "max_particles": 5000, "kld_err": 0.01, "kld_z": 0.99,
        "update_min_d": 0.2, "update_min_a": math.pi / 6, "resample_interval": 1,
        "transform_tolerance": 0.1, "recovery_alpha_slow": 0.0, "recovery_alpha_fast": 0.0,
        "initial_cov_xx": 0.25, "initial_cov_yy": 0.25, "initial_cov_aa": (math.pi / 12) ** 2,
        "gui_publish_rate": -1.0, "save_pose_rate": 0.5, "use_map_topic": False,
        "first_map_only": False, "selective_resampling": False, "tf_broadcast": True,
        "laser_min_range": -1.0, "laser_max_range": -1.0, "laser_max_beams": 30,
        "laser_z_hit": 0.95, "laser_z_short": 0.1, "laser_z_max": 0.05, "laser_z_rand": 0.05,
        "laser_sigma_hit": 0.1, "laser_lambda_short": 0.1, "laser_likelihood_max_dist": 2.0,
        "laser_model_type": "likelihood_field_prob", "do_beamskip": False,
        "beam_skip_distance": 0.5, "beam_skip_threshold": 0.3,
        "beam_skip_error_threshold": 0.9, "odom_model_type": "diff-corrected",
        "odom_frame_id": "odom", "base_frame_id": "base_link", "global_frame_id": "map",
    }  # fmt: skip
    for name, value in expected.items():
        assert getattr(p, name) == pytest.approx(value), name
    assert p.odom_alphas == (0.02, 0.02, 0.02, 0.02, 0.02)
    assert AmclParams.from_ros(p.to_ros()) == p


def test_the_alphas_default_to_the_chosen_models_and_given_values_are_kept() -> None:
    # a launch file that picks ROS's original model gets ROS's alphas
    assert AmclParams.from_ros({"odom_model_type": "diff"}).odom_alphas == (0.2,) * 5
    assert AmclParams(odom_model_type="omni").odom_alphas == (0.2,) * 5
    assert AmclParams.from_ros({"odom_model_type": "omni-corrected"}).odom_alphas == (0.02,) * 5
    p = AmclParams.from_ros({"odom_model_type": "diff", "odom_alpha2": 0.5, "odom_alpha3": -1})
    assert p.odom_alphas == (0.2, 0.5, 0.2, 0.2, 0.2)  # -1: the model's default
    assert AmclParams.default_of("odom_alpha4", "diff") == 0.2
    assert AmclParams.default_of("odom_alpha4", "diff-corrected") == 0.02
    assert AmclParams.default_of("laser_sigma_hit", "diff") == 0.1


def test_from_ros_coerces_numbers_and_drops_ignored_names() -> None:
    p = AmclParams.from_ros(
        {
            "laser_sigma_hit": 1,
            "min_particles": 500.0,
            "restore_defaults": False,
            "tf_broadcast": False,
        }
    )
    assert p.laser_sigma_hit == 1.0 and isinstance(p.laser_sigma_hit, float)
    assert p.min_particles == 500 and isinstance(p.min_particles, int)
    assert p.tf_broadcast is False


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"min_particles": 600, "max_particles": 500}, "min_particles <= max_particles"),
        ({"odom_model_type": "ackermann"}, "odom_model_type must be one of"),
        ({"kld_err": 0.0}, "kld_err must be in (0, 1)"),
        ({"resample_interval": 0}, "resample_interval must be >= 1"),
        ({"laser_sigma_hit": float("nan")}, "laser_sigma_hit must be finite"),
        ({"use_map_topic": 1}, "use_map_topic must be true or false"),
        ({"laser_max_beams": 1}, "laser_max_beams must be >= 2"),
        ({"odom_alpha3": -0.1}, "odom_alpha3 must be >= 0"),
    ],
)
def test_bad_parameters_are_one_clear_error(params: dict[str, object], message: str) -> None:
    with pytest.raises(AmclParamsError) as err:
        AmclParams.from_ros(params)
    assert message in str(err.value)


def test_unknown_names_are_warned_about_by_name_and_ignored_as_ros_does() -> None:
    warnings: list[str] = []
    p = AmclParams.from_ros(
        {"laser_z_hti": 0.5, "min_particles": 300, "tf_prefix": "", "use_odom_twist": True},
        warnings=warnings,
    )
    assert p.min_particles == 300 and p.laser_z_hit == AmclParams().laser_z_hit
    assert warnings == [
        "amcl: unknown parameter 'laser_z_hti' (did you mean laser_z_hit?) is ignored",
        "amcl: unknown parameter 'tf_prefix' is ignored",
        "amcl: unknown parameter 'use_odom_twist' is ignored",
    ]
    assert AmclParams.from_ros({"bag_scan_period": 0.1}, warnings=warnings) == AmclParams()
    assert len(warnings) == 3  # a name amcl reads but roverlab need not: quiet
    with pytest.raises(AmclParamsError, match="min_particles must be >= 1"):
        AmclParams.from_ros({"laser_z_hti": 0.5, "min_particles": 0})  # values still checked


def test_an_unknown_laser_model_is_a_warning_and_likelihood_field_as_amcl_does() -> None:
    warnings: list[str] = []
    p = AmclParams.from_ros({"laser_model_type": "likelihood"}, warnings=warnings)
    assert p.laser_model_type == "likelihood_field"
    assert warnings == [
        'Unknown laser model type "likelihood"; defaulting to likelihood_field model'
    ]
    with pytest.raises(AmclParamsError, match="laser_model_type must be one of"):
        AmclParams(laser_model_type="likelihood")
    levels = AmclParams.from_ros({"std_warn_level_x": 0.3, "std_warn_level_yaw": 0.05})
    assert (levels.std_warn_level_x, levels.std_warn_level_y, levels.std_warn_level_yaw) == (
        0.3, 0.2, 0.05,
    )  # fmt: skip


def test_fields_are_keyword_only() -> None:
    assert all(f.kw_only for f in dataclasses.fields(AmclParams))
    with pytest.raises(TypeError):
        AmclParams(100)  # type: ignore[misc]
