"""The collvoid planner's goal turn runs at max_vel_theta until it must slow to stop."""

from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.runtime import Node, Runtime

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
PARAMS = {
    "max_vel_x": 0.5,
    "max_vel_theta": 1.5,
    "min_vel_theta": -1.5,
    "xy_goal_tolerance": 0.2,
    "yaw_goal_tolerance": 0.3,
    "controller_frequency": 10.0,
}


def test_the_goal_turn_runs_at_max_vel_theta_until_it_must_slow_to_stop():
    """base_local_planner's turn rate |yaw error| (1/s) crept through the last radian of a
    lizi's turn (its skid steer turns at ~0.57 of the command: 1.8 s for 0.8 rad in
    willow_swap); the turn now runs at max_vel_theta, slowed only as acc_lim_theta requires."""
    node = Node(Runtime(), "move_base", "/robot")
    costmap_ros = SimpleNamespace(
        costmap=Costmap2D(100, 100, 0.05, -2.5, -2.5), footprint=LIZI, global_frame="map"
    )
    pl = CollvoidLocalPlanner.from_namespace(node, costmap_ros, PARAMS, "robot")
    pl.set_plan(np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]))
    yaw, w, rates = -1.2, 0.0, []
    for _ in range(40):
        cmd = pl.compute_velocity_commands((0.0, 0.0, yaw), (0.0, 0.0, w))
        if pl.is_goal_reached():
            break
        assert cmd.vx == 0.0
        w = cmd.vtheta
        rates.append(w)
        yaw += w * 0.1
    assert pl.is_goal_reached() and abs(yaw) <= 0.3
    assert max(rates) == pytest.approx(1.5)  # |yaw error| would never exceed 1.2
    assert len(rates) <= 8  # 0.9 rad at up to 1.5 rad/s (ramp 0.32 rad/s per cycle)
