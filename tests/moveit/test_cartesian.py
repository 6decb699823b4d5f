"""Pose targets (position and orientation) and compute_cartesian_path on the hunter's 4-joint
arm in the simulator."""

import copy

import numpy as np
import pytest

from fleetsim.moveit import MoveGroupCommander, MoveItCommanderException
from fleetsim.msgs import moveit_msgs
from fleetsim.tf.quaternions import quaternion_multiply

from .conftest import Hunters, assert_no_mujoco_warnings

E = moveit_msgs.MoveItErrorCodes


@pytest.fixture(scope="module")
def arm(hunter_robot):
    h = Hunters(hunter_robot)
    yield h, MoveGroupCommander("arm_group", ns="/hunter1", runtime=h.rt)
    assert_no_mujoco_warnings(h.sim.engine)


def xyz(pose) -> np.ndarray:
    return np.array([pose.position.x, pose.position.y, pose.position.z])


def angle_between(q1, q2) -> float:
    """rad between two orientations given as x y z w."""
    return 2 * np.arccos(min(1.0, abs(float(np.dot(q1, q2)))))


def test_a_reachable_pose_is_reached_with_its_orientation(arm):
    h, a = arm
    ctx = h.move_group("hunter1").pipeline.context("arm_group")
    # a pose whose tip pitch (arm_joint_04, which does not move cluedo_link's origin) differs
    # from home's by 0.95 rad: position-only IK from home would keep home's
    pos, quat = ctx.kin.link_pose(np.array([0.0173, 0.3, -1.0, -0.6]), "cluedo_link")
    a.set_named_target("home")
    assert a.go()
    target = a.get_current_pose().pose
    target.position.x, target.position.y, target.position.z = pos
    target.orientation.x, target.orientation.y, target.orientation.z, target.orientation.w = quat
    a.set_goal_position_tolerance(1e-3)
    a.set_goal_orientation_tolerance(1e-3)
    a.set_pose_target(target)
    assert a.go(), a.last_result()
    now = a.get_current_pose().pose
    assert type(now.position.x) is float and type(now.orientation.w) is float  # as rospy's
    assert np.linalg.norm(xyz(now) - pos) < 0.01
    o = now.orientation
    assert angle_between([o.x, o.y, o.z, o.w], quat) < 0.02


def test_an_orientation_four_joints_cannot_make_is_refused_saying_why(arm):
    h, a = arm
    a.set_named_target("home")  # not the start's upright arm, whose column turns the tip
    assert a.go()  # about its own z: this test must not depend on the tests run before it
    here = a.get_current_pose().pose
    o = here.orientation
    # where the tip is, turned a quarter turn about its own z axis: the arm's joints turn it
    # about the column (z) and about their pitch axes only
    turned = quaternion_multiply([o.x, o.y, o.z, o.w], [0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)])
    a.set_pose_target([*xyz(here), *turned])
    assert not a.go()
    result, text = a.last_result()
    assert result.error_code.val == E.NO_IK_SOLUTION
    assert "group 'arm_group' has 4 joints" in text and "set_position_target" in text
    with pytest.raises(MoveItCommanderException, match="not a rotation"):
        a.set_pose_target([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    a.set_position_target(xyz(here) - np.array([0.0, 0.0, 0.02]))  # the position alone is fine
    assert a.go(), a.last_result()


def test_cartesian_path_follows_a_straight_line_and_reports_the_fraction(arm):
    h, a = arm
    a.set_named_target("cam_low")
    assert a.go()
    ctx = h.move_group("hunter1").pipeline.context("arm_group")
    start = a.get_current_pose().pose
    down = copy.deepcopy(start)
    down.position.z -= 0.06
    side = copy.deepcopy(down)
    side.position.y += 0.05
    traj, fraction = a.compute_cartesian_path([down, side], 0.005, 0.0)
    assert fraction == pytest.approx(1.0)
    pts = traj.joint_trajectory.points
    tips = np.array([ctx.kin.link_pose(np.asarray(p.positions), "cluedo_link")[0] for p in pts])
    np.testing.assert_allclose(tips[-1], xyz(side), atol=1e-3)
    # every timed point lies on the two segments (within the IK tolerance and the timing's
    # spline between the 5 mm steps)
    a0, a1, a2 = xyz(start), xyz(down), xyz(side)

    def off_line(p):
        d = []
        for u, v in ((a0, a1), (a1, a2)):
            s = np.clip(np.dot(p - u, v - u) / np.dot(v - u, v - u), 0, 1)
            d.append(np.linalg.norm(p - (u + s * (v - u))))
        return min(d)

    assert max(off_line(p) for p in tips) < 2e-3
    assert a.execute(traj), a.last_result()
    assert np.linalg.norm(xyz(a.get_current_pose().pose) - a2) < 0.01
    # moveit_commander >= 1.1.15 form (no jump_threshold): a waypoint out of reach ends the
    # path part way, with the fraction reached
    far = copy.deepcopy(side)
    far.position.z += 1.0
    traj, fraction = a.compute_cartesian_path([far], 0.01, True)
    assert 0.0 < fraction < 0.5
    assert len(traj.joint_trajectory.points) >= 2
    with pytest.raises(MoveItCommanderException, match="eef_step must be > 0"):
        a.compute_cartesian_path([far], 0.0, 0.0)
    # the service itself: bad requests come back as error codes
    srv = "/hunter1/compute_cartesian_path"
    for fields, code in (
        ({"group_name": "gripper", "waypoints": [far]}, E.INVALID_GROUP_NAME),
        ({"link_name": "nowhere", "waypoints": [far]}, E.INVALID_LINK_NAME),
        ({"waypoints": []}, E.INVALID_GOAL_CONSTRAINTS),
    ):
        req = moveit_msgs.GetCartesianPathRequest(
            **{"group_name": "arm_group", "max_step": 0.01, **fields}
        )
        res = h.rt.graph.call_service(srv, moveit_msgs.GetCartesianPath, req)
        assert res.error_code.val == code, fields
