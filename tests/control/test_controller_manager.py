"""gazebo_ros_control + controller_manager: two hunters, each with its own controllers."""

import logging

import numpy as np
import pytest

from fleetsim.control.spawner import Spawner
from fleetsim.control.trajectory import sample
from fleetsim.errors import ControlError
from fleetsim.msgs import control_msgs, sensor_msgs, trajectory_msgs
from fleetsim.msgs import controller_manager_msgs as cmm
from fleetsim.msgs.builtin_interfaces import Duration

from .conftest import ARM, hunter_config

Result = control_msgs.FollowJointTrajectoryResult
HOME = [-1.57, 0.1293, -0.4276, 0.3481]
CAM_LOW = [-1.6481, 0.5271, -1.5215, 0.3481]


@pytest.fixture
def hunters(world, hunter_robot):
    for i, name in enumerate(("hunter1", "hunter2")):
        world.spawn(name, hunter_robot, (0, 2.0 * i, 0.05, 0, 0, 0), hunter_config())
        Spawner(
            world.rt, "spawner", f"/{name}", args=["joint_state_controller", "arm_group_controller"]
        )
    return world


def test_each_namespace_gets_a_controller_manager_and_joint_states(hunters):
    js = hunters.collect(sensor_msgs.JointState, "/hunter2/joint_states")
    hunters.rt.run(0.5)
    for ns in ("hunter1", "hunter2"):
        res = hunters.rt.graph.call_service(
            f"/{ns}/controller_manager/list_controllers", cmm.ListControllers
        )
        states = {c.name: (c.state, c.type) for c in res.controller}
        assert states == {
            "joint_state_controller": ("running", "joint_state_controller/JointStateController"),
            "arm_group_controller": ("running", "effort_controllers/JointTrajectoryController"),
        }
        arm = next(c for c in res.controller if c.name == "arm_group_controller")
        assert arm.claimed_resources[0].resources == ARM
    # joint_state_controller's arm, and the diff drive's wheels (publishWheelJointState,
    # updateRate 20 Hz) on the same topic, as in Gazebo
    arm_states = [m for m in js if m.name == ARM]
    wheel_states = [m for m in js if m.name != ARM]
    assert 20 <= len(arm_states) <= 26  # publish_rate 50 Hz over 0.5 s
    assert 8 <= len(wheel_states) <= 12 and all(len(m.name) == 2 for m in wheel_states)
    types = hunters.rt.graph.call_service(
        "/hunter1/controller_manager/list_controller_types", cmm.ListControllerTypes
    ).types
    assert "position_controllers/JointGroupPositionController" in types


def test_the_hunter_feeds_its_joint_damping_forward(hunter_robot):
    """ros_controllers.yaml's velocity_ff is each arm joint's URDF damping (N m s/rad), so a
    planned velocity gets the torque the damping takes without the PID lagging for it."""
    arm = hunter_config()["arm_group_controller"]
    assert arm["velocity_ff"] == {j: hunter_robot.joints[j].dynamics.damping for j in ARM}
    assert all(arm["gains"][j]["p"] == 10 and arm["gains"][j]["d"] == 0 for j in ARM)


def test_the_manual_gains_reach_a_pose_and_settle(hunters):
    """P = 10, D = 0 from ros_controllers.yaml (plus an integral term that takes out the
    gravity sag): a 6 s move to cam_low on hunter1 while hunter2 goes home; both end
    SUCCESSFUL (at rest within the default 0.01 rad/s) near the pose."""
    hunters.rt.run(0.3)
    q0 = hunters.cm("hunter1").hw.positions(ARM)
    ts = np.linspace(0, 1, 31)
    s = 3 * ts**2 - 2 * ts**3  # smooth start and stop
    sd = (6 * ts - 6 * ts**2) / 6.0
    pts = [
        (6 * t, q0 + (np.array(CAM_LOW) - q0) * a, (np.array(CAM_LOW) - q0) * b)
        for t, a, b in zip(ts[1:], s[1:], sd[1:], strict=True)
    ]
    h1 = hunters.follow("/hunter1/arm_group_controller/follow_joint_trajectory", ARM, pts)
    h2 = hunters.follow(
        "/hunter2/arm_group_controller/follow_joint_trajectory", ARM, [(6.0, HOME, [0.0] * 4)]
    )
    hunters.rt.run(8.0, until=lambda: h1.result is not None and h2.result is not None)
    assert (h1.result.error_code, h2.result.error_code) == (Result.SUCCESSFUL, Result.SUCCESSFUL)
    hunters.rt.run(1.0)
    np.testing.assert_allclose(hunters.cm("hunter1").hw.positions(ARM), CAM_LOW, atol=0.01)
    np.testing.assert_allclose(hunters.cm("hunter2").hw.positions(ARM), HOME, atol=0.01)
    assert np.abs(hunters.cm("hunter1").hw.velocities(ARM)).max() < 0.01


