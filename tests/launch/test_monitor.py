"""The run monitor counts goals for robots whose move_base is not in the launch plan, and
counts a goal as reached only when the simulator's ground truth agrees."""

import io
import os
from pathlib import Path

import pytest

from fleetsim.cli.launch import results_table
from fleetsim.launch.monitor import DEFAULT_XY_GOAL_TOLERANCE, GOAL_MARGIN
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import actionlib_msgs, geometry_msgs, move_base_msgs
from fleetsim.runtime import Node

#: the simulator and one lizi, no move_base: it would run in another process (node run)
ROBOT_ONLY = """<launch>
  <include file="$(find gazebo_ros)/launch/empty_world.launch">
    <arg name="gui" value="false"/>
  </include>
  <group ns="lizi1">
    <param name="tf_prefix" value="lizi1"/>
    <param name="robot_description"
           command="$(find xacro)/xacro $(find lizi)/urdf/lizi.urdf.xacro"/>
    <node name="spawn_urdf" pkg="gazebo_ros" type="spawn_model"
          args="-x 1 -y 2 -z 0.078 -urdf -param robot_description -model lizi1"/>
  </group>
</launch>
"""


def test_a_spawned_robot_without_move_base_in_the_plan_has_its_goals_counted(tmp_path: Path):
    os.environ.setdefault("MUJOCO_GL", "egl")
    f = tmp_path / "robot_only.launch"
    f.write_text(ROBOT_ONLY)
    with LaunchSession(load_plan(f), seed=1) as s:
        s.runtime.run(duration=0.3)  # the robot is spawned and sampled
        mb = move_base_msgs.MoveBase
        stand_in = Node(s.runtime, "move_base", "/lizi1")  # what a remote move_base publishes
        goal_pub = stand_in.create_publisher(mb.ActionGoal, "move_base/goal", 1)
        result_pub = stand_in.create_publisher(mb.ActionResult, "move_base/result", 1)
        assert not s.monitor.all_goals_done()
        goal_pub.publish(action_goal("g1", 1.0, 2.0))  # where the robot stands
        s.runtime.run(duration=0.1)
        r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
        assert (r.model, r.goals_sent, r.goals_reached) == ("lizi1", 1, 0)
        assert not s.monitor.all_goals_done()
        status = actionlib_msgs.GoalStatus(
            goal_id=actionlib_msgs.GoalID(id="g1"), status=actionlib_msgs.GoalStatus.SUCCEEDED
        )
        result_pub.publish(mb.ActionResult(status=status))
        s.runtime.run(duration=0.1)
        assert (r.goals_sent, r.goals_reached, r.goals_failed) == (1, 1, 0)
        assert s.monitor.all_goals_done() and s.monitor.success()


def action_goal(goal_id: str, x: float, y: float, frame: str = "map"):
    mb = move_base_msgs.MoveBase
    target = geometry_msgs.PoseStamped()
    target.header.frame_id = frame
    target.pose.position.x, target.pose.position.y = x, y
    target.pose.orientation.w = 1.0
    return mb.ActionGoal(
        goal_id=actionlib_msgs.GoalID(id=goal_id), goal=mb.Goal(target_pose=target)
    )


def status(goal_id: str, code: int, text: str = ""):
    return actionlib_msgs.GoalStatus(
        goal_id=actionlib_msgs.GoalID(id=goal_id), status=code, text=text
    )


