"""patrol_server drives a burger round circles, counts laps from odometry, and stops."""

import math
from pathlib import Path

import numpy as np
import pytest

from fleetsim.apps.patrol_server import PatrolServer, patrol_twist, shortest_angular_distance
from fleetsim.description import load_robot
from fleetsim.msgs import geometry_msgs, grobot_utilities
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.node import Simulator

BURGER = (
    Path(__file__).resolve().parents[2]
    / "src/fleetsim/assets/robots/turtlebot3_burger/urdf/turtlebot3_burger.urdf.xacro"
)


@pytest.fixture(autouse=True)
def in_tmp_dir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # where MuJoCo would write MUJOCO_LOG.TXT
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_shortest_angular_distance_and_the_circle_command():
    assert shortest_angular_distance(0.1, 0.3) == pytest.approx(0.2)
    assert shortest_angular_distance(3.0, -3.0) == pytest.approx(2 * math.pi - 6.0)
    assert shortest_angular_distance(-3.0, 3.0) == pytest.approx(6.0 - 2 * math.pi)
    t = patrol_twist(1.5, clockwise=True)
    assert t.linear.x == 0.1 and t.angular.z == pytest.approx(-0.1 / 1.5)
    assert patrol_twist(0.5, clockwise=False).angular.z == pytest.approx(0.2)


def karl(rt):
    sim = Simulator(rt, "gazebo")
    sim.spawn_robot("karl", load_robot(BURGER), (-2.0, 2.0, 0, 0, 0, 0), "/karl")
    server = PatrolServer(rt, "patrol_server", "/karl")
    probe = Node(rt, "probe")
    client = probe.create_action_client(grobot_utilities.Patrol, "/karl/patrol_server")
    return sim, server, client


@pytest.mark.parametrize(
    ("radius", "clockwise"),
    [(0.5, False), (0.15, True)],  # 1.1 deg per cycle: the 1 deg window; 3.8: stepped over
)
def test_two_laps_round_the_circle_then_success_and_a_stop(radius, clockwise):
    rt = Runtime(seed=1)
    sim, server, client = karl(rt)
    laps, path = [], []
    rt.run(duration=0.5)
    handle = client.send_goal(
        grobot_utilities.Patrol.Goal(radius=radius, clockwise=clockwise, num_patrols=2),
        feedback_cb=lambda h, fb: laps.append((rt.now(), fb.completed_patrols)),
    )
    probe = rt.graph.nodes["/probe"]
    probe.create_timer(0.2, lambda: path.append(sim.engine.model_pose("karl")[0][:2].copy()))
    lap_time = 2 * math.pi * radius / 0.1
    rt.run(duration=2 * lap_time + 3.0)
    assert [n for _, n in laps] == [1, 2]
    assert handle.status == 3 and handle.result.success  # SUCCEEDED
    # a lap takes 2 pi r / 0.1 m/s, to within the 10 Hz cycle, the 1 degree window and the
    # drive's yaw-rate tracking (the simulated burger turns 1-2 % slower than commanded); the
    # first one also has the wheels' spin-up
    (t1, _), (t2, _) = laps
    assert lap_time <= t1 - 0.5 <= 1.03 * lap_time + 0.6
    assert t2 - t1 == pytest.approx(lap_time, rel=0.03)
    path = np.array(path)
    start = np.array([-2.0, 2.0])
    side = -1.0 if clockwise else 1.0
    centre = start + np.array([0.0, side * radius])  # beside the start, left or right
    during = path[: round(2 * lap_time / 0.2)]
    np.testing.assert_allclose(np.linalg.norm(during - centre, axis=1), radius, atol=0.03)
    # stopped after the last lap
    assert np.linalg.norm(path[-1] - path[-5]) < 0.005
    assert np.linalg.norm(path[-1] - start) < 0.05
    assert {i: w.number for i, w in enumerate(sim.engine.data.warning) if w.number} == {}


def test_cancel_stops_the_patrol_and_a_bad_radius_is_aborted():
    rt = Runtime(seed=1)
    sim, server, client = karl(rt)
    cmds = []
    probe = rt.graph.nodes["/probe"]
    probe.create_subscription(geometry_msgs.Twist, "/karl/cmd_vel", cmds.append, queue_size=10)
    endless = client.send_goal(grobot_utilities.Patrol.Goal(radius=1.5, num_patrols=0))
    rt.run(duration=2.0)
    assert cmds and cmds[-1].angular.z == pytest.approx(0.1 / 1.5)
    endless.cancel()
    rt.run(duration=0.5)
    assert endless.status == 2  # PREEMPTED
    assert cmds[-1].linear.x == 0 and cmds[-1].angular.z == 0
    bad = client.send_goal(grobot_utilities.Patrol.Goal(radius=0.0))
    rt.run(duration=0.2)
    assert bad.status == 4  # ABORTED
    assert "radius must be a positive number of metres, got 0.0" in bad.text
    assert "/karl/patrol_server" in bad.text
