"""Recovery behaviours: clear costmap and rotate."""

import numpy as np
import pytest

from fleetsim.nav.costmap import NO_INFORMATION, LayeredCostmap
from fleetsim.nav.costmap.footprint import footprint_from_radius
from fleetsim.nav.recovery import (
    ClearCostmapRecovery,
    ClearCostmapRecoveryParams,
    RotateRecovery,
    aggressive_reset_params,
)


def test_conservative_reset_keeps_the_square_around_the_robot():
    lc = LayeredCostmap.from_params(
        {
            "static_map": False,
            "width": 10.0,
            "height": 10.0,
            "observation_sources": "s",
            "s": {"marking": True},
            "robot_radius": 0.2,
        },
        "c",
    )
    lc.add_observation("s", [5.0, 5.0, 0.0], [[5.8, 5.0, 0.1], [7.2, 5.0, 0.1]])
    lc.update_map(5.0, 5.0, 0.0)
    ClearCostmapRecovery(ClearCostmapRecoveryParams(reset_distance=3.0)).run([lc], 5.0, 5.0)
    g = lc.layer("obstacle_layer").grid
    near, far = g.world_to_map(5.8, 5.0), g.world_to_map(7.2, 5.0)
    assert g.costs[near[1], near[0]] == 254
    assert g.costs[far[1], far[0]] == NO_INFORMATION
    assert aggressive_reset_params(0.5).reset_distance == pytest.approx(2.0)


def test_rotate_recovery_turns_once_then_stops():
    from fleetsim.nav.costmap import Costmap2D

    m = Costmap2D(40, 40, 0.05)
    rr = RotateRecovery(m, footprint_from_radius(0.2))
    yaw, n = 0.0, 0
    while (cmd := rr.command(1.0, 1.0, yaw)) is not None:
        assert 0.4 <= cmd.vtheta <= 1.0
        yaw += cmd.vtheta * 0.05
        n += 1
        assert n < 1000
    assert yaw == pytest.approx(2 * np.pi, abs=0.15)
    m.costs[20, 26] = 254
    blocked = RotateRecovery(m, np.array([[0.35, 0.0], [-0.1, 0.1], [-0.1, -0.1]]))
    assert blocked.command(1.025, 1.025, np.pi / 2) is None
    assert "cannot rotate in place" in blocked.aborted


def test_moveback_recovery_backs_up_until_its_length_an_obstacle_or_its_timeout():
    from fleetsim.nav.costmap import Costmap2D
    from fleetsim.nav.recovery import MoveBackRecovery, MoveBackRecoveryParams

    m = Costmap2D(80, 40, 0.05)  # 4 x 2 m
    fp = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])

    def run(rec, x, t_step=0.05):
        t, n = 0.0, 0
        while (cmd := rec.command(x, 1.0, 0.0, t)) is not None:
            assert (cmd.vx, cmd.vy, cmd.vtheta) == (-0.3, 0.0, 0.0)
            x += cmd.vx * t_step
            t += t_step
            n += 1
            assert n < 1000
        return x, t

    back = MoveBackRecovery(m, fp)
    x, _ = run(back, 3.0)
    assert x == pytest.approx(2.0, abs=0.02) and back.outcome == "moved backwards 1 m"
    rec = MoveBackRecovery(m, fp)
    m.costs[:, 34] = 254  # a wall at x = 1.70-1.75 m behind a robot at 3 m facing +x
    x, _ = run(rec, 3.0)
    # stops once the footprint 0.1 m further back would reach the wall: its back edge at x-0.29
    assert 1.75 + 0.29 - 0.05 <= x <= 1.75 + 0.29 + 0.05, x
    assert "an obstacle behind the robot" in rec.outcome
    m.costs[:, 34] = 0
    slow = MoveBackRecovery(m, fp, MoveBackRecoveryParams(step_back_timeout=1.0))
    x, t = run(slow, 3.0)
    assert t == pytest.approx(1.05, abs=0.06) and x == pytest.approx(2.7, abs=0.03)
    assert "time out" in slow.outcome