@pytest.fixture
def robot_session(tmp_path: Path):
    """A session with lizi1 at (1, 2) and a stand-in for its remote move_base."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    f = tmp_path / "robot_only.launch"
    f.write_text(ROBOT_ONLY)
    with LaunchSession(load_plan(f), seed=1) as s:
        s.runtime.run(duration=0.3)
        mb = move_base_msgs.MoveBase
        stand_in = Node(s.runtime, "move_base", "/lizi1")
        pubs = (
            stand_in.create_publisher(mb.ActionGoal, "move_base/goal", 1),
            stand_in.create_publisher(mb.ActionResult, "move_base/result", 1),
        )
        yield s, pubs


def test_a_succeeded_result_that_ground_truth_contradicts_fails_the_run(robot_session):
    s, (goal_pub, result_pub) = robot_session
    mb = move_base_msgs.MoveBase
    goal_pub.publish(action_goal("far", 23.0, 2.0))  # 22 m from where lizi1 stands
    s.runtime.run(duration=0.1)
    result_pub.publish(mb.ActionResult(status=status("far", 3, "Goal reached.")))
    s.runtime.run(duration=0.1)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert (r.goals_sent, r.goals_reached, r.goals_unconfirmed) == (1, 0, 1)
    assert r.last_text == "reported reached, 22.0 m away by ground truth"
    assert r.distance_to_goal == pytest.approx(22.0, abs=0.05)
    assert r.localization_error is None  # nothing publishes map here
    assert s.monitor.all_goals_done() and not s.monitor.success()
    text = str([list(c.cells) for c in results_table(s.monitor).columns])
    assert "reported reached, 22.0 m away by ground truth" in text and "22.00" in text


def test_ground_truth_within_tolerance_plus_margin_confirms_the_goal(robot_session):
    s, (goal_pub, result_pub) = robot_session
    mb = move_base_msgs.MoveBase
    near = DEFAULT_XY_GOAL_TOLERANCE + GOAL_MARGIN - 0.05
    goal_pub.publish(action_goal("near", 1.0 + near, 2.0))
    s.runtime.run(duration=0.1)
    result_pub.publish(mb.ActionResult(status=status("near", 3, "Goal reached.")))
    s.runtime.run(duration=0.1)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert (r.goals_reached, r.goals_unconfirmed) == (1, 0)
    assert r.goal_tolerance == pytest.approx(DEFAULT_XY_GOAL_TOLERANCE + GOAL_MARGIN)
    assert r.distance_to_goal == pytest.approx(near, abs=0.02)
    assert s.monitor.success()


def test_the_goal_tolerance_comes_from_the_local_planner_parameters(robot_session):
    s, (goal_pub, result_pub) = robot_session
    mb = move_base_msgs.MoveBase
    s.runtime.params.set("/lizi1/move_base/base_local_planner", "dwa_local_planner/DWAPlannerROS")
    s.runtime.params.set("/lizi1/move_base/DWAPlannerROS/xy_goal_tolerance", 1.0)
    goal_pub.publish(action_goal("g", 2.0, 2.0))  # 1 m away: within 1.0 + margin
    s.runtime.run(duration=0.1)
    result_pub.publish(mb.ActionResult(status=status("g", 3)))
    s.runtime.run(duration=0.1)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert r.goal_tolerance == pytest.approx(1.0 + GOAL_MARGIN)
    assert (r.goals_reached, r.goals_unconfirmed) == (1, 0)


def test_a_goal_in_an_unknown_frame_is_not_confirmed(robot_session):
    s, (goal_pub, result_pub) = robot_session
    mb = move_base_msgs.MoveBase
    goal_pub.publish(action_goal("g", 1.0, 2.0, frame="nowhere"))
    s.runtime.run(duration=0.1)
    result_pub.publish(mb.ActionResult(status=status("g", 3)))
    s.runtime.run(duration=0.1)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert r.goals_unconfirmed == 1 and "does not resolve" in r.last_text
    assert not s.monitor.success()


def test_a_goal_in_the_robots_own_slam_map_is_placed_by_its_estimate_and_checked(robot_session):
    """A goal in ``lizi1/map`` (the robot's own gmapping map, started wherever it stood: here
    a map -> odom turned 90 degrees and shifted) has no transform to the world. It is placed
    where the robot's estimate put it when given, and arriving is checked by ground truth:
    0.2 m from the estimate confirms, 3 m does not."""
    import math

    from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped

    s, (goal_pub, result_pub) = robot_session
    mb = move_base_msgs.MoveBase
    # given before gmapping's first map -> odom: placed once the transform comes
    goal_pub.publish(action_goal("early", 0.0, 0.0, frame="lizi1/map"))
    s.runtime.run(duration=0.2)
    assert {r.namespace: r for r in s.monitor.results()}["/lizi1"].goal is None
    slam = Node(s.runtime, "slam_gmapping", "/lizi1")
    half = math.sqrt(0.5)
    StaticTransformBroadcaster(slam).send_transform(
        make_transform_stamped("lizi1/map", "lizi1/odom", 0.0, (3.0, -1.0, 0.0), (0, 0, half, half))
    )
    s.runtime.run(duration=0.2)
    assert {r.namespace: r for r in s.monitor.results()}["/lizi1"].goal is not None
    est = s.runtime.tf_buffer.lookup_transform("lizi1/map", "lizi1/base_link", 0.0)
    ex, ey = est.transform.translation.x, est.transform.translation.y
    q = est.transform.rotation
    yaw_est = 2 * math.atan2(q.z, q.w)
    pos, (w, _, _, z) = s.monitor.sim.engine.model_pose("lizi1")
    yaw_true = 2 * math.atan2(z, w)
    for goal_id, (dx, dy) in (("near", (0.2, 0.0)), ("far", (0.0, 3.0))):
        goal_pub.publish(action_goal(goal_id, ex + dx, ey + dy, frame="lizi1/map"))
        s.runtime.run(duration=0.1)
        r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
        turn = yaw_true - yaw_est  # the frame's heading in the world
        want = (
            pos[0] + math.cos(turn) * dx - math.sin(turn) * dy,
            pos[1] + math.sin(turn) * dx + math.cos(turn) * dy,
        )
        assert r.goal == pytest.approx(want, abs=0.01)
        result_pub.publish(mb.ActionResult(status=status(goal_id, 3, "Goal reached.")))
        s.runtime.run(duration=0.1)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert (r.goals_sent, r.goals_reached, r.goals_unconfirmed) == (3, 1, 1)
    assert r.last_text == "reported reached, 3.0 m away by ground truth"


def test_the_localization_error_compares_map_to_base_with_ground_truth(robot_session):
    """A localizer that is 0.5 m off (here a static map -> odom) shows as a 0.5 m error."""
    from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped

    s, _ = robot_session
    localizer = Node(s.runtime, "localizer", "/lizi1")
    StaticTransformBroadcaster(localizer).send_transform(
        make_transform_stamped("map", "lizi1/odom", 0.0, (0.5, 0.0, 0.0))
    )
    s.runtime.run(duration=0.2)
    r = {r.namespace: r for r in s.monitor.results()}["/lizi1"]
    assert r.localization_error == pytest.approx(0.5, abs=0.01)


def test_without_a_simulator_here_ground_truth_comes_from_gazebo_model_states():
    """A joined session (``launch --connect``) has no engine: /gazebo/model_states is the truth,
    and the move_base node's own name (move_base_node, as the lesson) finds its tolerance."""
    from fleetsim.launch.model import LaunchPlan, NodeSpec
    from fleetsim.launch.monitor import RunMonitor
    from fleetsim.msgs import gazebo_msgs
    from fleetsim.runtime import Runtime

    rt = Runtime(seed=1)
    rt.params.set("/lizi1/move_base_node/TrajectoryPlannerROS/xy_goal_tolerance", 0.3)
    plan = LaunchPlan(nodes=[NodeSpec("move_base", "move_base", "move_base_node", "/lizi1")])
    monitor = RunMonitor(rt, plan, {})
    mb = move_base_msgs.MoveBase
    sim = Node(rt, "gazebo", "/")
    states = sim.create_publisher(gazebo_msgs.ModelStates, "/gazebo/model_states")
    stand_in = Node(rt, "move_base_node", "/lizi1")
    goal_pub = stand_in.create_publisher(mb.ActionGoal, "move_base/goal", 1)
    result_pub = stand_in.create_publisher(mb.ActionResult, "move_base/result", 1)
    pose = geometry_msgs.Pose()
    pose.position.x, pose.position.y = 5.0, 1.0
    states.publish(gazebo_msgs.ModelStates(name=["lizi1"], pose=[pose], twist=[]))
    goal_pub.publish(action_goal("a", 5.5, 1.0))  # 0.5 m: within 0.3 + margin
    goal_pub.publish(action_goal("b", 9.0, 1.0))  # replaces a; 4 m away
    rt.spin_once()
    result_pub.publish(mb.ActionResult(status=status("a", 3)))
    result_pub.publish(mb.ActionResult(status=status("b", 3)))
    rt.spin_once()
    r = monitor.results()[0]
    assert r.goal_tolerance == pytest.approx(0.3 + GOAL_MARGIN)
    assert (r.goals_sent, r.goals_reached, r.goals_unconfirmed) == (2, 1, 1)
    assert r.last_text == "reported reached, 4.0 m away by ground truth"
    assert r.distance_to_goal == pytest.approx(4.0)


