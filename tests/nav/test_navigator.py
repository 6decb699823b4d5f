"""Navigator against a fake move_base: goals, waypoints, feedback, cancel, failures."""

import math
import socket
import threading
import time

import numpy as np
import pytest
from fake_move_base import FakeMoveBase

from fleetsim.errors import ActionError
from fleetsim.nav.navigator import (
    INITIAL_COV_AA,
    Navigator,
    TaskResult,
    pose_stamped,
    task_result_of,
)
from fleetsim.runtime import Node, Runtime


@pytest.fixture
def world():
    rt = Runtime(seed=0)
    mb = FakeMoveBase(rt, "/lizi1", start=(0.0, 0.0), speed=1.0)
    yield rt, mb
    rt.shutdown()


def test_go_to_pose_succeeds_with_feedback(world):
    rt, mb = world
    nav = Navigator(rt, namespace="lizi1")
    assert nav.is_task_complete() and nav.get_feedback() is None
    assert nav.go_to_pose(3.0, 4.0, yaw=1.0)
    assert not nav.is_task_complete() and nav.get_result() is TaskResult.UNKNOWN
    rt.run(duration=2.0)
    fb = nav.get_feedback()
    assert fb.pose is not None and fb.frame_id == "map"
    assert fb.distance_remaining == pytest.approx(5.0 - math.hypot(*fb.pose[:2]), abs=1e-6)
    assert 1.0 < fb.navigation_time <= 2.0 + 1e-9 and fb.goal == pytest.approx((3, 4, 1.0))
    assert nav.spin_until_complete(timeout=10.0)
    assert nav.get_result() is TaskResult.SUCCEEDED
    assert nav.get_status_text() == "goal reached"
    assert (mb.x, mb.y) == (3.0, 4.0) and rt.now() < 6.0


def test_follow_waypoints_in_order_and_posestamped(world):
    rt, mb = world
    nav = Navigator(rt, "/lizi1")
    ps = pose_stamped(2.0, 2.0, math.pi / 2, "map", 0.0)
    nav.follow_waypoints([(1.0, 0.0), (1.0, 1.0, 0.5), ps])
    seen = set()
    while not nav.is_task_complete():
        rt.run(duration=0.1)
        seen.add(nav.get_feedback().current_waypoint)
    assert nav.get_result() is TaskResult.SUCCEEDED
    assert mb.goals == [(1.0, 0.0), (1.0, 1.0), (2.0, 2.0)]
    assert seen == {0, 1, 2} and nav.get_feedback().number_of_waypoints == 3


def test_aborted_waypoint_fails_the_task(world):
    rt, mb = world
    nav = Navigator(rt, "/lizi1")
    nav.follow_waypoints([(1.0, 0.0), (-5.0, 0.0), (2.0, 0.0)])
    assert nav.spin_until_complete(timeout=20.0)
    assert nav.get_result() is TaskResult.FAILED
    assert nav.get_status_text() == "waypoint 2 of 3: the goal (-5.000, 0.000) is off the map"
    assert mb.goals == [(1.0, 0.0), (-5.0, 0.0)]


def test_cancel_and_preempt_by_a_new_goal(world):
    rt, mb = world
    nav = Navigator(rt, "/lizi1")
    nav.go_to_pose(10.0, 0.0)
    rt.run(duration=1.0)
    nav.cancel_task()
    assert nav.spin_until_complete(timeout=2.0)
    assert nav.get_result() is TaskResult.CANCELED and mb.x < 2.0
    nav.go_to_pose(10.0, 0.0)
    rt.run(duration=1.0)
    nav.go_to_pose(mb.x, 1.0)  # the old goal is preempted; only the new task counts
    assert nav.spin_until_complete(timeout=5.0)
    assert nav.get_result() is TaskResult.SUCCEEDED and mb.y == 1.0


def test_timeout_returns_false(world):
    rt, _ = world
    nav = Navigator(rt, "/lizi1")
    nav.go_to_pose(100.0, 0.0)
    assert not nav.spin_until_complete(timeout=1.0)
    assert rt.now() == pytest.approx(1.0, abs=0.11)
    with pytest.raises(ActionError, match="timeout must be >= 0"):
        nav.spin_until_complete(timeout=-1)


