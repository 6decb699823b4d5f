"""Tests for fleetsim.slam.params: gmapping's code defaults, ROS's -1, the no-effect four."""

import logging

import pytest

from fleetsim.errors import ParameterError
from fleetsim.slam.params import GmappingParams, gmapping_params


def test_code_defaults_not_the_wikis():
    p = GmappingParams()
    assert p.maxUrange is None and p.maxRange is None  # the laser's range_max - 0.01
    assert p.temporalUpdate is None  # off
    assert (p.srr, p.srt, p.str, p.stt) == (0.1, 0.2, 0.1, 0.2)
    assert (p.particles, p.angularUpdate, p.linearUpdate, p.iterations) == (30, 0.5, 1.0, 5)
    assert (p.xmin, p.xmax, p.delta, p.occ_thresh) == (-100.0, 100.0, 0.05, 0.25)
    assert p.transform_publish_period == 0.05 and p.tf_delay is None


def test_minus_one_means_unset_and_the_four_sampling_parameters_warn(caplog):
    with caplog.at_level(logging.INFO):
        p = gmapping_params(
            {"temporalUpdate": -1.0, "maxUrange": -1, "llsamplerange": 0.01, "lasamplestep": 0.1}
        )
    assert p.temporalUpdate is None and p.maxUrange is None
    warnings = [r.getMessage() for r in caplog.records if r.levelno == logging.WARNING]
    notes = [r.getMessage() for r in caplog.records if r.levelno == logging.INFO]
    assert len(warnings) == 1 and "parameter 'lasamplestep' has no effect" in warnings[0]
    assert len(notes) == 1 and "parameter 'llsamplerange' has no effect" in notes[0]


def test_bad_values_name_the_parameter():
    with pytest.raises(ParameterError, match="parameter 'particles' = 0 is out of range"):
        gmapping_params({"particles": 0}, "/robot/slam_gmapping")
    with pytest.raises(ParameterError, match="parameter 'sigma' must be float"):
        gmapping_params({"sigma": "wide"})
    with pytest.raises(ParameterError, match="xmin < xmax"):
        gmapping_params({"xmin": 5.0, "xmax": 1.0})
    with pytest.raises(ParameterError, match=r"^/lizi1/slam_gmapping: the map extent xmin"):
        gmapping_params({"xmin": 5.0, "xmax": 1.0}, "/lizi1/slam_gmapping")
    with pytest.raises(ParameterError, match="parameter 'climb_skip' = -1 is out of range"):
        gmapping_params({"climb_skip": -1})


def test_a_value_from_a_yaml_file_is_named_with_its_file_and_line(tmp_path, caplog):
    """A user's gmapping.yaml loaded by <rosparam>: the error and the warning say where the
    value was set, as amcl's and explore's do (the origins were dropped by a plain dict)."""
    from fleetsim.runtime import ParamTree

    yaml_file = tmp_path / "gmapping.yaml"
    yaml_file.write_text("particles: 30\ndelta: -0.05\n")
    tree = ParamTree()
    tree.load_file(yaml_file, "/slam_gmapping")
    with pytest.raises(ParameterError, match=rf"set at {yaml_file}:2"):
        gmapping_params(tree.get("/slam_gmapping"), "/slam_gmapping")
    yaml_file.write_text("particles: 30\nparticels: 40\n")
    tree = ParamTree()
    tree.load_file(yaml_file, "/slam_gmapping")
    with caplog.at_level(logging.WARNING):
        gmapping_params(tree.get("/slam_gmapping"), "/slam_gmapping")
    assert f"unknown parameter 'particels' (did you mean 'particles'?) (set at {yaml_file}:2)" in (
        caplog.text
    )


def test_a_parameter_in_the_wrong_case_is_offered_its_own_name(caplog):
    """maxURange: difflib alone offered maxRange (another parameter) before maxUrange."""
    with caplog.at_level(logging.WARNING):
        gmapping_params({"maxURange": 8.0})
    assert "unknown parameter 'maxURange' (did you mean 'maxUrange'?)" in caplog.text
