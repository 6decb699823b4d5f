"""move_base's plugin loading: planners by name, DWA names, recovery behaviour lists."""

import logging

import numpy as np
import pytest

from fleetsim.errors import ParameterError
from fleetsim.nav.costmap import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_from_radius
from fleetsim.nav.move_base import MoveBaseParams
from fleetsim.nav.move_base_plugins import (
    dwa_namespace,
    local_planner,
    local_planner_namespace,
    recovery_behaviors,
)


class LocalCostmap:
    """What the loaders read from a Costmap2DROS: its master grid and footprint."""

    def __init__(self):
        self.costmap = Costmap2D(60, 60, 0.05, -1.5, -1.5)
        self.footprint = footprint_from_radius(0.21)
        self.global_frame = "odom"


def test_trajectory_planner_gets_move_base_controller_frequency():
    name, planner = local_planner(
        "base_local_planner/TrajectoryPlannerROS",
        {"TrajectoryPlannerROS": {"max_vel_x": 0.3}},
        10.0,
        LocalCostmap(),
        "/move_base",
    )
    assert name == "TrajectoryPlannerROS"
    assert planner.params.max_vel_x == 0.3 and planner.sim_period == pytest.approx(0.1)
    _, ns = local_planner_namespace(
        "base_local_planner/TrajectoryPlannerROS",
        {"TrajectoryPlannerROS": {"controller_frequency": 5.0}},
        10.0,
        "/move_base",
    )
    assert ns["controller_frequency"] == 5.0  # its own value wins


def test_dwa_planner_names_map_onto_the_dwa_mode(caplog):
    ns = {"max_rot_vel": 2.0, "path_distance_bias": 10.0, "vth_samples": 30,
          "max_trans_vel": 0.5, "acc_lim_x": 1.0}  # fmt: skip
    with caplog.at_level(logging.WARNING):
        name, planner = local_planner(
            "dwa_local_planner/DWAPlannerROS", {"DWAPlannerROS": ns}, 20.0, LocalCostmap(), "/mb"
        )
    p = planner.params
    assert name == "DWAPlannerROS"
    assert (p.dwa, p.meter_scoring, p.max_vel_theta, p.pdist_scale, p.vtheta_samples) == (
        True, True, 2.0, 10.0, 30)  # fmt: skip
    assert p.acc_lim_x == 1.0 and p.gdist_scale == 24.0  # DWAPlannerROS's default
    assert "'max_trans_vel' has no counterpart" in caplog.text
    assert dwa_namespace({}, "x")["min_vel_x"] == 0.0
    assert p.min_vel_theta == -2.0  # a magnitude in DWA: as far right as left


def test_dwa_planner_noetic_names_keep_rotation_symmetric(caplog):
    """melodic/noetic DWAPlannerROS names: min_vel_theta is the least rotational speed (a
    magnitude), not TrajectoryPlannerROS's signed lower bound; max_vel_trans has no
    counterpart (said so, not "did you mean 'max_vel_theta'")."""
    ns = {"max_vel_theta": 1.5, "min_vel_theta": 0.4, "max_vel_trans": 0.5, "min_vel_x": 0.0}
    with caplog.at_level(logging.WARNING):
        _, planner = local_planner(
            "dwa_local_planner/DWAPlannerROS", {"DWAPlannerROS": ns}, 20.0, LocalCostmap(), "/mb"
        )
    p = planner.params
    assert (p.max_vel_theta, p.min_vel_theta, p.min_in_place_vel_theta) == (1.5, -1.5, 0.4)
    assert "'max_vel_trans' has no counterpart" in caplog.text
    assert "did you mean" not in caplog.text


@pytest.mark.parametrize(
    ("kind", "value", "match"),
    [
        ("base_local_planner", "base_local_planner/TrajectoryPlanerROS",
         r"'base_local_planner' = 'base_local_planner/TrajectoryPlanerROS' is not available "
         r"\(did you mean 'base_local_planner/TrajectoryPlannerROS'\?\)"),
        ("base_local_planner", "teb_local_planner/TebLocalPlannerROS", r"known: base_local"),
    ],
)  # fmt: skip
def test_unknown_local_planner_is_an_error(kind, value, match):
    with pytest.raises(ParameterError, match=match):
        local_planner_namespace(value, {}, 20.0, "/move_base")


def names(recs):
    return [(r.name, "clear" if r.clear else "back" if r.moveback else "rotate") for r in recs]


