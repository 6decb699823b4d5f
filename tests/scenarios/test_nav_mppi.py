"""The lizis reach their goals with Nav2's MPPI controller as move_base's local planner.

Two runs, as the DWA ones they mirror: the office demo (the shipped navigation_multi.launch with
``local_planner:=mppi``, which loads ``params/lizi/mppi_params.yaml`` over the DWA parameters)
and the lesson's three lizis in Willow (the `willow_nav` package with the same MPPI block added
to its ``base_local_planner_params.yaml``, as a lesson user would paste it). Pass criteria come
from the simulator's ground truth and the `RunMonitor`'s contact count.
"""

from __future__ import annotations

import math

import pytest
from nav_harness import (
    CONFIG,
    GOALS,
    SIM_LIMIT,
    WILLOW,
    TruthLog,
    lesson_starts,
    willow_session,
)

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.errors import LaunchError
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.nav.controllers.mppi import MPPIController
from fleetsim.nav.map_io import load_map

LIZI_MPPI = resolve_launch_file("navigation_multi").parent / "params" / "lizi" / "mppi_params.yaml"
ROBOTS = ("lizi1", "lizi2", "lizi3")
MPPI_XY_TOLERANCE = 0.25  # m, xy_goal_tolerance of params/lizi/mppi_params.yaml


def no_mujoco_warnings(s: LaunchSession) -> None:
    engine = s.nodes["/gazebo"].engine
    assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}


def assert_mppi_drives(s: LaunchSession) -> None:
    for r in ROBOTS:
        controller = s.nodes[f"/{r}/move_base_node"].controller
        assert isinstance(controller, MPPIController), (r, type(controller))
        assert controller.params.vx_max == 0.5 and controller.params.wz_max == 1.0


def test_an_unknown_local_planner_names_the_missing_params_file():
    with pytest.raises(LaunchError, match=r"params/lizi/teb_params\.yaml"):
        load_plan(resolve_launch_file("navigation_multi"), {"local_planner": "teb"})


@pytest.mark.scenario
def test_office_demo_lizis_reach_their_goals_with_mppi(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    plan = load_plan(resolve_launch_file("navigation_multi"), {"local_planner": "mppi"})
    with LaunchSession(plan, seed=1) as s:
        assert_mppi_drives(s)
        s.run(duration=150.0, until_goals=True)
        results = {r.namespace.strip("/"): r for r in s.monitor.results()}
        assert set(results) == set(ROBOTS)
        for r in results.values():
            assert (r.goals_sent, r.goals_reached, r.collisions) == (1, 1, 0), r
            assert r.path_length > 10.0, r
            assert r.distance_to_goal <= MPPI_XY_TOLERANCE + 0.05, r
        assert s.monitor.success()
        no_mujoco_warnings(s)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


@pytest.mark.scenario
def test_lesson_lizis_in_willow_reach_their_goals_with_mppi(monkeypatch, tmp_path):
    config = tmp_path / "move_base_config"
    config.mkdir()
    for f in CONFIG.iterdir():
        text = f.read_text()
        if f.name == "base_local_planner_params.yaml":
            text += "\n" + LIZI_MPPI.read_text()
        (config / f.name).write_text(text)
    monkeypatch.chdir(tmp_path)
    session = willow_session(lesson_starts(load_map(WILLOW)), GOALS, config=config)
    try:
        assert_mppi_drives(session)
        log = TruthLog(session.runtime, list(GOALS))
        session.runtime.run(duration=SIM_LIMIT, until=session.monitor.all_goals_done)
        results = {r.namespace.strip("/"): r for r in session.monitor.results()}
        for robot, (gx, gy, _) in GOALS.items():
            r = results[robot]
            assert (r.goals_sent, r.goals_reached, r.collisions) == (1, 1, 0), (robot, r)
            assert math.dist(log.xy(robot), (gx, gy)) <= MPPI_XY_TOLERANCE + 0.05, robot
            assert r.path_length >= 15.0, (robot, r)
        assert session.monitor.success()
        no_mujoco_warnings(session)
    finally:
        session.close()
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
