"""move_base closed loop on the room world: goals, aborts with reasons, preemption, cancel."""

import math

import numpy as np
import pytest
from nav_world import fill, goal_msg, move_base_params, nav_world, room_grid, room_map

from fleetsim.msgs import geometry_msgs, nav_msgs
from fleetsim.msgs.actionlib_msgs import GoalStatus
from fleetsim.nav.map_server import grid_msg_from_map

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


def test_goal_inside_a_wall_aborts_after_recoveries_with_the_reason():
    w = nav_world(move_base_params(planner_patience=1.0))
    h = run_goal(w, goal_msg(4.0, 1.0))
    assert h.status == GoalStatus.ABORTED
    assert h.text.startswith(
        "Failed to find a valid plan. Even after executing recovery behaviors."
    )
    assert "navfn: the goal (4.000, 1.000) is in an obstacle" in h.text
    assert w.rt.now() < 40.0  # bounded: 5 x patience + two turns
    turns = [m.angular.z for _, m in w.watch.cmds if m.angular.z > 0]
    assert len(turns) > 20  # rotate_recovery turned the robot in place
    assert w.watch.cmds[-1][1].angular.z == 0.0


def test_goal_outside_the_map_aborts_without_recoveries():
    params = move_base_params(planner_patience=0.5, recovery_behavior_enabled=False)
    w = nav_world(params)
    w.rt.run(duration=0.5)
    h = run_goal(w, goal_msg(20.0, 20.0))
    assert h.status == GoalStatus.ABORTED
    assert "navfn: the goal (20.000, 20.000) is off the global costmap" in h.text
    assert w.rt.now() < 2.0


def test_unreachable_goal_in_a_closed_box_aborts():
    params = move_base_params(planner_patience=0.5, recovery_behavior_enabled=False)
    h = run_goal(nav_world(params), goal_msg(6.7, 1.1))
    assert h.status == GoalStatus.ABORTED
    assert "not connected to the robot through free space" in h.text


def test_max_planning_retries_ends_planning_before_the_patience():
    params = move_base_params(
        planner_patience=30.0, max_planning_retries=0, recovery_behavior_enabled=False
    )
    w = nav_world(params)
    w.rt.run(duration=0.5)
    h = run_goal(w, goal_msg(20.0, 20.0))
    assert h.status == GoalStatus.ABORTED and w.rt.now() < 1.0


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
    assert "waiting for the costmaps" in caplog.text
    node = w.client.node
    pub = node.create_publisher(nav_msgs.OccupancyGrid, "/map", 1, latch=True)
    pub.publish(grid_msg_from_map(room_map(), "map"))
    w.rt.run(duration=20.0, until=lambda: h.done)
    assert h.status == GoalStatus.SUCCEEDED


def test_oscillation_timeout_aborts():
    params = move_base_params(
        oscillation_timeout=0.5, oscillation_distance=50.0, recovery_behavior_enabled=False
    )
    h = run_goal(nav_world(params), goal_msg(6.0, 4.5), limit=10.0)
    assert h.status == GoalStatus.ABORTED
    assert h.text == "Robot is oscillating. Even after executing recovery behaviors."


def test_blocked_robot_aborts_on_controller_patience():
    world = room_grid()
    fill(world, 0.6, 0.6, 1.4, 0.7)  # a pen around the robot that only its laser sees
    fill(world, 0.6, 1.3, 1.4, 1.4)
    fill(world, 0.6, 0.6, 0.7, 1.4)
    fill(world, 1.3, 0.6, 1.4, 1.4)
    params = move_base_params(
        glob={"observation_sources": ""},  # the global planner does not see the pen
        controller_patience=1.0,
        recovery_behavior_enabled=False,
    )
    w = nav_world(params, world=world)
    h = run_goal(w, goal_msg(3.0, 3.0), limit=20.0)
    assert h.status == GoalStatus.ABORTED
    assert h.text.startswith("Failed to find a valid control.")
    assert "TrajectoryPlannerROS: no valid trajectory" in h.text
    assert w.bot.min_clearance > 0.0


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
