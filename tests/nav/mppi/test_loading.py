"""MPPIController parameters: Nav2's defaults, and errors that name the parameter."""

import logging

import pytest

from fleetsim.errors import ParameterError
from fleetsim.nav.controllers.mppi import MPPIParams, load_mppi
from fleetsim.nav.controllers.mppi.critics import CostCritic, GoalCritic

CRITICS = ["ConstraintCritic", "CostCritic", "GoalCritic"]


def test_nav2_defaults():
    p = MPPIParams()
    assert (p.batch_size, p.time_steps, p.model_dt, p.iteration_count) == (1000, 56, 0.05, 1)
    assert (p.vx_std, p.vy_std, p.wz_std) == (0.2, 0.2, 0.4)
    assert (p.vx_max, p.vx_min, p.vy_max, p.wz_max) == (0.5, -0.35, 0.5, 1.9)
    assert (p.temperature, p.gamma, p.motion_model) == (0.3, 0.015, "DiffDrive")
    assert (p.xy_goal_tolerance, p.yaw_goal_tolerance) == (0.25, 0.25)


def test_critics_load_in_order_with_their_blocks_and_prefix():
    p, ack, critics = load_mppi(
        {
            "critics": ["mppi::critics::CostCritic", "GoalCritic", "ConstraintCritic"],
            "CostCritic": {"cost_weight": 2.0, "consider_footprint": True},
            "ConstraintCritic": {"enabled": False},
            "AckermannConstraints": {"min_turning_r": 0.4},
        }
    )
    assert [type(c) for c in critics] == [CostCritic, GoalCritic]
    assert critics[0].params.cost_weight == 2.0 and critics[0].params.consider_footprint
    assert ack.min_turning_r == 0.4


@pytest.mark.parametrize(
    ("ns", "match"),
    [
        ({"critics": ["CostCritic", "GoalCritc"]}, r"'critics' names 'GoalCritc'.*'GoalCritic'"),
        ({"critics": CRITICS, "temperature": -0.1}, r"'temperature' = -0.1 is out of range"),
        ({"critics": CRITICS, "batch_size": 0}, r"'batch_size' = 0 is out of range"),
        ({"critics": CRITICS, "motion_model": "Diff"}, r"'motion_model' must be one of"),
        ({"critics": []}, r"'critics' is empty"),
        ({}, r"'critics' is empty"),
        ({"critics": CRITICS, "vx_min": 1.0}, r"'vx_min' = 1.0 exceeds vx_max"),
        ({"critics": CRITICS, "CostCritic": {"cost_power": 0}}, r"CostCritic: .*'cost_power' = 0"),
        ({"critics": CRITICS, "GoalCritic": 3}, r"GoalCritic: the critic's parameters must be"),
        ({"critics": CRITICS, "enforce_path_inversion": True}, r"'enforce_path_inversion'"),
    ],
)  # fmt: skip
def test_bad_input_names_the_parameter(ns, match):
    with pytest.raises(ParameterError, match=match) as err:
        load_mppi(ns, "/lizi1/move_base/MPPIController")
    assert str(err.value).startswith("/lizi1/move_base/MPPIController")


def test_unknown_keys_and_unlisted_critic_blocks_are_warned_about(caplog):
    with caplog.at_level(logging.WARNING):
        load_mppi({"critics": CRITICS, "batch_sise": 10, "TwirlingCritic": {"cost_weight": 1.0}})
    assert "unknown parameter 'batch_sise' (did you mean 'batch_size'?)" in caplog.text
    assert "'TwirlingCritic' has parameters but is not in 'critics'" in caplog.text
