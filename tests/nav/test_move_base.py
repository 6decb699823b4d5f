"""move_base closed loop on the room world: goals, aborts with reasons, preemption, cancel."""

import logging
import math

import numpy as np
import pytest
from nav_world import goal_msg, move_base_params, nav_world, room_map

from fleetsim.errors import ParameterError
from fleetsim.msgs import geometry_msgs, nav_msgs
from fleetsim.msgs.actionlib_msgs import GoalStatus
from fleetsim.nav.map_server import grid_msg_from_map
from fleetsim.tf.patience import GRACE

RADIUS = 0.2  # the test robot's footprint radius


def run_goal(w, goal, limit=60.0):
    h = w.client.send_goal(goal)
    w.rt.run(duration=limit, until=lambda: h.done)
    return h


def final_distance(w, x, y):
    return math.hypot(w.bot.pose[0] - x, w.bot.pose[1] - y)


def test_reaches_a_goal_through_the_door_and_stops():
    w = nav_world()
    h = run_goal(w, goal_msg(6.0, 4.5, 0.0))
    assert h.status == GoalStatus.SUCCEEDED and h.text == "Goal reached."
    assert final_distance(w, 6.0, 4.5) <= 0.15  # xy_goal_tolerance
    assert abs(math.remainder(w.bot.pose[2], 2 * math.pi)) <= 0.2 + 0.05
    assert w.bot.min_clearance > RADIUS  # never touched a wall
    t_last, last = w.watch.cmds[-1]
    assert (last.linear.x, last.angular.z) == (0.0, 0.0)  # stopped on success
    speeds = [m.linear.x for _, m in w.watch.cmds]
    assert max(speeds) <= 0.5 + 1e-9 and max(speeds) > 0.4  # max_vel_x
    assert w.watch.goals[0].header.frame_id == "map"
    assert w.watch.plans and w.watch.plans[0].header.frame_id == "map"
    assert w.watch.local and w.watch.local[-1].header.frame_id == "lizi1/odom"
    fb = w.watch.feedback[-1].feedback.base_position
    assert fb.header.frame_id == "map"
    assert math.hypot(fb.pose.position.x - 6.0, fb.pose.position.y - 4.5) < 0.3
    assert w.mb.state == "PLANNING" and not w.mb.server.is_active()


def test_simple_goal_topic_in_the_odom_frame_is_transformed_to_the_map():
    w = nav_world(start=(1.0, 1.0, math.pi / 2))
    pub = w.client.node.create_publisher(geometry_msgs.PoseStamped, "move_base_simple/goal")
    w.rt.run(duration=0.5)
    # odom is the start pose (1, 1, 90 deg): odom (1.0, -1.0) is map (2.0, 2.0)
    g = goal_msg(1.0, -1.0, -math.pi / 2, frame="lizi1/odom").target_pose
    pub.publish(g)
    w.rt.run(duration=40.0, until=lambda: not w.mb.server.is_active() and w.watch.goals)
    shown = w.watch.goals[0]
    assert shown.header.frame_id == "map"
    assert (shown.pose.position.x, shown.pose.position.y) == pytest.approx((2.0, 2.0))
    assert w.mb.server._finished[-1].status == GoalStatus.SUCCEEDED
    assert final_distance(w, 2.0, 2.0) <= 0.15


def test_a_newer_goal_preempts_and_cancel_stops_the_robot():
    w = nav_world()
    first = w.client.send_goal(goal_msg(6.0, 4.5))
    w.rt.run(duration=3.0)
    assert w.mb.state == "CONTROLLING" and not first.done
    second = w.client.send_goal(goal_msg(1.0, 4.0))
    w.rt.run(duration=2.0)
    assert first.status == GoalStatus.PREEMPTED
    assert second.status == GoalStatus.ACTIVE
    assert w.watch.goals[-1].pose.position.y == pytest.approx(4.0)
    second.cancel()
    w.rt.run(duration=0.3)
    assert second.status == GoalStatus.PREEMPTED
    assert w.watch.cmds[-1][1] == geometry_msgs.Twist()
    before = w.bot.pose.copy()
    w.rt.run(duration=1.0)
    np.testing.assert_allclose(w.bot.pose, before)  # no more commands: it stays put


def test_invalid_quaternion_is_aborted():
    w = nav_world()
    g = goal_msg(2.0, 1.0)
    g.target_pose.pose.orientation = geometry_msgs.Quaternion(x=1.0, w=0.0)  # upside down
    h = run_goal(w, g, limit=1.0)
    assert h.status == GoalStatus.ABORTED
    assert "z-axis of the quaternion must be close to vertical" in h.text
    g.target_pose.pose.orientation = geometry_msgs.Quaternion(w=0.0)
    assert "length is close to zero" in run_goal(w, g, limit=1.0).text


def test_goal_before_the_map_waits_then_is_reached(caplog):
    w = nav_world(with_map=False)
    h = w.client.send_goal(goal_msg(2.0, 1.0))
    w.rt.run(duration=2.0)
    assert h.status == GoalStatus.ACTIVE
    assert "waiting" not in caplog.text  # a map that comes up late is waited for quietly
    w.rt.run(duration=GRACE - 1.0)
    assert h.status == GoalStatus.ACTIVE
    said = [r.getMessage() for r in caplog.records]
    assert sum("s for the costmaps (map and tf)" in m for m in said) == 1
    assert sum("s for the map on /map" in m for m in said) == 1  # the global costmap
    assert any("waiting 5.0 s for the costmaps" in m for m in said)
    node = w.client.node
    pub = node.create_publisher(nav_msgs.OccupancyGrid, "/map", 1, latch=True)
    pub.publish(grid_msg_from_map(room_map(), "map"))
    w.rt.run(duration=20.0, until=lambda: h.done)
    assert h.status == GoalStatus.SUCCEEDED


