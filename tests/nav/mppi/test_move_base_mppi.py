"""move_base with base_local_planner nav2_mppi_controller::MPPIController in the room world."""

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/nav: the room world

from nav_world import fill, goal_msg, move_base_params, nav_world, room_grid

from fleetsim.msgs.actionlib_msgs import GoalStatus

MPPI = {
    "batch_size": 1000,
    "critics": [
        "ConstraintCritic", "CostCritic", "GoalCritic", "GoalAngleCritic", "PathAlignCritic",
        "PathFollowCritic", "PathAngleCritic", "PreferForwardCritic",
    ],
    "CostCritic": {"consider_footprint": True},
}  # fmt: skip


def mppi_world(**kw):
    params = move_base_params(
        base_local_planner="nav2_mppi_controller::MPPIController", MPPIController=MPPI
    )
    del params["TrajectoryPlannerROS"]
    world = fill(room_grid(), 2.0, 0.1, 2.4, 1.6)  # a box across the start row, seen by laser
    return nav_world(params, start=(1.0, 1.0, 0.0), world=world, **kw)


@pytest.mark.scenario
def test_reaches_a_goal_around_a_box_without_touching_it(caplog):
    w = mppi_world()
    assert type(w.mb.controller).__name__ == "MPPIController"
    h = w.client.send_goal(goal_msg(3.2, 1.0, 0.0))
    w.rt.run(duration=40.0, until=lambda: h.done)
    assert h.status == GoalStatus.SUCCEEDED and h.text == "Goal reached."
    assert math.hypot(w.bot.pose[0] - 3.2, w.bot.pose[1] - 1.0) <= 0.25
    assert abs(math.remainder(w.bot.pose[2], 2 * math.pi)) <= 0.25 + 0.05
    assert w.bot.min_clearance > w.bot.radius  # never touched the box or a wall
    assert max(c[1][0] for c in w.bot.commands) <= 0.5 + 1e-9  # vx_max
    assert "unknown parameter" not in caplog.text


def test_noise_comes_from_the_runtime_seed():
    w = mppi_world()
    fresh = w.rt.rng("/lizi1/move_base/MPPIController")  # the plugin's own stream
    assert (w.mb.controller.noise[:, :, 0] == fresh.normal(0.0, 0.2, (1000, 56))).all()
    runs = []
    for _ in range(2):
        w = mppi_world()
        w.client.send_goal(goal_msg(3.2, 1.0, 0.0))
        w.rt.run(duration=3.0)
        runs.append([(t, tuple(c)) for t, c in w.bot.commands])
    assert len(runs[0]) > 20 and runs[0] == runs[1]
