"""Issue 14's repro, ``../shared/repro/willow10_amcl.launch``, as typed: ten lizis with amcl in
Willow, seeded goals. It once blew up at 5.3 s (NaN in QACC, MuJoCo's silent reset, laser
origins hundreds of metres off the map). Now every lizi reaches its goal, with no warning from
MuJoCo or from any node. The lizis' lasers sweep above each other's bodies, so with the plain
TrajectoryPlannerROS the contacts between robots the monitor counts are real meetings on their
routes, not a reset's (``local_planner:=collvoid`` avoids them: see the README)."""

from __future__ import annotations

from pathlib import Path

import pytest

from fleetsim.launch.runner import LaunchSession, load_plan

pytestmark = [pytest.mark.scenario, pytest.mark.usefixtures("quiet_run")]

REPRO = Path(__file__).resolve().parents[2].parent / "shared" / "repro" / "willow10_amcl.launch"


def test_willow10_amcl_repro_reaches_every_goal_without_a_warning():
    with LaunchSession(load_plan(REPRO, seed=0), seed=0) as s:
        s.run(duration=240.0, until_goals=True)
        engine = s.nodes["/gazebo"].engine
        assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
        results = s.monitor.results()
        assert len(results) == 10
        for r in results:
            # confirmed by ground truth: the robot stands at its goal, not off the map as the
            # reset left them
            assert (r.goals_sent, r.goals_reached, r.goals_unconfirmed) == (1, 1, 0), r
            assert r.distance_to_goal is not None and r.distance_to_goal <= r.goal_tolerance, r
            assert r.localization_error is not None and r.localization_error < 0.2, r
