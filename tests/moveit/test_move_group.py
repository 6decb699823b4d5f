"""move_group in the simulator: the hunter's nine named poses, obstacles, bad requests, two
hunters at once, and fake execution without physics."""

import logging

import numpy as np
import pytest

from fleetsim.moveit import (
    MoveGroup,
    MoveGroupCommander,
    MoveItCommanderException,
    PlanningSceneInterface,
)
from fleetsim.msgs import geometry_msgs, moveit_msgs, sensor_msgs, trajectory_msgs
from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.runtime import Node, Runtime
from fleetsim.tf.quaternions import quaternion_multiply
from fleetsim.tf.transforms import transform_points

from .conftest import ARM, Hunters, assert_no_mujoco_warnings, load_hunter_params

E = moveit_msgs.MoveItErrorCodes
VMAX = np.array([0.2, 0.2, 0.2, 0.5])


@pytest.fixture(scope="module")
def one(hunter_robot):
    h = Hunters(hunter_robot)
    yield h
    assert_no_mujoco_warnings(h.sim.engine)


def camera_direction(h: Hunters, ns: str) -> np.ndarray:
    """The arm camera's viewing direction (+x of camera_arm) in base_link."""
    e = h.sim.engine
    base = e.data.xmat[e.body_id(ns, "base_link")].reshape(3, 3)
    cam = e.data.xmat[e.body_id(ns, "camera_arm")].reshape(3, 3)
    return base.T @ cam[:, 0]


def arm_states(one, states: list):
    """Subscribe ``states`` to the hunter's joint_states messages that carry the arm (its
    diff drive publishes the wheels there too, publishWheelJointState, as in ROS)."""

    def keep(msg) -> None:
        if "arm_joint_01" in msg.name:
            states.append(msg)

    return one.probe.create_subscription(sensor_msgs.JointState, "/hunter1/joint_states", keep)


def measured_speeds(states: list) -> np.ndarray:
    """(J,) the largest |velocity| each arm joint showed on /joint_states: the reported
    velocities and the finite differences of the positions at the publish rate (50 Hz)."""
    reported = np.abs(np.array([s.velocity for s in states])).max(axis=0)
    t = np.array([s.header.stamp.to_sec() for s in states])
    q = np.array([s.position for s in states])
    differenced = np.abs(np.diff(q, axis=0) / np.diff(t)[:, None]).max(axis=0)
    return np.maximum(reported, differenced)


def test_each_named_pose_is_reached_within_the_speed_limits(one):
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    states = []
    arm_states(one, states)
    for name in arm.get_named_targets():
        arm.set_named_target(name)
        assert arm.go(), (name, arm.last_result())
        assert arm.last_result()[0].error_code.val == E.SUCCESS
        np.testing.assert_allclose(
            arm.get_current_joint_values(),
            list(arm.get_named_target_values(name).values()),
            atol=0.01,
        )
        d = camera_direction(one, "hunter1")
        if "left" in name:
            assert d[1] > 0.5, (name, d)
        if "right" in name:
            assert d[1] < -0.5, (name, d)
        if "back" in name:
            assert d[0] < -0.5, (name, d)
        if "low" in name:
            assert d[2] < -0.5, (name, d)
        else:
            assert d[2] > -0.5, (name, d)
    speeds = measured_speeds(states)
    assert np.all(speeds <= VMAX * 1.05), speeds / VMAX


