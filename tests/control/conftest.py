"""Shared fixtures of the ros_control tests: the hunter (and a small arm) in the simulator."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np
import pytest
import yaml

os.environ.setdefault("MUJOCO_GL", "egl")

from fleetsim.description import load_robot
from fleetsim.description.packages import ASSET_ROBOTS
from fleetsim.msgs import control_msgs, trajectory_msgs
from fleetsim.msgs.builtin_interfaces import Duration
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.node import Simulator

HUNTER = ASSET_ROBOTS / "hunter"
ARM = [f"arm_joint_0{i}" for i in range(1, 5)]
SIM_FIXTURES = Path(__file__).resolve().parents[1] / "sim" / "fixtures"


@pytest.fixture(scope="session")
def hunter_robot():
    return load_robot(HUNTER / "urdf" / "hunter.urdf.xacro")


@pytest.fixture(autouse=True)
def in_tmp_dir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def assert_no_mujoco_warnings(engine):
    assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}


class World:
    """A runtime with the simulator, robots spawned into namespaces and a probe node."""

    def __init__(self) -> None:
        self.rt = Runtime()
        self.sim = Simulator(self.rt)
        self.probe = Node(self.rt, "probe")

    def spawn(self, name: str, robot, pose=(0, 0, 0.05, 0, 0, 0), config: dict | None = None):
        if config is not None:
            self.rt.params.update(f"/{name}", config)
        return self.sim.spawn_robot(name, robot, pose, f"/{name}")

    def cm(self, ns: str):
        return self.rt.graph.nodes[f"/{ns}/controller_manager"]

    def collect(self, msg_type, topic: str) -> list:
        store: list = []
        self.probe.create_subscription(msg_type, topic, store.append)
        return store

    def follow(self, action: str, joints, points, **goal_fields):
        """Send a FollowJointTrajectory goal of ``points`` [(t, positions[, velocities])]."""
        cli = self.probe.create_action_client(control_msgs.FollowJointTrajectory, action)
        goal = control_msgs.FollowJointTrajectoryGoal(**goal_fields)
        goal.trajectory.joint_names = list(joints)
        for p in points:
            pt = trajectory_msgs.JointTrajectoryPoint(
                positions=np.asarray(p[1], float), time_from_start=Duration.from_sec(p[0])
            )
            if len(p) > 2:
                pt.velocities = np.asarray(p[2], float)
            goal.trajectory.points.append(pt)
        return cli.send_goal(goal)


def hunter_config() -> dict:
    return yaml.safe_load((HUNTER / "config" / "ros_controllers.yaml").read_text())


@pytest.fixture
def world():
    w = World()
    yield w
    assert_no_mujoco_warnings(w.sim.engine)
    logging.disable(logging.NOTSET)