def test_a_new_goal_waits_afresh_for_the_costmaps(caplog):
    """A goal cancelled while the map was missing leaves no wait behind: the next goal, sent
    after the map came, is not told it waited since the first (found in review)."""
    w = nav_world(move_base_params(shutdown_costmaps=True), with_map=False)
    first = w.client.send_goal(goal_msg(2.0, 1.0))
    w.rt.run(duration=2.0)
    first.cancel()
    pub = w.client.node.create_publisher(nav_msgs.OccupancyGrid, "/map", 1, latch=True)
    pub.publish(grid_msg_from_map(room_map(), "map"))
    w.rt.run(duration=20.0)
    h = w.client.send_goal(goal_msg(2.0, 1.0))
    w.rt.run(duration=20.0, until=lambda: h.done)
    assert h.status == GoalStatus.SUCCEEDED
    assert "for the costmaps" not in caplog.text


def test_a_goal_in_the_shared_map_for_a_robot_with_its_own_map_is_named(caplog):
    """gmapping in the robot's namespace makes its map lizi1/map; a goal sent in 'map'
    (send_goals' default) cannot be placed: said after tf's 5 s, not at the planner's
    patience, with the frame to send it in (found by a new user)."""
    w = nav_world()
    w.rt.run(duration=1.0)
    w.mb.global_frame = "lizi1/map"  # as a global costmap in a SLAM robot's own map
    goal = goal_msg(2.0, 1.0).target_pose
    with caplog.at_level(logging.WARNING):
        assert w.mb.to_global(goal) is None
        w.rt.run(duration=4.9)
        assert w.mb.to_global(goal) is None
        assert "Failed to transform the goal pose" not in caplog.text
        w.rt.run(duration=0.2)
        assert w.mb.to_global(goal) is None
    assert "Failed to transform the goal pose from map into the lizi1/map frame: " in caplog.text
    assert "this robot's global frame is lizi1/map: send the goal in that frame" in caplog.text


def test_speed_limit_and_shutdown_costmaps():
    params = move_base_params(planner={"max_vel_x": 0.25}, shutdown_costmaps=True)
    w = nav_world(params)
    w.rt.run(duration=0.5)
    assert w.mb.global_costmap.stopped  # no goal yet
    h = run_goal(w, goal_msg(3.0, 1.0))
    assert h.status == GoalStatus.SUCCEEDED
    speeds = [m.linear.x for _, m in w.watch.cmds]
    assert 0.2 < max(speeds) <= 0.25 + 1e-9
    assert w.mb.global_costmap.stopped and w.mb.local_costmap.stopped


def test_lesson_parameters_load_without_unknown_warnings(caplog):
    params = move_base_params(
        controller_frequency=10.0,
        max_planning_retries=-1,
        recovery_behaviors=[{"name": "spin", "type": "rotate_recovery/RotateRecovery"}],
        spin={"frequency": 10.0},
        planner_patiance=3.0,
    )
    w = nav_world(params)
    assert w.mb.params.max_planning_retries is None  # ROS's -1: no limit
    assert w.mb.params.controller_frequency == 10.0
    assert [r.name for r in w.mb.recoveries] == ["spin"]
    unknown = [r.getMessage() for r in caplog.records if "unknown parameter" in r.getMessage()]
    assert (
        len(unknown) == 1 and "'planner_patiance' (did you mean 'planner_patience'?)" in unknown[0]
    )


def test_unknown_global_planner_is_an_error():
    with pytest.raises(ParameterError, match=r"'base_global_planner' = 'global_planner/Glob"):
        nav_world(move_base_params(base_global_planner="global_planner/GlobalPlanner"))


def test_local_planner_parameters_in_move_base_own_namespace_are_said_to_be_misplaced(caplog):
    """A base_local_planner_params.yaml without its 'TrajectoryPlannerROS:' line puts
    max_vel_x and acc_lim_x into move_base's namespace: one warning names them and where they
    belong, instead of two plain "unknown parameter" lines; move_base's own keys are not in it."""
    params = move_base_params(max_vel_x=0.3, acc_lim_x=1.0, controller_frequency=10.0)
    with caplog.at_level("WARNING"):
        nav_world(params)
    said = [r.getMessage() for r in caplog.records if "TrajectoryPlannerROS's" in r.getMessage()]
    assert len(said) == 1, said
    assert "'acc_lim_x', 'max_vel_x' are TrajectoryPlannerROS's, read only under " in said[0]
    assert "/lizi1/move_base/TrajectoryPlannerROS/" in said[0]
    assert not [r for r in caplog.records if "unknown parameter" in r.getMessage()]
    caplog.clear()  # another planner's names differ: not guessed, a plain unknown parameter
    dwa = {**params, "base_local_planner": "dwa_local_planner/DWAPlannerROS"}
    with caplog.at_level("WARNING"):
        nav_world(dwa)
    assert not [r for r in caplog.records if "TrajectoryPlannerROS's" in r.getMessage()]
    assert any("unknown parameter 'max_vel_x'" in r.getMessage() for r in caplog.records)
