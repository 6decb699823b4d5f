"""Every shipped scenario runs headless and meets its pass criterion."""

import math

import pytest

from fleetsim.cli.launch import resolve_launch_file, scenarios
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import sensor_msgs

pytestmark = pytest.mark.scenario


def session(name: str, **args: str) -> LaunchSession:
    return LaunchSession(load_plan(resolve_launch_file(name), args), seed=1)


def distance_to(s: LaunchSession, model: str, goal: tuple[float, float]) -> float:
    pos, _ = s.monitor.sim.engine.model_pose(model)
    return math.hypot(float(pos[0]) - goal[0], float(pos[1]) - goal[1])


def test_the_shipped_scenarios_are_listed():
    assert {"navigation_multi", "pioneer_multi", "hunter_run", "barn"} <= set(scenarios())


@pytest.mark.parametrize("localization", ["fake", "amcl"])
def test_navigation_multi_all_robots_reach_their_goals(localization):
    with session("navigation_multi", localization=localization) as s:
        s.run(duration=150.0, until_goals=True)
        results = {r.namespace: r for r in s.monitor.results()}
        assert set(results) == {"/lizi1", "/lizi2", "/lizi3"}
        for r in results.values():
            assert r.goals_sent == 1, r
            assert r.goals_reached == 1, r
            assert r.collisions == 0, r
            assert r.path_length > 10.0, r
        assert s.monitor.success()
        frames = set(s.runtime.tf_buffer.all_frames())
        assert {"map", "lizi1/odom", "lizi1/base_link", "lizi3/laser_link"} <= frames


@pytest.mark.parametrize("localization", ["fake", "amcl"])
def test_pioneer_multi_all_robots_reach_their_goals(localization):
    goals = {"pioneer1": (5.0, 16.0), "pioneer2": (18.0, 17.5), "pioneer3": (25.0, 16.0)}
    with session("pioneer_multi", localization=localization) as s:
        s.run(duration=90.0, until_goals=True)
        assert s.monitor.success(), s.monitor.results()
        for model, goal in goals.items():
            assert distance_to(s, model, goal) < 0.5, model


def test_hunter_run_gazebo_publishes_its_sensors_and_frames():
    with session("hunter_run", sim_type="gazebo", launch_nav_stack="false") as s:
        scans = []
        s.runtime.graph.subscribe("/scan", sensor_msgs.LaserScan, scans.append)
        buf = s.runtime.tf_buffer
        s.runtime.run(duration=2.0)
        assert scans and scans[-1].header.frame_id == "laser"
        frames = {"odom", "base_link", "laser", "camera_front_low", "camera_left", "arm_base_link"}
        assert frames <= set(buf.all_frames())
        assert buf.can_transform("odom", "laser", 0.0)


def test_hunter_run_rviz_is_the_model_without_a_simulator():
    with session("hunter_run", sim_type="rviz", launch_nav_stack="false") as s:
        buf = s.runtime.tf_buffer
        s.runtime.run(duration=1.0)
        assert "/gazebo" not in s.nodes and s.skipped == ["/rviz"]
        assert buf.can_transform("base_link", "cluedo_link", 0.0)


def test_hunter_run_nav_stack_drives_to_a_goal():
    from fleetsim.nav.navigator import Navigator, TaskResult

    with session("hunter_run", sim_type="gazebo") as s:
        nav = Navigator(s.runtime, "/")
        s.runtime.run(duration=1.0)
        nav.go_to_pose(7.0, 10.0, 0.0)
        s.runtime.run(duration=40.0, until=nav.is_task_complete)
        assert nav.get_result() == TaskResult.SUCCEEDED, nav.get_status_text()
