"""Tests for fleetsim.localization.amcl.params: ROS names/defaults, -1 as unset, validation."""

import logging
import math

import pytest

from fleetsim.errors import ParameterError
from fleetsim.localization.amcl.params import AmclParams, params_from_mapping


def test_defaults_are_ros_defaults():
    p = AmclParams()
    assert (p.min_particles, p.max_particles) == (100, 5000)
    assert (p.kld_err, p.kld_z) == (0.01, 0.99)
    assert p.update_min_d == 0.2 and p.update_min_a == pytest.approx(math.pi / 6)
    assert p.resample_interval == 2 and p.transform_tolerance == 0.1
    assert p.recovery_alpha_slow == 0.0 and p.recovery_alpha_fast == 0.0
    assert p.initial_cov_xx == 0.25 and p.initial_cov_yy == 0.25
    assert p.initial_cov_aa == pytest.approx((math.pi / 12) ** 2)
    assert p.gui_publish_rate is None and p.laser_min_range is None and p.laser_max_range is None
    assert p.laser_max_beams == 30 and p.laser_model_type == "likelihood_field"
    assert (p.laser_z_hit, p.laser_z_short, p.laser_z_max, p.laser_z_rand) == (
        0.95,
        0.1,
        0.05,
        0.05,
    )
    assert (p.laser_sigma_hit, p.laser_lambda_short, p.laser_likelihood_max_dist) == (
        0.2,
        0.1,
        2.0,
    )
    assert p.odom_model_type == "diff" and p.odom_alphas == (0.2,) * 5
    assert (p.odom_frame_id, p.base_frame_id, p.global_frame_id) == ("odom", "base_link", "map")
    assert p.tf_broadcast is True and p.selective_resampling is False and p.do_beamskip is False
    assert (p.beam_skip_distance, p.beam_skip_threshold, p.beam_skip_error_threshold) == (
        0.5,
        0.3,
        0.9,
    )


def test_minus_one_from_yaml_means_unset():
    p = params_from_mapping(
        {
            "laser_max_range": -1,
            "laser_min_range": -1.0,
            "gui_publish_rate": -1,
            "save_pose_rate": -1,
        }
    )
    assert p.laser_max_range is None and p.laser_min_range is None
    assert p.gui_publish_rate is None and p.save_pose_rate is None
    assert params_from_mapping({"laser_max_range": 12}).laser_max_range == 12.0


def test_yaml_numbers_are_coerced():
    p = params_from_mapping({"min_particles": 500.0, "odom_alpha1": 1, "laser_max_beams": 60})
    assert p.min_particles == 500 and isinstance(p.min_particles, int)
    assert p.odom_alpha1 == 1.0 and isinstance(p.odom_alpha1, float)


@pytest.mark.parametrize(
    ("mapping", "match"),
    [
        ({"min_particles": -10}, r"amcl\.yaml: parameter 'min_particles' = -10 is out of range"),
        ({"max_particles": -1}, r"'max_particles' = -1 is out of range"),
        ({"min_particles": 600, "max_particles": 500}, r"min_particles \(600\) > max_particles"),
        (
            {"odom_model_type": "dif"},
            r"'odom_model_type' must be one of .* \(did you mean 'diff'\?\)",
        ),
        ({"laser_model_type": "ray"}, r"'laser_model_type' must be one of 'likelihood_field'"),
        ({"min_particles": 1.5}, r"'min_particles' must be int, got float 1.5"),
        ({"kld_err": "small"}, r"'kld_err' must be float, got str 'small'"),
        ({"tf_broadcast": "yes"}, r"'tf_broadcast' must be bool"),
        ({"laser_z_hit": 1.5}, r"'laser_z_hit' = 1.5 is out of range \[0, 1\]"),
        ({"resample_interval": 0}, r"'resample_interval' = 0 is out of range"),
    ],
)
def test_bad_values_name_the_parameter(mapping, match):
    with pytest.raises(ParameterError, match=match):
        params_from_mapping(mapping, source="amcl.yaml")


def test_direct_construction_validates_too():
    with pytest.raises(ParameterError, match=r"AmclParams: parameter 'min_particles'"):
        AmclParams(min_particles=-1)


def test_unknown_key_warns_with_suggestion(caplog):
    with caplog.at_level(logging.WARNING):
        p = params_from_mapping({"min_particle": 3}, source="/lizi1/amcl")
    assert p.min_particles == 100
    assert "/lizi1/amcl: unknown parameter 'min_particle' (did you mean 'min_particles'?)" in (
        caplog.text
    )


def test_direct_construction_checks_choices_and_types():
    with pytest.raises(ParameterError, match=r"unknown odom_model_type 'dif' \(did you mean"):
        AmclParams(odom_model_type="dif")
    with pytest.raises(ParameterError, match=r"'min_particles' must be an integer"):
        AmclParams(min_particles=2.5)
    assert AmclParams(laser_max_range=-1).laser_max_range is None