def test_measured_speeds_stay_within_half_the_limits(one):
    """At scaling 0.5 the arm, not only the plan, keeps to 0.5 x max_velocity (+5 %): moves
    that hold the pitch joints still (cam_low -> cam_low_left -> cam_low_back) and moves that
    swing them (-> home_low -> cam_left). Under P-only gains the held joints dropped by one
    gravity sag at the start of each move, at up to 1.7 x the scaled limit."""
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    arm.set_named_target("cam_low")
    assert arm.go()
    states = []
    sub = arm_states(one, states)
    arm.set_max_velocity_scaling_factor(0.5)
    for name in ("cam_low_left", "cam_low_back", "home_low", "cam_left"):
        arm.set_named_target(name)
        assert arm.go(), (name, arm.last_result())
    sub.destroy()
    speeds = measured_speeds(states)
    assert np.all(speeds <= VMAX * 0.5 * 1.05), speeds / (VMAX * 0.5)
    # the yaw ran at its limit, the elbow swung at a good part of its own
    assert speeds[0] > VMAX[0] * 0.5 * 0.95 and speeds[2] > VMAX[2] * 0.5 * 0.5, speeds


def test_half_speed_and_a_box_in_the_way(one, caplog):
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    scene = PlanningSceneInterface(ns="/hunter1", runtime=one.rt)
    arm.set_named_target("cam_low")
    assert arm.go()
    mg = one.move_group("hunter1")
    ctx = mg.pipeline.context("arm_group")
    start = np.array(arm.get_current_joint_values())
    goal = np.array(list(arm.get_named_target_values("cam_low_back").values()))
    box = geometry_msgs.PoseStamped()
    box.header.frame_id = arm.get_planning_frame()
    mid = ctx.kin.link_pose(0.5 * (start + goal), "cluedo_link")[0]
    box.pose.position = geometry_msgs.Point(*mid)
    box.pose.orientation.w = 1.0
    scene.add_box("box", box, (0.1, 0.1, 0.1))
    assert scene.get_known_object_names() == ["box"]
    assert not ctx.scene.is_valid(0.5 * (start + goal))
    states = []
    arm_states(one, states)
    arm.set_max_velocity_scaling_factor(0.5)
    arm.set_named_target("cam_low_back")
    caplog.clear()
    with caplog.at_level(logging.INFO):
        assert arm.go()
    # the plan says which planner found it (no ompl_planning.yaml here: RRTConnect) ...
    assert "geometric::RRTConnect found a path" in caplog.text
    planned = arm.last_result()[0].planning_time
    assert 0 < planned < 5.0
    positions = [np.asarray(s.position) for s in states]
    assert all(ctx.scene.is_valid(q) for q in positions)  # the arm never entered the box
    speeds = measured_speeds(states)
    assert np.all(speeds <= VMAX * 0.5 * 1.05), speeds / (VMAX * 0.5)
    scene.remove_world_object("box")
    assert scene.get_known_object_names() == []
    # ... and that none ran when the straight motion is free
    arm.set_named_target("cam_low")
    caplog.clear()
    with caplog.at_level(logging.INFO):
        assert arm.go()
    assert (
        "straight joint-space motion is collision-free, so geometric::RRTConnect was not run"
        in (caplog.text)
    )


def test_bad_requests_are_refused_with_their_reason(one):
    with pytest.raises(MoveItCommanderException, match="Group 'arm' was not found"):
        MoveGroupCommander("arm", ns="/hunter1", runtime=one.rt)
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    with pytest.raises(MoveItCommanderException, match="no named state 'cam_up'"):
        arm.set_named_target("cam_up")
    with pytest.raises(MoveItCommanderException, match="'arm_joint_02' value 2.5000 is outside"):
        arm.set_joint_value_target([0.0, 2.5, 0.0, 0.0])
    with pytest.raises(MoveItCommanderException, match="scaling factor"):
        arm.set_max_velocity_scaling_factor(0.0)
    arm.set_position_target([1.5, 0.0, 0.5])  # 1.5 m away: out of reach
    assert not arm.go()
    result, text = arm.last_result()
    assert result.error_code.val == E.NO_IK_SOLUTION and "cluedo_link" in text
    ok, _, _, code = arm.plan([0.0, 1.8, 1.8, 0.0])  # folded onto the chassis
    assert not ok and code.val == E.GOAL_IN_COLLISION
    wheels = trajectory_msgs.JointTrajectory(joint_names=["joint_left_wheel"])
    wheels.points = [
        trajectory_msgs.JointTrajectoryPoint(positions=[0.0], time_from_start=Duration.from_sec(1))
    ]
    assert not arm.execute(wheels)
    assert "Unable to identify any set of controllers" in arm.last_result()[1]
    mg = one.move_group("hunter1")
    req = moveit_msgs.MotionPlanRequest(group_name="gripper")
    res, text = mg.plan(req)
    assert res.error_code.val == E.INVALID_GROUP_NAME and "'gripper'" in text