def test_the_notes_under_the_table_name_each_collision_and_the_whole_long_status():
    """A run that fails on a collision says which robots touched, when and where (once per
    pair: both robots record it); a status too long for the table's column is shortened there
    and given whole below it."""
    from types import SimpleNamespace

    from fleetsim.cli.launch import STATUS_WIDTH, results_notes
    from fleetsim.launch.monitor import RobotResult

    long = "Failed to find a valid plan. Even after executing recovery behaviors. " * 2
    a = RobotResult(namespace="/lizi1", model="lizi1", last_text="Goal reached.")
    b = RobotResult(namespace="/lizi2", model="lizi2", last_text=long)
    a.collision_events.append((14.672, "lizi2", 3.0, 4.5))
    b.collision_events.append((14.672, "lizi1", 3.4, 4.5))
    b.collision_events.append((20.0, "willowgarage", 7.25, 1.0))
    monitor = SimpleNamespace(results=lambda: [a, b])
    assert results_notes(monitor) == [
        "collision at 14.67 s: /lizi1 touched robot /lizi2, /lizi1 at (3.00, 4.50)",
        "collision at 20.00 s: /lizi2 touched 'willowgarage', /lizi2 at (7.25, 1.00)",
        f"/lizi2 last status: {long}",
    ]
    cells = [list(c.cells) for c in results_table(monitor).columns]
    status = cells[-1]
    assert status[0] == "Goal reached." and len(status[1]) == STATUS_WIDTH
    assert status[1].endswith("\u2026")
    from rich.console import Console

    con = Console(record=True, width=200, file=io.StringIO())
    con.print(results_table(monitor))
    shown = con.export_text()
    assert "last result at [sim s]" in shown and "path [m]" in shown  # not eaten as markup


def test_a_robot_in_the_root_namespace_is_named_by_its_model_in_the_table():
    from types import SimpleNamespace

    from fleetsim.launch.monitor import RobotResult

    root = RobotResult(namespace="/", model="robocluedo_robot")
    named = RobotResult(namespace="/lizi1", model="lizi1")
    monitor = SimpleNamespace(results=lambda: [root, named])
    robots = list(results_table(monitor).columns[0].cells)
    assert robots == ["/ (robocluedo_robot)", "/lizi1"]
