"""Kinematics, collision checks, OMPL planning and toppra timing on the hunter's arm."""

import mujoco
import numpy as np
import pytest

from fleetsim.moveit.collision import CollisionScene
from fleetsim.moveit.kinematics import Kinematics
from fleetsim.moveit.planner import PlanFailure, plan_path
from fleetsim.moveit.timing import time_parameterize
from fleetsim.msgs.moveit_msgs import MoveItErrorCodes as E

#: cluedo_link and camera_arm positions in base_link (the model's forward kinematics, checked
#: against Pinocchio and an own numpy FK by the research notes)
FK = {
    "home": ([-0.026, 0.000, 1.019], [-0.084, 0, 0.828]),
    "cam_low": ([0.025, -0.008, 0.858], [-0.142, 0.005, 0.749]),
    "cam_low_back": ([-0.175, -0.011, 0.858], [-0.008, 0.007, 0.749]),
    "home_low": ([0.054, -0.010, 0.785], [-0.136, 0.005, 0.722]),
}


@pytest.fixture(scope="module")
def arm(hunter_model):
    lim = hunter_model.limits("arm_group")
    kin = Kinematics(
        hunter_model.robot, hunter_model.active_joints("arm_group"), lim.lower, lim.upper
    )
    scene = CollisionScene(
        kin, hunter_model.links("arm_group"), hunter_model.srdf.disabled_collisions
    )
    return hunter_model, kin, scene, lim


def test_forward_kinematics_of_named_poses(arm):
    model, kin, _, _ = arm
    for name, (tip, cam) in FK.items():
        q = model.named_target("arm_group", name)
        np.testing.assert_allclose(kin.link_pose(q, "cluedo_link")[0], tip, atol=1.5e-3)
        np.testing.assert_allclose(kin.link_pose(q, "camera_arm")[0], cam, atol=1.5e-3)


def test_position_ik_reaches_a_named_pose_tip(arm):
    model, kin, scene, lim = arm
    target = np.array(FK["cam_low"][0])
    rng = np.random.default_rng(3)
    seeds = [np.zeros(4)] + [rng.uniform(lim.lower, lim.upper) for _ in range(10)]
    q = kin.position_ik("cluedo_link", target, seeds, 1e-4, valid=scene.is_valid)
    assert q is not None
    np.testing.assert_allclose(kin.link_pose(q, "cluedo_link")[0], target, atol=1e-4)
    assert np.all(q >= lim.lower) and np.all(q <= lim.upper)
    assert kin.position_ik("cluedo_link", np.array([2.0, 0, 1.0]), seeds) is None  # out of reach


def test_named_poses_are_free_and_folding_onto_the_chassis_is_not(arm):
    model, _, scene, _ = arm
    for q in model.named_targets("arm_group").values():
        assert scene.contacts(q) == []
    hits = scene.contacts(np.array([0.0, 1.8, 1.8, 0.0]))
    assert hits and all("cluedo_link" in pair or "arm_link_03" in pair for pair in hits)


def test_a_box_in_the_way_is_gone_around(arm):
    model, kin, scene, lim = arm
    start = model.named_target("arm_group", "cam_low")
    goal = model.named_target("arm_group", "cam_low_back")
    # a box where the straight joint-space path sweeps the arm's tip
    mid = kin.link_pose(0.5 * (start + goal), "cluedo_link")[0]
    box = [
        (
            int(mujoco.mjtGeom.mjGEOM_BOX),
            np.array([0.05, 0.05, 0.05]),
            mid,
            np.array([1.0, 0, 0, 0]),
        )
    ]
    free = plan_path(start, goal, lim.lower, lim.upper, scene.is_valid, "RRTConnect", 5.0, 1, 7)
    assert free.planner == "" and len(free.path) == 2  # straight and free: no planner ran
    ran = plan_path(start, goal, lim.lower, lim.upper, scene.is_valid, "RRT", try_straight=False)
    assert ran.planner == "RRT"
    np.testing.assert_allclose(ran.path[[0, -1]], [start, goal], atol=1e-9)
    scene.add_object("box", box)
    try:
        assert not scene.is_valid(0.5 * (start + goal))
        plan = plan_path(start, goal, lim.lower, lim.upper, scene.is_valid, "RRTConnect", 5.0, 1, 7)
        assert plan.planner == "RRTConnect" and plan.planning_time > 0
        dense = np.concatenate(
            [np.linspace(a, b, 50) for a, b in zip(plan.path[:-1], plan.path[1:], strict=True)]
        )
        assert all(scene.is_valid(q) for q in dense)
        np.testing.assert_allclose(plan.path[-1], goal, atol=1e-9)
    finally:
        scene.remove_object("box")