def test_position_target_and_kinematics_services(one):
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    target = [0.0, 0.1, 0.85]
    arm.set_goal_position_tolerance(0.005)
    arm.set_position_target(target)
    assert arm.go()
    p = arm.get_current_pose().pose.position
    assert np.linalg.norm(np.array([p.x, p.y, p.z]) - target) < 0.01
    fk = one.rt.graph.call_service(
        "/hunter1/compute_fk",
        moveit_msgs.GetPositionFK,
        moveit_msgs.GetPositionFKRequest(fk_link_names=["cluedo_link", "nowhere"]),
    )
    assert fk.error_code.val == E.INVALID_LINK_NAME
    ik = moveit_msgs.GetPositionIKRequest()
    ik.ik_request.group_name = "arm_group"
    ik.ik_request.pose_stamped.pose.position = geometry_msgs.Point(*target)
    res = one.rt.graph.call_service("/hunter1/compute_ik", moveit_msgs.GetPositionIK, ik)
    assert res.error_code.val == E.SUCCESS and list(res.solution.joint_state.name) == ARM


def test_two_hunters_move_their_arms_at_the_same_time(hunter_robot):
    h = Hunters(hunter_robot, ("hunter1", "hunter2"))
    a1 = MoveGroupCommander("arm_group", ns="/hunter1", runtime=h.rt)
    a2 = MoveGroupCommander("arm_group", ns="/hunter2", runtime=h.rt)
    a1.set_named_target("cam_left")
    a2.set_named_target("cam_right")
    a1.go(wait=False)
    a2.go(wait=False)
    t0 = h.rt.now()
    h.rt.run(40.0, until=lambda: a1._last.result is not None and a2._last.result is not None)
    assert a1._last.result.error_code.val == E.SUCCESS
    assert a2._last.result.error_code.val == E.SUCCESS
    durations = [
        a._last.result.planned_trajectory.joint_trajectory.points[-1].time_from_start.to_sec()
        for a in (a1, a2)
    ]
    assert h.rt.now() - t0 < sum(durations)  # at the same time, not one after the other
    assert camera_direction(h, "hunter1")[1] > 0.5
    assert camera_direction(h, "hunter2")[1] < -0.5
    assert_no_mujoco_warnings(h.sim.engine)


def test_fake_execution_without_physics(hunter_robot):
    rt = Runtime()
    load_hunter_params(rt, "/hunter1", hunter_robot, fake=True)
    MoveGroup(rt, "move_group", "/hunter1")
    fake = []
    probe = Node(rt, "probe")
    probe.create_subscription(
        sensor_msgs.JointState, "/hunter1/move_group/fake_controller_joint_states", fake.append
    )
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=rt)
    arm.set_named_target("cam_back")
    assert arm.go()
    rt.run(0.1)
    np.testing.assert_allclose(
        fake[-1].position, list(arm.get_named_target_values("cam_back").values()), atol=1e-9
    )


