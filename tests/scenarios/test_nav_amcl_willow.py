"""The amcl issue's fourth "must show": the three-lizi Willow scenario with amcl.

The same run as `test_nav_willow` (willow_nav's navigation_multi.launch, the lesson's starts
moved to free cells, the same goals), with ``localization:=amcl``: one_robot.launch includes
amcl_node.xml instead of fake_localization, and robots.launch sets each robot's initial pose as
``<ns>/amcl/initial_pose_x``, ``_y``, ``_a``, as the lesson does. Pass: every robot's goal
SUCCEEDED, its ground-truth position within ``xy_goal_tolerance`` plus amcl's error budget of
the goal, and no contact with walls or other robots.
"""

import math

import pytest
from nav_harness import (
    GOALS,
    SIM_LIMIT,
    WILLOW,
    XY_GOAL_TOLERANCE,
    TruthLog,
    lesson_starts,
    willow_session,
)

from fleetsim.nav.map_io import load_map

AMCL_ERROR_BUDGET = 0.25  # m: the goal is judged on amcl's estimate, the test on ground truth


def test_initial_poses_reach_each_robots_amcl():
    starts = lesson_starts(load_map(WILLOW))
    session = willow_session(starts, localization="amcl")
    try:
        for i, (x, y, yaw) in enumerate(starts, start=1):
            amcl = session.nodes[f"/lizi{i}/amcl"]
            p = amcl.params
            assert (p.initial_pose_x, p.initial_pose_y, p.initial_pose_a) == (x, y, yaw)
        session.runtime.run(duration=1.0)
        for i, (x, y, _) in enumerate(starts, start=1):
            est = session.nodes[f"/lizi{i}/amcl"].filter.estimate.pose
            assert math.dist(est[:2], (x, y)) < 0.3, (i, est)
    finally:
        session.close()


@pytest.mark.scenario
def test_three_lizis_with_amcl_reach_their_goals():
    starts = lesson_starts(load_map(WILLOW))
    session = willow_session(starts, GOALS, localization="amcl")
    try:
        log = TruthLog(session.runtime, list(GOALS))
        session.runtime.run(duration=SIM_LIMIT, until=session.monitor.all_goals_done)
        results = {r.namespace.strip("/"): r for r in session.monitor.results()}
        for robot, (gx, gy, _) in GOALS.items():
            r = results[robot]
            assert (r.goals_sent, r.goals_reached) == (1, 1), (robot, r)
            gap = math.dist(log.xy(robot), (gx, gy))
            assert gap <= XY_GOAL_TOLERANCE + AMCL_ERROR_BUDGET, (robot, gap)
            assert r.collisions == 0, (robot, r)
        assert session.monitor.success()
    finally:
        session.close()
