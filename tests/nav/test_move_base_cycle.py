"""move_base's executeCycle: planning patience and retries, recoveries, oscillation and
controller patience, each ending in an abort whose text carries the reason."""

from nav_world import fill, goal_msg, move_base_params, nav_world, room_grid

from fleetsim.msgs.actionlib_msgs import GoalStatus


def run_goal(w, goal, limit=60.0):
    h = w.client.send_goal(goal)
    w.rt.run(duration=limit, until=lambda: h.done)
    return h


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


def test_goal_outside_the_map_aborts_without_recoveries(caplog):
    params = move_base_params(planner_patience=0.5, recovery_behavior_enabled=False)
    w = nav_world(params)
    w.rt.run(duration=0.5)
    with caplog.at_level("WARNING"):
        h = run_goal(w, goal_msg(20.0, 20.0))
    assert h.status == GoalStatus.ABORTED
    assert "navfn: the goal (20.000, 20.000) is off the global costmap" in h.text
    assert w.rt.now() < 2.0
    # said at the first plan that fails, as navfn_ros does, not only when the goal aborts
    # (with recoveries, half a minute or more later); once, not at every retry
    warned = [r for r in caplog.records if "will always fail to this goal" in r.getMessage()]
    assert len(warned) == 1
    assert "navfn: the goal (20.000, 20.000) is off the global costmap" in warned[0].getMessage()


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


def plans_for_short_goal(**top):
    w = nav_world(move_base_params(**top))
    h = run_goal(w, goal_msg(3.0, 1.0), limit=20.0)
    assert h.status == GoalStatus.SUCCEEDED
    return w.watch.plans


def test_planner_frequency_zero_plans_once_and_positive_replans():
    assert len(plans_for_short_goal()) == 1
    assert len(plans_for_short_goal(planner_frequency=2.0)) >= 5  # ~5 s of driving


def test_a_clearing_recovery_forgets_far_obstacles_at_the_next_update():
    w = nav_world()
    w.rt.run(duration=0.5)
    cm = w.mb.global_costmap
    layer = cm.layered.layer("obstacle_layer")
    w.bot.scan_timer.cancel()  # no raytracing to clear the marks below
    layer.buffers["scan"].observations = []
    cm.sources.drop_unread()  # nor a scan that came since the last update
    near, far = cm.costmap.world_to_map(1.5, 1.0), cm.costmap.world_to_map(3.0, 4.0)
    for mx, my in (near, far):
        layer.grid.costs[my, mx] = 254
    cm.mark_full_update()
    cm.update()
    assert cm.costmap.costs[far[1], far[0]] == 254
    conservative = w.mb.recoveries[0]
    assert conservative.name == "conservative_reset"
    assert w.mb._run_recovery(conservative)  # a clearing is done at once
    cm.update()
    assert cm.costmap.costs[far[1], far[0]] < 253  # outside the 3 m square: forgotten
    assert cm.costmap.costs[near[1], near[0]] == 254  # inside it: kept


def test_a_new_goal_during_a_rotate_recovery_starts_afresh():
    w = nav_world(move_base_params(planner_patience=0.5))
    first = w.client.send_goal(goal_msg(4.0, 1.0))  # inside the wall
    spinning = w.mb.recoveries[1].rotate
    w.rt.run(duration=10.0, until=lambda: spinning.start_angle is not None)
    assert w.mb.state == "CLEARING" and w.mb.recovery_index == 1
    w.rt.run(duration=1.0)  # part of the turn
    second = run_goal(w, goal_msg(2.0, 2.0), limit=30.0)
    assert first.status == GoalStatus.PREEMPTED
    assert second.status == GoalStatus.SUCCEEDED
    assert spinning.start_angle is None


def test_a_moveback_recovery_backs_the_robot_up_then_move_base_goes_on():
    params = move_base_params(
        planner_patience=0.5,
        recovery_behaviors=[{"name": "back", "type": "moveback_recovery/MoveBackRecovery"}],
        back={"step_back_length": 0.5, "linear_vel_back": -0.2},
    )
    w = nav_world(params, start=(3.0, 1.0, 0.0))
    h = run_goal(w, goal_msg(4.0, 1.0))  # inside the wall: planning fails, then recovery
    assert h.status == GoalStatus.ABORTED
    assert "navfn: the goal (4.000, 1.000) is in an obstacle" in h.text
    backs = [m.linear.x for _, m in w.watch.cmds if m.linear.x < 0]
    assert backs and set(backs) == {-0.2}
    assert 2.4 <= w.bot.pose[0] <= 2.55, w.bot.pose  # 0.5 m straight back, then stopped
    assert abs(w.bot.pose[1] - 1.0) < 1e-6 and w.watch.cmds[-1][1].linear.x == 0.0
    assert w.mb.recoveries[0].moveback.outcome == "moved backwards 0.5 m"


def test_a_goal_in_a_wall_of_the_map_is_warned_about_at_the_first_failed_plan(caplog):
    """navfn says nothing of a goal in a wall until move_base aborts it after its patience and
    recoveries; fleetsim warns once, at the first plan that fails, as for a goal off the map."""
    w = nav_world(move_base_params(planner_patience=1.0))
    with caplog.at_level("WARNING"):
        h = w.client.send_goal(goal_msg(4.0, 1.0))
        w.rt.run(duration=0.5)
        warned = [
            r.getMessage() for r in caplog.records if "in a wall of the map" in r.getMessage()
        ]
        assert len(warned) == 1 and "the goal (4.000, 1.000) is in an obstacle" in warned[0]
        w.rt.run(duration=60.0, until=lambda: h.done)
    assert h.status == GoalStatus.ABORTED
    assert len([r for r in caplog.records if "in a wall of the map" in r.getMessage()]) == 1