def test_a_new_trajectory_joins_from_the_desired_state(hunters):
    """As ros_controllers' JTC: on start the controller holds the measured position; a goal
    arriving mid-trajectory is bridged from the current trajectory's desired state (not from
    where the lagging arm is), so the setpoint never jumps."""
    hunters.rt.run(0.3)
    jtc = hunters.cm("hunter1").controllers["arm_group_controller"]
    hw = hunters.cm("hunter1").hw
    assert len(jtc.traj.times) == 1  # holding where the arm was when it started
    np.testing.assert_allclose(jtc.traj.positions[0], hw.positions(ARM), atol=0.02)
    action = "/hunter1/arm_group_controller/follow_joint_trajectory"
    q0 = hw.positions(ARM)
    hunters.follow(action, ARM, [(2.0, CAM_LOW, [0.0] * 4)])
    hunters.rt.run(1.0)
    first = jtc.traj
    hunters.follow(action, ARM, [(2.0, HOME, [0.0] * 4)])
    hunters.rt.run(0.02)
    bridge = jtc.traj
    assert bridge is not first
    t = float(bridge.times[0])
    desired = sample(first, t)[0]
    np.testing.assert_allclose(bridge.positions[0], desired, atol=1e-12)
    assert np.abs(desired - hw.positions(ARM)).max() > 1e-3  # the arm lags: joining from it
    assert np.abs(desired - q0).max() > 0.1  # would jump the setpoint


def test_goal_rejections_and_tolerance_violations(hunters):
    hunters.rt.run(0.3)
    action = "/hunter1/arm_group_controller/follow_joint_trajectory"
    h = hunters.follow(action, ARM[:3], [(1.0, [0, 0, 0])])
    hunters.rt.run(0.2)
    assert h.result.error_code == Result.INVALID_JOINTS
    assert "Joints on incoming goal don't match the controller joints" in h.result.error_string
    h = hunters.follow(action, ARM, [(1.0, HOME), (0.5, HOME)])
    hunters.rt.run(0.2)
    assert h.result.error_code == Result.INVALID_GOAL and "point 1" in h.result.error_string
    tol = [control_msgs.JointTolerance(name=j, position=0.001) for j in ARM]
    fast = hunters.follow(action, ARM, [(0.2, CAM_LOW)], path_tolerance=tol)
    hunters.rt.run(0.5, until=lambda: fast.result is not None)
    assert fast.result.error_code == Result.PATH_TOLERANCE_VIOLATED
    assert fast.result.error_string.startswith("arm_joint_0")
    assert "path error" in fast.result.error_string
    hunters.rt.run(1.0)
    # a 0.2 s jump, allowed 1 ns beyond its end to be at rest (the yaml allows 0.5 s)
    jump = hunters.follow(
        action, ARM, [(0.2, HOME)], goal_time_tolerance=Duration(sec=0, nanosec=1)
    )
    hunters.rt.run(2.0, until=lambda: jump.result is not None)
    assert jump.result.error_code == Result.GOAL_TOLERANCE_VIOLATED
    assert "goal velocity" in jump.result.error_string
    assert "beyond constraints/stopped_velocity_tolerance 0.01" in jump.result.error_string