def test_initial_pose_has_amcls_default_covariance(world):
    rt, mb = world
    nav = Navigator(rt, "/lizi1")
    nav.set_initial_pose(1.0, 2.0, math.pi / 2)
    rt.run(duration=0.01)
    (msg,) = mb.initial_poses
    assert msg.header.frame_id == "map"
    assert (msg.pose.pose.position.x, msg.pose.pose.position.y) == (1.0, 2.0)
    assert msg.pose.pose.orientation.z == pytest.approx(math.sqrt(0.5))
    cov = np.asarray(msg.pose.covariance).reshape(6, 6)
    assert cov[0, 0] == cov[1, 1] == 0.25 and cov[5, 5] == pytest.approx((math.pi / 12) ** 2)
    assert cov[5, 5] == INITIAL_COV_AA and np.count_nonzero(cov) == 3


def test_errors_name_the_problem(world):
    rt, _ = world
    with pytest.raises(ActionError, match="no move_base action server at /lizi2/move_base"):
        Navigator(rt, "/lizi2").go_to_pose(1.0, 1.0)
    nav = Navigator(rt, "/lizi1")
    with pytest.raises(ActionError, match="waypoint 1 must be \\(x, y\\[, yaw\\]\\)"):
        nav.follow_waypoints([(1.0, 2.0), (float("nan"), 1.0)])
    with pytest.raises(ActionError, match="at least one pose"):
        nav.follow_waypoints([])
    with pytest.raises(ActionError, match="needs a fleetsim Runtime"):
        Navigator(object())


def test_user_node_and_two_navigators_coexist(world):
    rt, mb = world
    user = Node(rt, "commander", "/")
    a = Navigator(user, "/lizi1")
    b = Navigator(rt, "/lizi1")
    assert b._own_node.full_name == "/lizi1/navigator"
    assert Navigator(rt, "/lizi1")._own_node.full_name == "/lizi1/navigator_2"
    a.go_to_pose(1.0, 0.0)
    assert a.spin_until_complete(5.0) and a.get_result() is TaskResult.SUCCEEDED
    assert b.get_result() is TaskResult.UNKNOWN  # b's state is its own
    b.destroy()
    assert "/lizi1/navigator" not in rt.graph.nodes


def test_status_mapping():
    assert [task_result_of(s) for s in range(10)] == [
        TaskResult.UNKNOWN, TaskResult.UNKNOWN, TaskResult.CANCELED, TaskResult.SUCCEEDED,
        TaskResult.FAILED, TaskResult.FAILED, TaskResult.UNKNOWN, TaskResult.UNKNOWN,
        TaskResult.CANCELED, TaskResult.FAILED,
    ]  # fmt: skip


def free_endpoint():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


def test_remote_navigator_over_zenoh():
    """A Navigator in a 'tool process' (SimulationClient) drives the simulation's move_base."""
    from fleetsim.transport import SimulationClient, ZenohBridge

    rt = Runtime(seed=0)
    mb = FakeMoveBase(rt, "/lizi1", speed=2.0)
    ep = free_endpoint()
    ZenohBridge(rt, listen=[ep])
    stop = threading.Event()
    thread = threading.Thread(target=lambda: rt.run(until=stop.is_set, rate=4.0), daemon=True)
    thread.start()
    try:
        with SimulationClient(ep, timeout=3.0) as client:
            nav = Navigator(client, "/lizi1")
            nav.set_initial_pose(0.5, 0.5, 0.0)
            nav.follow_waypoints([(1.0, 0.0), (1.0, 1.0)])
            assert nav.spin_until_complete(timeout=20.0)
            assert nav.get_result() is TaskResult.SUCCEEDED, nav.get_status_text()
            assert mb.goals == [(1.0, 0.0), (1.0, 1.0)]
            nav.go_to_pose(-1.0, 0.0)
            assert nav.spin_until_complete(timeout=20.0)
            assert nav.get_result() is TaskResult.FAILED
            assert "off the map" in nav.get_status_text()
            nav.go_to_pose(50.0, 0.0)
            deadline = time.monotonic() + 10
            while nav.get_feedback().pose is None and time.monotonic() < deadline:
                time.sleep(0.02)
            nav.cancel_task()
            assert nav.spin_until_complete(timeout=20.0)
            assert nav.get_result() is TaskResult.CANCELED
            with pytest.raises(ActionError, match="no move_base action server at /nobody"):
                Navigator(client, "/nobody").go_to_pose(1.0, 1.0)
            nav.destroy()
        assert len(mb.initial_poses) == 1 and mb.initial_poses[0].pose.covariance[0] == 0.25
    finally:
        stop.set()
        thread.join(10)
        rt.shutdown()