def test_stop_start_deviation_and_the_plan_service(one):
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    arm.set_named_target("home")
    assert arm.go()
    arm.set_named_target("cam_back")
    arm.go(wait=False)
    one.rt.run(2.0)
    arm.stop()
    one.rt.run(1.0, until=lambda: arm._last.result is not None)
    result, text = arm.last_result()
    assert result.error_code.val == E.PREEMPTED and "trajectory_execution_event" in text
    held = np.array(arm.get_current_joint_values())
    one.rt.run(1.0)
    np.testing.assert_allclose(arm.get_current_joint_values(), held, atol=0.01)
    # a trajectory that starts away from where the arm is: refused before it moves
    far = trajectory_msgs.JointTrajectory(joint_names=ARM)
    far.points = [
        trajectory_msgs.JointTrajectoryPoint(
            positions=held + 0.2, time_from_start=Duration.from_sec(0.0)
        ),
        trajectory_msgs.JointTrajectoryPoint(
            positions=held + 0.3, time_from_start=Duration.from_sec(1.0)
        ),
    ]
    assert not arm.execute(far)
    assert "start point deviates from current robot state more than 0.01" in arm.last_result()[1]
    req = moveit_msgs.GetMotionPlanRequest()
    req.motion_plan_request.group_name = "arm_group"
    req.motion_plan_request.goal_constraints = [
        moveit_msgs.Constraints(
            joint_constraints=[
                moveit_msgs.JointConstraint(joint_name=j, position=v)
                for j, v in arm.get_named_target_values("cam_left").items()
            ]
        )
    ]
    now = arm.get_current_joint_values()
    res = one.rt.graph.call_service(
        "/hunter1/plan_kinematic_path", moveit_msgs.GetMotionPlan, req
    ).motion_plan_response
    assert res.error_code.val == E.SUCCESS
    pts = res.trajectory.joint_trajectory.points
    np.testing.assert_allclose(pts[0].positions, now, atol=1e-9)  # from the current state
    np.testing.assert_allclose(
        pts[-1].positions, list(arm.get_named_target_values("cam_left").values()), atol=1e-9
    )


def test_a_new_goal_preempts_the_running_one_and_runs_itself(one):
    """The manual's manipulation unit sends a pose every 5 s whether the last is done or not:
    the running goal ends PREEMPTED (MoveIt's code -7), the new one runs to SUCCESS with its
    own result, and move_group goes on serving (it had answered the new goal PREEMPTED, run it
    anyway, then died ending a goal no longer active)."""
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    assert arm.go("home")
    arm.go("cam_left", wait=False)
    first = arm._last
    one.rt.run(1.0)
    assert first.result is None  # still moving
    assert arm.go("cam_right")
    assert first.result is not None and first.result.error_code.val == E.PREEMPTED
    assert "another goal" in first.text or "new goal" in first.text
    assert arm.last_result()[0].error_code.val == E.SUCCESS
    np.testing.assert_allclose(
        arm.get_current_joint_values(),
        list(arm.get_named_target_values("cam_right").values()),
        atol=0.02,
    )
    one.rt.run(3.0)  # nothing left running to end a goal that is gone
    assert arm.go("home")


def test_a_goal_already_met_succeeds_without_moving(one):
    """Going where the arm already is (a named pose twice, the current joint values, a pose
    target at the current pose): SUCCESS with MoveIt's "already met", nothing executed; a move
    a hair from where it stands is timed (toppra found no profile below ~5e-5 rad)."""
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    assert arm.go("cam_left")
    one.rt.run(2.0)  # the controller's integral term settles the joints to well within 1e-4
    for target in ("cam_left", arm.get_current_joint_values()):
        assert arm.go(target), arm.last_result()
        result, text = arm.last_result()
        assert text == "Requested path and goal constraints are already met."
        (point,) = result.planned_trajectory.joint_trajectory.points  # the start, at rest
        assert point.time_from_start.to_sec() == 0.0
    # a plan of it holds that one point (MoveIt's tutorials test for points), and executes
    ok, traj, _, _ = arm.plan(arm.get_current_joint_values())
    assert ok and len(traj.joint_trajectory.points) == 1 and arm.execute(traj)
    arm.set_goal_position_tolerance(0.01)
    arm.set_position_target(
        [getattr(arm.get_current_pose().pose.position, k) for k in ("x", "y", "z")]
    )
    assert arm.go() and "already met" in arm.last_result()[1]
    arm.set_goal_joint_tolerance(0.0)
    for delta in (1e-6, 5e-5, 5e-4):
        q = np.array(arm.get_current_joint_values())
        q[0] += delta
        assert arm.go(list(q)), (delta, arm.last_result())
        assert arm.last_result()[0].planned_trajectory.joint_trajectory.points