def test_plan_failures_are_typed(arm):
    model, _, scene, lim = arm
    bad = np.array([0.0, 1.8, 1.8, 0.0])
    ok = model.named_target("arm_group", "home")
    with pytest.raises(PlanFailure, match="goal state is in collision") as e:
        plan_path(ok, bad, lim.lower, lim.upper, scene.is_valid)
    assert e.value.code == E.GOAL_IN_COLLISION
    with pytest.raises(PlanFailure, match="start state is in collision"):
        plan_path(bad, ok, lim.lower, lim.upper, scene.is_valid)
    with pytest.raises(PlanFailure, match="unknown planner 'RRTFast'"):
        plan_path(ok, ok, lim.lower, lim.upper, scene.is_valid, "RRTFast")


@pytest.mark.parametrize("scaling", [1.0, 0.5])
def test_timing_stays_within_scaled_limits(scaling):
    path = np.array(
        [[-1.57, 0.1293, -0.4276, 0.3481], [0.0, 0.3, -1.0, 0.3], [1.68, 0.53, -1.52, 0.35]]
    )
    vmax, amax = np.array([0.2, 0.2, 0.2, 0.5]), np.ones(4)
    t, pos, vel, acc = time_parameterize(path, vmax, amax, scaling, scaling)
    assert np.all(np.diff(t) > 0)
    assert np.all(np.abs(vel) <= vmax * scaling * 1.001)
    assert np.all(np.abs(acc) <= amax * scaling * 1.01)
    np.testing.assert_allclose(pos[0], path[0])
    np.testing.assert_allclose(pos[-1], path[-1])
    assert not vel[0].any() and not vel[-1].any()
    # the limit is reached: joint 1 moves 3.25 rad at 0.2 rad/s * scaling
    assert t[-1] == pytest.approx(3.25 / (0.2 * scaling) + 0.2 * scaling, rel=0.05)


@pytest.mark.parametrize("points", [2, 3, 5])
def test_a_move_a_hair_long_is_timed_within_the_limits(points):
    """Paths shorter than ~5e-5 rad, two points or more (a short Cartesian path, a plan's path
    with its goal appended): toppra found no profile for them; they are timed in closed form,
    from rest to rest, within the scaled limits, through the path's points."""
    rng = np.random.default_rng(points)
    path = np.cumsum(rng.uniform(-1e-5, 1e-5, (points, 4)), axis=0)
    vmax, amax = np.array([0.2, 0.2, 0.2, 0.5]), np.array([1.0, 1.0, 1.0, 2.0])
    t, pos, vel, acc = time_parameterize(path, vmax, amax, 0.5, 0.5)
    assert t[0] == 0.0 and t[-1] > 0 and np.all(np.diff(t) > 0)
    np.testing.assert_allclose(pos[0], path[0]) and np.testing.assert_allclose(pos[-1], path[-1])
    assert np.all(np.abs(vel) <= 0.5 * vmax + 1e-12) and np.all(np.abs(acc) <= 0.5 * amax + 1e-9)
    assert not vel[0].any() and not vel[-1].any()