def test_old_header_timestamp(hunters):
    hunters.rt.run(1.0)
    cli_goal = control_msgs.FollowJointTrajectoryGoal()
    cli_goal.trajectory.joint_names = ARM
    cli_goal.trajectory.header.stamp.sec = 0
    cli_goal.trajectory.header.stamp.nanosec = 100_000_000  # 0.1 s, long past
    cli_goal.trajectory.points = [
        trajectory_msgs.JointTrajectoryPoint(positions=HOME, time_from_start=Duration.from_sec(0.2))
    ]
    cli = hunters.probe.create_action_client(
        control_msgs.FollowJointTrajectory, "/hunter1/arm_group_controller/follow_joint_trajectory"
    )
    h = cli.send_goal(cli_goal)
    hunters.rt.run(0.2)
    assert h.result.error_code == Result.OLD_HEADER_TIMESTAMP


def test_load_switch_unload_errors(hunters, caplog):
    hunters.rt.run(0.3)
    cm = hunters.cm("hunter1")
    hunters.rt.params.set("/hunter1/bogus/type", "effort_controllers/JointMagicController")
    with pytest.raises(
        ControlError,
        match="controller type 'effort_controllers/JointMagicController' does not exist",
    ):
        cm.load("bogus")
    with pytest.raises(ControlError, match="namespace: '/hunter1/nothing'"):
        cm.load("nothing")
    with caplog.at_level(logging.ERROR):
        ok = hunters.rt.graph.call_service(
            "/hunter1/controller_manager/load_controller",
            cmm.LoadController,
            cmm.LoadControllerRequest(name="bogus"),
        ).ok
    assert not ok and "JointMagicController" in caplog.text
    hunters.rt.params.update(
        "/hunter1/second",
        {
            "type": "position_controllers/JointGroupPositionController",
            "joints": ARM,
        },
    )
    with pytest.raises(ControlError, match="needs hardware_interface/PositionJointInterface"):
        cm.load("second")
    hunters.rt.params.update(
        "/hunter1/twin",
        {
            "type": "effort_controllers/JointPositionController",
            "joint": "arm_joint_02",
            "pid": {"p": 10.0},
        },
    )
    cm.load("twin")
    with pytest.raises(
        ControlError,
        match="'arm_joint_02' is already claimed by running controller 'arm_group_controller'",
    ):
        cm.switch(start=["twin"])
    cm.switch(start=["twin"], stop=["arm_group_controller"])
    assert cm.controllers["twin"].running and not cm.controllers["arm_group_controller"].running
    with pytest.raises(ControlError, match="'twin' is running; stop it first"):
        cm.unload("twin")
    with pytest.raises(ControlError, match="'ghost' is not loaded"):
        cm.switch(start=["ghost"])
    cm.switch(stop=["twin"])
    cm.unload("twin")
    assert "/hunter1/twin" not in hunters.rt.graph.nodes


def test_deleting_the_model_removes_its_controller_manager(hunters):
    hunters.rt.run(0.3)
    hunters.sim.delete_model("hunter2")
    assert "/hunter2/controller_manager" not in hunters.rt.graph.nodes
    assert "/hunter2/arm_group_controller" not in hunters.rt.graph.nodes
    assert "/hunter2/controller_manager/list_controllers" not in hunters.rt.graph.services
    hunters.rt.run(0.3)


def test_joint_reads_follow_the_model_when_a_delete_recompiles_it(hunters):
    """Trajectory controllers read their joints by cached addresses (`SimRobotHW.states`): when
    deleting hunter1 recompiles the world, hunter2's joints move in qpos and the cache must
    follow (the deleted robot is the first spawned, so hunter2's addresses do change)."""
    hunters.rt.run(0.3)
    hw = hunters.cm("hunter2").hw
    before = hw.plugin.addresses(ARM)[0].copy()
    hunters.sim.delete_model("hunter1")
    hunters.rt.run(0.3)
    q, qd = hw.states(ARM)
    assert not np.array_equal(hw.plugin.addresses(ARM)[0], before)
    truth = hw.plugin.states(hunters.sim.engine)
    assert q.tolist() == [truth[j][0] for j in ARM]
    assert qd.tolist() == [truth[j][1] for j in ARM]
    assert np.abs(q).max() < 0.2  # still holding the arm's start, not reading another body