def test_joint_limits_yaml_values_are_checked_when_move_group_starts(hunter_robot, caplog):
    """``max_velocity: '0.2 rad/s'`` crashed the first plan with a bare ValueError; now
    move_group refuses to start, naming the joint, the key and the value."""
    from fleetsim.errors import PlanningError

    rt = Runtime()
    load_hunter_params(rt, "/hunter1", hunter_robot)
    rt.params.set("/hunter1/robot_description_planning/joint_limits/arm_joint_02/max_velocity",
                  "0.2 rad/s")  # fmt: skip
    with pytest.raises(PlanningError, match="arm_joint_02/max_velocity: '0.2 rad/s' is not a"):
        MoveGroup(rt, "move_group", "/hunter1")
    rt = Runtime()
    load_hunter_params(rt, "/hunter1", hunter_robot)
    rt.params.set("/hunter1/robot_description_planning/joint_limits/arm_joint_02/max_velocty", 0.3)
    rt.params.set("/hunter1/robot_description_planning/default_velocity_scaling_factor", 0.0)
    with caplog.at_level(logging.WARNING):
        MoveGroup(rt, "move_group", "/hunter1")
    assert (
        "max_velocty is not a joint limit fleetsim reads; ignored (did you mean 'max_velocity'?)"
        in caplog.text
    )
    assert "default_velocity_scaling_factor is 0, outside (0, 1]" in caplog.text


def test_execute_of_plans_tuple_and_a_commander_for_a_links_only_group(one):
    """``arm.execute(arm.plan())`` (the Melodic idiom; plan() returns a tuple since Noetic)
    says what to pass, before sending anything; the SRDF's ``ee`` group (a link, no joints)
    gets a commander with no joints and its link as end effector, and refuses to plan."""
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    arm.set_named_target("home")
    plan = arm.plan()
    with pytest.raises(MoveItCommanderException, match=r"execute\(plan\[1\]\)"):
        arm.execute(plan)
    with pytest.raises(MoveItCommanderException, match="got str"):
        arm.execute("home")
    assert arm.execute(plan[1])
    ee = MoveGroupCommander("ee", ns="/hunter1", runtime=one.rt)
    assert ee.get_active_joints() == [] and ee.get_end_effector_link() == "cluedo_link"
    assert not ee.go([])
    assert ee.last_result()[0].error_code.val == E.INVALID_GROUP_NAME


