"""move_base's services (make_plan, clear_costmaps, NavfnROS/make_plan) and pose helpers."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from nav_world import fill, goal_msg, nav_world, room_grid

from fleetsim.errors import ServiceError
from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs, std_srvs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.move_base_support import (
    path_msg,
    pose_of,
    pose_stamped,
    poses_in_frame,
    quaternion_problem,
)
from fleetsim.tf import Buffer, make_transform_stamped


def plan_request(goal, start=None, tolerance=0.0):
    req = nav_msgs.GetPlan.Request(goal=goal_msg(*goal).target_pose, tolerance=tolerance)
    if start is not None:
        req.start = goal_msg(*start).target_pose
    return req


@pytest.fixture(scope="module")
def idle():
    w = nav_world()
    w.rt.run(duration=0.5)
    return w


def call(w, name, req):
    return w.rt.graph.call_service(f"/lizi1/move_base/{name}", None, req)


def test_make_plan_from_the_robot_to_a_goal(idle):
    resp = call(idle, "make_plan", plan_request((6.0, 4.5)))
    poses = resp.plan.poses
    assert resp.plan.header.frame_id == "map" and len(poses) > 50
    assert (poses[0].pose.position.x, poses[0].pose.position.y) == pytest.approx((1.0, 1.0))
    assert (poses[-1].pose.position.x, poses[-1].pose.position.y) == pytest.approx((6.0, 4.5))
    ys = [p.pose.position.y for p in poses if abs(p.pose.position.x - 4.0) < 0.05]
    assert ys and all(2.5 < y < 3.5 for y in ys)  # through the door


def test_make_plan_tolerance_searches_near_a_blocked_goal(idle):
    assert call(idle, "make_plan", plan_request((4.0, 1.0))).plan.poses == []
    resp = call(idle, "make_plan", plan_request((4.0, 1.0), tolerance=1.0))
    poses = resp.plan.poses
    assert poses and (poses[-1].pose.position.x, poses[-1].pose.position.y) == (4.0, 1.0)
    reached = poses[-2].pose.position  # the nearby goal actually planned to
    assert 0.25 < math.hypot(reached.x - 4.0, reached.y - 1.0) <= 1.0 * math.sqrt(2)


def test_navfn_make_plan_uses_the_given_start(idle):
    resp = call(idle, "NavfnROS/make_plan", plan_request((2.0, 5.0), start=(1.0, 5.0)))
    first = resp.plan.poses[0].pose.position
    assert (first.x, first.y) == pytest.approx((1.0, 5.0))
    assert call(idle, "NavfnROS/make_plan", plan_request((30.0, 5.0), (1.0, 5.0))).plan.poses == []


def test_make_plan_is_refused_while_a_goal_is_active():
    w = nav_world()
    w.client.send_goal(goal_msg(6.0, 4.5))
    w.rt.run(duration=0.5)
    with pytest.raises(ServiceError, match=r"must be in an inactive state"):
        call(w, "make_plan", plan_request((2.0, 2.0)))


def test_clear_costmaps_forgets_sensed_obstacles():
    world = room_grid()
    fill(world, 2.0, 0.8, 2.2, 1.2)
    w = nav_world(world=world)
    w.rt.run(duration=0.6)
    cm = w.mb.local_costmap
    cell = cm.costmap.world_to_map(1.01, 0.0)  # the box's face, in odom (start pose (1, 1, 0))
    assert cm.costmap.costs[cell[1], cell[0]] == 254
    w.bot.scan_timer.cancel()
    call(w, "clear_costmaps", std_srvs.Empty.Request())
    cm.update()
    assert cm.costmap.costs[cell[1], cell[0]] == 0
    layer = w.mb.global_costmap.layered.layer("obstacle_layer")
    assert layer.buffers["scan"].observations == []


def test_quaternion_problems():
    q = geometry_msgs.Quaternion
    assert quaternion_problem(q(z=math.sin(0.3), w=math.cos(0.3))) == ""
    assert quaternion_problem(q(z=2.0, w=0.0)) == ""  # not unit, but vertical: normalised
    assert "NaN" in quaternion_problem(q(x=float("nan")))
    assert "close to zero" in quaternion_problem(q(w=0.0))
    assert "close to vertical" in quaternion_problem(q(x=0.3, w=0.95))


@settings(max_examples=50, deadline=None)
@given(
    tf=st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-3.1, 3.1)),
    pose=st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-3.1, 3.1)),
)
def test_poses_in_frame_round_trip(tf, pose):
    buf = Buffer()
    yaw = tf[2]
    buf.set_transform(
        make_transform_stamped(
            "map", "odom", 1.0, (tf[0], tf[1], 0.0), (0, 0, math.sin(yaw / 2), math.cos(yaw / 2))
        )
    )
    p = np.array([pose])
    there = poses_in_frame(buf, p, "odom", "map")
    back = poses_in_frame(buf, there, "map", "odom")
    np.testing.assert_allclose(back[:, :2], p[:, :2], atol=1e-9)
    assert math.isclose(math.remainder(back[0, 2] - pose[2], 2 * math.pi), 0.0, abs_tol=1e-9)
    c, s = math.cos(yaw), math.sin(yaw)
    assert there[0, 0] == pytest.approx(tf[0] + c * pose[0] - s * pose[1], abs=1e-9)


def test_poses_moved_match_the_numpy_formula_bit_for_bit():
    """The compiled transform of a plan gives NumPy's values exactly (yaw wrap included, at
    the wrap's edges too)."""
    from fleetsim.nav.move_base_support import poses_moved

    rng = np.random.default_rng(2)
    edges = np.array([[0.0, -0.0, math.pi], [1.0, 2.0, -math.pi], [3.0, 4.0, 3 * math.pi]])
    for _ in range(200):
        p = np.concatenate([rng.uniform(-30, 30, (int(rng.integers(0, 400)), 3)), edges])
        tx, ty = rng.uniform(-20, 20, 2)
        tyaw = float(rng.choice([0.0, math.pi, -math.pi, rng.uniform(-4, 4)]))
        c, s = math.cos(tyaw), math.sin(tyaw)
        want = np.empty_like(p)
        want[:, 0] = tx + c * p[:, 0] - s * p[:, 1]
        want[:, 1] = ty + s * p[:, 0] + c * p[:, 1]
        want[:, 2] = np.remainder(p[:, 2] + tyaw + math.pi, 2 * math.pi) - math.pi
        got = poses_moved(p, float(tx), float(ty), tyaw)
        assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


def test_path_and_pose_messages():
    stamp = Time.from_sec(2.0)
    msg = path_msg(np.array([[1.0, 2.0, 0.5], [3.0, 4.0, -1.0]]), "map", stamp)
    assert msg.header == std_msgs.Header(stamp=stamp, frame_id="map")
    assert [pose_of(p.pose) for p in msg.poses] == [
        pytest.approx((1.0, 2.0, 0.5)),
        pytest.approx((3.0, 4.0, -1.0)),
    ]
    assert pose_stamped(0, 0, math.pi, "odom", stamp).pose.orientation.z == pytest.approx(1.0)
