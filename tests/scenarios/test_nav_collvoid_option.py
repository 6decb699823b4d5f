"""``local_planner:=collvoid`` on the shipped lizi launch files (``navigation_multi`` ->
``robots.launch`` -> ``one_robot.launch``): each lizi's move_base runs collvoid's local planner
with a robots_layer in its global costmap, and a me_publisher shares it on /position_share, so
the robots see each other (their lasers sweep above the other bodies)."""

from __future__ import annotations

import pytest

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.controllers.trajectory_planner import TrajectoryPlanner

ROBOTS = ("lizi1", "lizi2", "lizi3")


def test_the_plain_planner_stays_the_default():
    plan = load_plan(resolve_launch_file("navigation_multi"))
    assert not [n for n in plan.nodes if n.name == "me_publisher"]


@pytest.mark.scenario
def test_collvoid_option_shares_the_lizis_and_drives_them(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    plan = load_plan(resolve_launch_file("navigation_multi"), {"local_planner": "collvoid"})
    assert sorted(n.namespace.strip("/") for n in plan.nodes if n.name == "me_publisher") == list(
        ROBOTS
    )
    with LaunchSession(plan, seed=1) as s:
        s.run(duration=4.0)
        now = s.runtime.now()
        for r in ROBOTS:
            mb = s.nodes[f"/{r}/move_base_node"]
            assert isinstance(mb.controller, CollvoidLocalPlanner), (r, type(mb.controller))
            assert not isinstance(mb.controller, TrajectoryPlanner)
            mb.global_costmap.layered.layer("robots_layer")  # raises when the layer is missing
            heard = {n.robot_id for n in mb.controller.share.table.fresh(now)}
            assert set(ROBOTS) - {r} <= heard, (r, heard)
        engine = s.nodes["/gazebo"].engine
        assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
        moved = [r for r in s.monitor.results() if r.path_length > 0.3]
        assert len(moved) == len(ROBOTS), s.monitor.results()
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