def test_targets_and_objects_in_other_frames_go_through_tf(hunter_robot, caplog):
    """A PoseStamped target, Cartesian waypoints and collision objects in ``odom`` (or any
    frame tf knows) are transformed into the planning frame, as move_group does; they had been
    taken as if in base_link. An unknown frame is MoveIt's FRAME_TRANSFORM_FAILURE, and an
    object in one is not added."""
    h = Hunters(hunter_robot, tf_prefix=True)
    h.sim.engine.set_model_state("hunter1", position=[2.0, -1.0, 0.05],
                                 orientation=[np.cos(0.3), 0.0, 0.0, np.sin(0.3)])  # fmt: skip
    h.rt.run(0.5)
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=h.rt)
    assert arm.get_planning_frame() == "hunter1/base_link"
    assert arm.go("home")
    here = arm.get_current_pose()
    assert here.header.frame_id == "hunter1/base_link"
    tf = h.rt.tf_buffer.lookup_arrays("hunter1/odom", "hunter1/base_link", 0.0)
    p = here.pose.position
    in_odom = transform_points(*tf, [[p.x, p.y, p.z]])[0]
    assert np.linalg.norm(in_odom[:2] - [p.x, p.y]) > 1.0  # the frames are far apart
    arm.set_goal_position_tolerance(0.005)
    arm.set_pose_reference_frame("hunter1/odom")
    arm.set_position_target(in_odom - [0.0, 0.0, 0.04])
    assert arm.go(), arm.last_result()
    now = arm.get_current_pose().pose.position
    assert np.linalg.norm([now.x - p.x, now.y - p.y, now.z - (p.z - 0.04)]) < 0.01
    # Cartesian waypoints in the pose reference frame (odom): 3 cm up again, in a line
    up = geometry_msgs.Pose(position=geometry_msgs.Point(*in_odom))
    up.orientation.w = 1.0
    traj, fraction = arm.compute_cartesian_path([up], 0.005, False)
    assert fraction == pytest.approx(1.0), fraction
    assert arm.execute(traj)
    now = arm.get_current_pose().pose.position
    assert np.linalg.norm([now.x - p.x, now.y - p.y, now.z - p.z]) < 0.01
    # a stamped target in an unknown frame
    target = geometry_msgs.PoseStamped()
    target.header.frame_id = "nowhere"
    target.pose.position = geometry_msgs.Point(*in_odom)
    target.pose.orientation.w = 1.0
    arm.set_pose_target(target)
    assert not arm.go()
    result, text = arm.last_result()
    assert result.error_code.val == E.FRAME_TRANSFORM_FAILURE
    assert "Unable to transform from frame 'nowhere'" in text
    # objects: one in odom lands where the tip is, one in an unknown frame is not added
    scene = PlanningSceneInterface("/hunter1", runtime=h.rt)
    box = geometry_msgs.PoseStamped()
    box.header.frame_id = "hunter1/odom"
    box.pose.position = geometry_msgs.Point(*in_odom)
    box.pose.orientation.w = 1.0
    scene.add_box("at_tip", box, (0.05, 0.05, 0.05))
    box.header.frame_id = "nowhere"
    with caplog.at_level(logging.ERROR):
        scene.add_box("lost", box, (0.05, 0.05, 0.05))
    mg = h.move_group("hunter1")
    (geom,) = mg.pipeline.objects["at_tip"]
    np.testing.assert_allclose(geom[2], [p.x, p.y, p.z], atol=1e-4)  # the base creeps µm
    assert "lost" not in mg.pipeline.objects and "Unable to transform" in caplog.text
    scene = h.rt.graph.call_service(
        "/hunter1/get_planning_scene",
        moveit_msgs.GetPlanningScene,
        moveit_msgs.GetPlanningSceneRequest(),
    ).scene
    (obj,) = scene.world.collision_objects  # as placed, in the root link's frame
    assert obj.header.frame_id == "hunter1/base_link"
    q = obj.primitive_poses[0].position
    np.testing.assert_allclose([q.x, q.y, q.z], [p.x, p.y, p.z], atol=1e-4)
    assert_no_mujoco_warnings(h.sim.engine)


def test_out_of_reach_approximate_ik_and_more_of_moveit_commanders_calls(one, caplog):
    """A pose 2 m away is out of reach whatever its orientation, and says so (it had blamed
    the orientation, sending the user to set_position_target, which failed too); approx=True
    takes the position with the orientation the arm makes there; moveit_commander calls the
    manual's client makes exist."""
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=one.rt)
    assert arm.go("home")
    far = geometry_msgs.Pose(position=geometry_msgs.Point(2.0, 0.0, 0.5))
    far.orientation.w = 1.0
    arm.set_pose_target(far)
    assert not arm.go()
    text = arm.last_result()[1]
    assert "whatever its orientation: the position is out of the arm's reach" in text
    here = arm.get_current_pose().pose
    p = here.position
    target = geometry_msgs.Pose(position=geometry_msgs.Point(p.x, p.y, p.z - 0.05))
    o = here.orientation  # a quarter turn about the tip's own z: not one the joints make
    turned = quaternion_multiply([o.x, o.y, o.z, o.w], [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)])
    target.orientation = geometry_msgs.Quaternion(*turned)
    arm.set_goal_position_tolerance(0.005)
    arm.set_joint_value_target(target, False)
    assert not arm.go()  # that orientation is not one the arm can make there
    assert "an orientation the arm can make" in arm.last_result()[1]
    arm.set_joint_value_target(target, "cluedo_link", True)
    assert arm.go(), arm.last_result()
    z = arm.get_current_pose().pose.position.z
    assert z == pytest.approx(p.z - 0.05, abs=0.006)
    arm.set_pose_reference_frame(arm.get_planning_frame())
    arm.allow_replanning(True)
    arm.set_start_state_to_current_state()
    assert len(arm.get_current_rpy()) == 3 and len(arm.get_random_joint_values()) == 4
    arm.set_random_target()
    assert arm.get_joint_value_target() != arm.get_current_joint_values()


