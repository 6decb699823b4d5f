"""Shared fixtures of the move_group tests: the hunter's model and a running hunter."""

from __future__ import annotations

import os

import pytest
import yaml

os.environ.setdefault("MUJOCO_GL", "egl")

from fleetsim.control.spawner import Spawner
from fleetsim.description import load_robot
from fleetsim.description.packages import ASSET_ROBOTS
from fleetsim.description.srdf import load_srdf
from fleetsim.moveit import MoveGroup
from fleetsim.moveit.robot_model import RobotModel
from fleetsim.runtime import Node, Runtime
from fleetsim.sim.node import Simulator

HUNTER = ASSET_ROBOTS / "hunter"
ARM = [f"arm_joint_0{i}" for i in range(1, 5)]


def config(name: str) -> dict:
    return yaml.safe_load((HUNTER / "config" / name).read_text())


@pytest.fixture(scope="session")
def hunter_robot():
    return load_robot(HUNTER / "urdf" / "hunter.urdf.xacro")


@pytest.fixture(scope="session")
def hunter_model(hunter_robot):
    srdf = load_srdf(HUNTER / "config" / "robocluedo_robot.srdf", hunter_robot)
    return RobotModel(hunter_robot, srdf, config("joint_limits.yaml"))


@pytest.fixture(autouse=True)
def in_tmp_dir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    yield
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def load_hunter_params(rt: Runtime, ns: str, robot, fake: bool = False) -> None:
    ctrl = config("ros_controllers.yaml")
    rt.params.update(ns, ctrl)
    rt.params.set(f"{ns}/robot_description", robot.to_urdf())
    rt.params.set(
        f"{ns}/robot_description_semantic",
        (HUNTER / "config" / "robocluedo_robot.srdf").read_text(),
    )
    rt.params.update(f"{ns}/robot_description_planning", config("joint_limits.yaml"))
    mg = {"controller_list": ctrl["controller_list"]}
    if fake:
        mg["moveit_controller_manager"] = (
            "moveit_fake_controller_manager/MoveItFakeControllerManager"
        )
    rt.params.update(f"{ns}/move_group", mg)


class Hunters:
    """Hunters in namespaces, each with controllers and a move_group, in the simulator."""

    def __init__(self, robot, names=("hunter1",), tf_prefix: bool = False) -> None:
        self.rt = Runtime()
        self.sim = Simulator(self.rt)
        self.probe = Node(self.rt, "probe")
        for i, name in enumerate(names):
            ns = f"/{name}"
            load_hunter_params(self.rt, ns, robot)
            if tf_prefix:  # the robot's nodes use its prefixed frames, as the simulator does
                self.rt.params.set(f"{ns}/tf_prefix", name)
            self.sim.spawn_robot(name, robot, (0, 3.0 * i, 0.05, 0, 0, 0), ns)
            Spawner(self.rt, "spawner", ns, args=["joint_state_controller", "arm_group_controller"])
            MoveGroup(self.rt, "move_group", ns)
        self.rt.run(0.3)

    def move_group(self, ns: str) -> MoveGroup:
        return self.rt.graph.nodes[f"/{ns}/move_group"]


def assert_no_mujoco_warnings(engine):
    assert {i: w.number for i, w in enumerate(engine.data.warning) if w.number} == {}
