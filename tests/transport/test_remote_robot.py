"""Scenario: the simulator in this process, a robot's controller in another, over Zenoh.

The controller (``helper_nodes.GoToPoint``) runs in a subprocess started through
``fleetsim node run``'s function, on the simulation's /clock, reading ``/r/odom`` and sending
``/r/cmd_vel``; the simulator's ground truth must end within the controller's tolerance.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fleetsim.msgs import nav_msgs, std_msgs
from fleetsim.runtime import Node, Runtime

ROOT = Path(__file__).resolve().parents[2]
DIFFBOT = ROOT / "tests" / "sim" / "fixtures" / "diffbot.urdf"

pytestmark = pytest.mark.scenario


def test_controller_in_another_process_drives_the_robot_to_its_goal(endpoint):
    os.environ.setdefault("MUJOCO_GL", "egl")
    from fleetsim.description import load_robot
    from fleetsim.sim.node import Simulator
    from transport.conftest import SimThread

    rt = Runtime(seed=3)
    rt.params.set("/r/go_to_point", {"goal_x": 1.2, "goal_y": 0.6, "xy_goal_tolerance": 0.1})
    sim = Simulator(rt)
    sim.spawn_robot("r", load_robot(DIFFBOT))
    watcher = Node(rt, "watcher")
    arrived, odom = [], []
    watcher.create_subscription(std_msgs.Bool, "/r/arrived", lambda m: arrived.append(rt.now()))
    watcher.create_subscription(nav_msgs.Odometry, "/r/odom", odom.append, queue_size=1)
    code = (
        "import sys\n"
        "from fleetsim.transport.noderun import run_node\n"
        f"run_node('transport.helper_nodes:GoToPoint', '/r', connect='{endpoint}',\n"
        "         until=float(sys.argv[1]))\n"
    )
    env = dict(os.environ, PYTHONPATH=f"{ROOT / 'src'}{os.pathsep}{ROOT / 'tests'}")
    with SimThread(rt, endpoint, rate=2.0):
        until = rt.now() + 12.0
        r = subprocess.run(
            [sys.executable, "-c", code, str(until)],
            env=env,
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert r.returncode == 0, r.stderr
        # it ran until the sim time it was given, and stopped there (no wall-clock bound: the
        # subprocess timeout catches a hang; a loaded machine only makes it slower)
        assert rt.now() >= until, (rt.now(), until)
        position, _ = sim.engine.model_pose("r")
    assert arrived, "the remote controller never reported arrival"
    p = odom[-1].pose.pose.position
    assert np.hypot(p.x - 1.2, p.y - 0.6) < 0.1  # by its odometry, within its tolerance
    drift = np.hypot(p.x - position[0], p.y - position[1])
    print(f"arrived at t={arrived[0]:.2f} s; truth {position[:2]}, odometry drift {drift:.3f} m")
    assert np.hypot(position[0] - 1.2, position[1] - 0.6) < 0.1 + drift + 1e-6


HOST = """
import sys
from fleetsim.runtime import Runtime
from fleetsim.transport import ZenohBridge
from fleetsim.transport.paramserver import request_param
from transport.helper_nodes import GoToPoint

endpoint, until, robots = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
rt = Runtime()
bridge = ZenohBridge(rt, mode="client", connect=[endpoint], follow_clock=True)
rt.params.set("/", request_param(bridge.session, bridge.keys, "dump", "/"))
nodes = [GoToPoint(rt, namespace="/" + r) for r in robots]
bridge.run_following(until=until)
rt.shutdown()
"""


def test_two_processes_each_host_half_the_robots_controllers(endpoint):
    os.environ.setdefault("MUJOCO_GL", "egl")
    from fleetsim.description import load_robot
    from fleetsim.sim.node import Simulator
    from transport.conftest import SimThread

    goals = {"r1": (1.0, 0.5), "r2": (-1.0, 0.5), "r3": (1.0, -0.5), "r4": (-1.0, -2.5)}
    starts = {"r1": (0, 0), "r2": (0, 1), "r3": (0, -1), "r4": (0, -2)}
    rt = Runtime(seed=4)
    sim = Simulator(rt)
    arrived: dict[str, float] = {}
    odom: dict = {}
    watcher = Node(rt, "watcher")
    robot = load_robot(DIFFBOT)
    for name, (gx, gy) in goals.items():
        sx, sy = starts[name]
        rt.params.set(f"/{name}/go_to_point", {"goal_x": gx - sx, "goal_y": gy - sy})
        sim.spawn_robot(name, robot, (sx, sy, 0, 0, 0, 0))
        watcher.create_subscription(
            std_msgs.Bool, f"/{name}/arrived", lambda m, n=name: arrived.setdefault(n, rt.now())
        )
        watcher.create_subscription(
            nav_msgs.Odometry, f"/{name}/odom", lambda m, n=name: odom.__setitem__(n, m), 1
        )
    env = dict(os.environ, PYTHONPATH=f"{ROOT / 'src'}{os.pathsep}{ROOT / 'tests'}")
    with SimThread(rt, endpoint, rate=2.0):
        until = rt.now() + 12.0
        procs = [
            subprocess.Popen(
                [sys.executable, "-c", HOST, endpoint, str(until), *half],
                env=env,
                stderr=subprocess.PIPE,
                text=True,
            )
            for half in (["r1", "r2"], ["r3", "r4"])
        ]
        for p in procs:
            _, err = p.communicate(timeout=60)
            assert p.returncode == 0, err
        truth = {n: sim.engine.model_pose(n)[0] for n in goals}
    assert sorted(arrived) == sorted(goals)  # every robot reported arrival from its process
    for name, (gx, gy) in goals.items():
        (sx, sy), p = starts[name], odom[name].pose.pose.position
        assert np.hypot(p.x - (gx - sx), p.y - (gy - sy)) < 0.1, name  # by its odometry
        drift = np.hypot(p.x + sx - truth[name][0], p.y + sy - truth[name][1])
        assert np.hypot(truth[name][0] - gx, truth[name][1] - gy) < 0.1 + drift + 1e-6, name