def test_a_group_state_missing_a_joint_is_warned_about(hunter_robot, caplog):
    from fleetsim.description.srdf import parse_srdf
    from fleetsim.moveit.robot_model import RobotModel

    from .conftest import HUNTER

    text = (HUNTER / "config" / "robocluedo_robot.srdf").read_text()
    start = text.index('<group_state name="cam_left"')
    line = text.index('<joint name="arm_joint_01"', start)
    text = text[:line] + text[text.index("\n", line) + 1 :]
    with caplog.at_level(logging.WARNING):
        RobotModel(hunter_robot, parse_srdf(text, "hunter.srdf", hunter_robot), {})
    assert (
        "group state 'cam_left' doesn't specify all joints of group 'arm_group' "
        "(arm_joint_01 missing: taken as 0)" in caplog.text
    )


def test_a_timed_out_execution_says_when_the_physics_is_paused(hunter_robot):
    """``gazebo_paused:=true``: the arm never moves and the execution times out; the message
    says the physics is paused."""
    h = Hunters(hunter_robot)
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=h.rt)
    h.sim.engine.paused = True
    assert not arm.go("cam_left")
    result, text = arm.last_result()
    assert result.error_code.val == E.TIMED_OUT
    assert "The simulator's physics is paused (/gazebo/unpause_physics)" in text


def test_a_fixed_virtual_joint_needs_no_tf(hunter_robot):
    """The Setup Assistant's ``<virtual_joint type="fixed" parent_frame="world">``: the planning
    frame is ``world``, which no one publishes on tf; MoveIt's model holds that transform
    (identity), so targets without a frame and get_current_pose work without it."""
    from fleetsim.control.spawner import Spawner
    from fleetsim.sim.node import Simulator

    from .conftest import HUNTER

    rt = Runtime()
    sim = Simulator(rt)
    load_hunter_params(rt, "/hunter1", hunter_robot)
    srdf = (HUNTER / "config" / "robocluedo_robot.srdf").read_text()
    vj = '<virtual_joint name="vj" type="fixed" parent_frame="world" child_link="base_link"/>'
    rt.params.set("/hunter1/robot_description_semantic", srdf.replace("</robot>", vj + "</robot>"))
    sim.spawn_robot("hunter1", hunter_robot, (0, 0, 0.05, 0, 0, 0), "/hunter1")
    Spawner(rt, "spawner", "/hunter1", args=["joint_state_controller", "arm_group_controller"])
    MoveGroup(rt, "move_group", "/hunter1")
    rt.run(0.3)
    arm = MoveGroupCommander("arm_group", ns="/hunter1", runtime=rt)
    assert arm.get_planning_frame() == "world"
    assert arm.go("home")
    here = arm.get_current_pose()
    assert here.header.frame_id == "world"
    p = here.pose.position
    arm.set_goal_position_tolerance(0.005)
    arm.set_position_target([p.x, p.y, p.z - 0.03])
    assert arm.go(), arm.last_result()
    assert arm.get_current_pose().pose.position.z == pytest.approx(p.z - 0.03, abs=0.006)
    assert_no_mujoco_warnings(sim.engine)