def test_default_recoveries_follow_move_base():
    p = MoveBaseParams(conservative_reset_dist=2.0)
    recs = recovery_behaviors(p, {}, {"max_rotational_vel": 0.7}, 0.3, LocalCostmap(), "/mb")
    assert names(recs) == [
        ("conservative_reset", "clear"),
        ("rotate_recovery", "rotate"),
        ("aggressive_reset", "clear"),
        ("rotate_recovery", "rotate"),
    ]
    assert recs[0].clear.params.reset_distance == 2.0
    assert recs[2].clear.params.reset_distance == pytest.approx(1.2)  # 4 x circumscribed
    rp = recs[1].rotate.params
    assert rp.max_rotational_vel == 0.7 and rp.yaw_goal_tolerance == 0.10
    p = MoveBaseParams(clearing_rotation_allowed=False)
    assert len(recovery_behaviors(p, {}, {}, 0.3, LocalCostmap(), "/mb")) == 2


def test_a_recovery_list_reads_each_namespace():
    p = MoveBaseParams(
        recovery_behaviors=[
            {"name": "spin", "type": "rotate_recovery/RotateRecovery"},
            {"name": "wipe", "type": "clear_costmap_recovery/ClearCostmapRecovery"},
            {"name": "back", "type": "moveback_recovery/MoveBackRecovery"},
        ]
    )
    ns = {"spin": {"sim_granularity": 0.05}, "wipe": {"reset_distance": 0.5,
          "layer_names": ["obstacles"]}, "back": {"step_back_length": 0.3}}  # fmt: skip
    recs = recovery_behaviors(p, ns, {"max_vel_theta": 0.9}, 0.3, LocalCostmap(), "/mb")
    assert names(recs) == [("spin", "rotate"), ("wipe", "clear"), ("back", "back")]
    assert recs[2].moveback.params.step_back_length == 0.3
    assert recs[2].moveback.params.linear_vel_back == -0.3
    assert recs[0].rotate.params.sim_granularity == 0.05
    assert recs[0].rotate.params.max_rotational_vel == 0.9
    assert recs[1].clear.params.layer_names == ["obstacles"]
    assert np.isclose(recs[1].clear.params.reset_distance, 0.5)


@pytest.mark.parametrize(
    ("entry", "match"),
    [
        ({"name": "slow", "type": "move_slow_and_clear/MoveSlowAndClear"},
         r"recovery_behaviors\[0\] 'slow' has type 'move_slow_and_clear/MoveSlowAndClear', "
         r"which is not available"),
        ({"name": "x"}, r"recovery_behaviors\[0\] must be a mapping with 'name' and 'type'"),
        ({"name": "x", "type": "rotate_recovery/RotateRecover"},
         r"did you mean 'rotate_recovery/RotateRecovery'"),
    ],
)  # fmt: skip
def test_bad_recovery_entries(entry, match):
    p = MoveBaseParams(recovery_behaviors=[entry])
    with pytest.raises(ParameterError, match=match):
        recovery_behaviors(p, {}, {}, 0.3, LocalCostmap(), "/mb")


def test_moveback_forwards_is_an_error_naming_the_parameter():
    p = MoveBaseParams(
        recovery_behaviors=[{"name": "back", "type": "moveback_recovery/MoveBackRecovery"}]
    )
    with pytest.raises(ParameterError, match=r"/mb/back.*linear_vel_back"):
        recovery_behaviors(p, {"back": {"linear_vel_back": 0.3}}, {}, 0.3, LocalCostmap(), "/mb")


def lizi_global_costmap(inflation_radius):
    from types import SimpleNamespace

    from fleetsim.nav.costmap import LayeredCostmap

    fp = [[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]]
    ns = {"static_map": False, "width": 4.0, "height": 4.0, "footprint": fp,
          "inflation_radius": inflation_radius, "cost_scaling_factor": 5.0}  # fmt: skip
    lc = LayeredCostmap.from_params(ns, "global_costmap")
    return SimpleNamespace(layered=lc, costmap=lc.costmap, global_frame="map")


def test_circumscribed_clearance_takes_the_global_costmaps_circumscribed_cost(caplog):
    from fleetsim.nav.move_base_plugins import global_planner

    ns = {"NavfnROS": {"circumscribed_clearance": True}}
    _, planner = global_planner("navfn/NavfnROS", ns, lizi_global_costmap(0.45), "/mb")
    cost, radius = planner.circumscribed
    assert radius == pytest.approx(np.hypot(0.20, 0.17))  # footprint_padding 0.01 m
    assert cost == int(252 * np.exp(-5.0 * (radius - 0.17)))  # costmap_2d's computeCost
    with caplog.at_level(logging.WARNING):
        _, planner = global_planner("navfn/NavfnROS", ns, lizi_global_costmap(0.2), "/mb")
    assert planner.circumscribed[0] == 0
    assert "circumscribed_clearance has no effect" in caplog.text
